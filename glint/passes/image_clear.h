#pragma once
// Clears colour storage images with a compute dispatch. Passes that only
// write some pixels of an output (the traces write the pixels they trace)
// clear it first; vkCmdClearColorImage would do, but runs on the graphics
// engine, of which compute-class GPUs have little: on an H200 it cleared
// three 1080p targets in 0.77 ms, more than the SSLR trace itself.
//
// In a pass, declare each image Access::StorageWrite, then
//   clearer.clear(pc, texture);          // zero
// Writes of the same pass to the same image need no barrier after it (the
// image is written twice by the same stage; callers that read it in the
// same pass must add one).

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/executor.h"

#include <glm/glm.hpp>

namespace glint::passes {

class ImageClearer {
public:
    // Throws gpu::GpuError when the device lacks shaderStorageImageWriteWithoutFormat.
    explicit ImageClearer(gpu::Context& ctx);

    // Fills `texture` (declared StorageWrite by the current pass) with `value`.
    void clear(rg::PassContext& pc, rg::Texture texture, glm::vec4 value = glm::vec4(0.0f)) const;

private:
    gpu::Context& ctx_;
    gpu::Pipeline pipeline_;
};

} // namespace glint::passes
