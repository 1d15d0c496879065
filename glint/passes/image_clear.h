#pragma once
// Clears colour storage images with a compute dispatch. Passes that only
// write some pixels of an output (the traces write the pixels they trace)
// clear it first; vkCmdClearColorImage would do, but runs on the graphics
// engine, of which compute-class GPUs have little: on an H200 it cleared
// three 1080p targets in 0.77 ms, more than the SSLR trace itself.
//
// A pass of its own that zeroes some images (the handles then name the
// cleared versions):
//   clearer.addClearPass(graph, "sslr.clear", textures);
// or, in a pass that declares each image Access::StorageWrite,
//   clearer.clear(pc, texture);          // zero
// Writes of the same pass to the same image need no barrier after it (the
// image is written twice by the same stage; callers that read it in the
// same pass must add one).

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"

#include <glm/glm.hpp>

#include <span>
#include <string_view>

namespace glint::passes {

class ImageClearer {
public:
    // Throws gpu::GpuError when the device lacks shaderStorageImageWriteWithoutFormat.
    explicit ImageClearer(gpu::Context& ctx);

    // Fills `texture` (declared StorageWrite by the current pass) with `value`.
    void clear(rg::PassContext& pc, rg::Texture texture, glm::vec4 value = glm::vec4(0.0f)) const;

    // Declares pass `name` on the graphics queue, which zeroes each of
    // `textures`, and points each handle at its cleared version. The
    // clearer must outlive the plans compiled from `graph`.
    void addClearPass(rg::Graph& graph, std::string_view name, std::span<rg::Texture> textures) const;

private:
    gpu::Context& ctx_;
    gpu::Pipeline pipeline_;
};

} // namespace glint::passes
