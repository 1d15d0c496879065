#pragma once
// The whole reflection frame (passes::ReflectionRenderer) rendered for a
// few frames from the start of a scene's camera path, for the GPU tests
// that judge the composited image: the last frame's output read back.

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include <cstring>
#include <vector>

namespace glint::test {

// `frames` frames of `s` seen from its camera path at time 0, without
// jitter, each declared with `settings` (resetHistory set on the first);
// returns the last composited image, size.x x size.y RGBA8.
inline std::vector<uint8_t> renderComposited(gpu::Context& ctx, const scene::Scene& s, glm::uvec2 size,
                                             uint32_t frames, const passes::ReflectionFrameSettings& settings,
                                             const passes::ReflectionRendererOptions& options = {}) {
    rg::Executor executor(ctx);
    passes::ReflectionRenderer renderer(ctx, s, options);
    const rg::HostReadback readback(ctx, VkDeviceSize(size.x) * size.y * 4, "composited.readback");
    scene::Camera camera;
    camera.resolution = size;
    camera.lens = s.lens;
    camera.jitter = false;
    const scene::CameraPose pose = s.cameraPath.evaluate(0.0f);
    for (uint32_t i = 0; i < frames; ++i) {
        if (i == 0) {
            camera.reset(pose, i);
        } else {
            camera.advance(pose, i);
        }
        rg::Graph graph(executor.queueCaps());
        passes::ReflectionFrameSettings frame = settings;
        frame.resetHistory = i == 0;
        const passes::ReflectionFrame f = renderer.addFrame(graph, camera, frame);
        rg::FrameResources resources;
        renderer.bind(resources, f);
        if (i + 1 == frames) {
            readback.copy(graph, resources, f.output.color);
        }
        executor.run(graph.compile(executor.compileOptions()), resources);
    }
    executor.waitIdle();
    std::vector<uint8_t> rgba(size_t(size.x) * size.y * 4);
    std::memcpy(rgba.data(), readback.bytes().data(), rgba.size());
    return rgba;
}

} // namespace glint::test
