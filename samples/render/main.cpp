// glint-render: the headless renderer. Until the reflection pipeline lands
// it renders the smoke scene with every ray backend the device has and
// writes one PNG per backend, or (--scene plaza) the plaza's G-buffer lit
// colour through the render graph.

#include "common/app.h"
#include "graph/executor.h"
#include "graph/graph.h"
#include "passes/gbuffer.h"
#include "passes/smoke_trace.h"
#include "scene/animation.h"
#include "scene/builtin_scenes.h"

#include "glint/packing.h"

#include <glm/gtc/packing.hpp>

#include <spdlog/spdlog.h>

#include <cmath>

#include <algorithm>

using namespace glint;

namespace {

// Krzysztof Narkowicz's fit of the ACES filmic curve ("ACES Filmic Tone
// Mapping Curve", 2016): a film-like shoulder in five constants.
float tonemapAces(float x) {
    x = std::max(x, 0.0f);
    return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

// One frame of the G-buffer at size x size from the scene's camera path at
// `seconds`; its lit colour copied out of the graph, tonemapped and sRGB-encoded.
std::vector<uint8_t> renderPlazaLit(gpu::Context& ctx, uint32_t size, float seconds) {
    scene::Scene plaza = scene::makePlaza();
    scene::Camera camera;
    camera.resolution = {size, size};
    camera.lens = plaza.lens;
    camera.jitter = false;  // a still image, no temporal resolve to undo it
    camera.reset(plaza.cameraPath.evaluate(seconds), 0);
    // Places the camera node (and the first-person arm under it) at the camera.
    scene::advanceScene(plaza, seconds, &camera);

    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, plaza);
    gpu::Buffer pixels(ctx, {VkDeviceSize(size) * size * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             gpu::MemoryUsage::Readback, "plaza_lit.readback"});

    rg::Graph graph(executor.queueCaps());
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    const rg::Buffer target = graph.importBuffer(
        "plaza_lit.readback", {{pixels.size()}, rg::BoundaryState::of(rg::Access::None),
                               rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT,
                                                      VK_IMAGE_LAYOUT_UNDEFINED)});
    struct CopyData {
        rg::Texture lit;
        rg::Buffer target;
    };
    const CopyData& copy = graph.addPass<CopyData>(
        "copy_lit", rg::Queue::Graphics,
        [&](rg::Builder& b, CopyData& d) {
            d.lit = b.read(gbuf.lit, rg::Access::TransferSrc);
            d.target = b.write(target, rg::Access::TransferDst);
        },
        [size](const CopyData& d, rg::PassContext& pc) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {size, size, 1};
            vkCmdCopyImageToBuffer(pc.cmd(), pc.image(d.lit).handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.buffer(d.target).handle(), 1, &region);
        });
    graph.markOutput(copy.target);
    rg::FrameResources resources;
    resources.bind(target, pixels);
    executor.run(graph.compile(executor.compileOptions()), resources);
    executor.waitIdle();

    const auto halves = pixels.mappedSpan<const uint16_t>();
    std::vector<uint8_t> rgba(size_t(size) * size * 4);
    for (size_t i = 0; i < size_t(size) * size; ++i) {
        for (size_t c = 0; c < 3; ++c) {
            const float linear = tonemapAces(glm::unpackHalf1x16(halves[i * 4 + c]));
            rgba[i * 4 + c] = uint8_t(shader::encodeUnorm8(shader::linearToSrgb(linear)));
        }
        rgba[i * 4 + 3] = 255;
    }
    for (const rg::PassTiming& t : executor.timings()) {
        if (t.milliseconds) spdlog::info("{}: {:.3f} ms GPU", t.name, *t.milliseconds);
    }
    return rgba;
}

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-render", [&] {
        app::Args args(argc, argv, "usage: glint-render [--scene smoke|plaza] [--size N] [--out DIR] [--time SECONDS]",
                       {"scene", "size", "out", "time"}, {});
        const std::string sceneName = args.get("scene", "smoke");
        if (sceneName != "smoke" && sceneName != "plaza") {
            throw std::runtime_error("--scene " + sceneName + ": unknown scene (available: smoke, plaza)");
        }
        const uint32_t size = args.getUint("size", 256);
        if (size == 0 || size > 8192) {
            throw std::runtime_error("--size " + std::to_string(size) + ": must be 1..8192");
        }
        const std::string outDir = args.get("out", "build/out");
        // Camera path time: 3 s looks down the plaza past the puddles
        // (the path starts behind a palm trunk).
        const std::string timeText = args.get("time", "3");
        float seconds = 0.0f;
        try {
            size_t used = 0;
            seconds = std::stof(timeText, &used);
            if (used != timeText.size() || !std::isfinite(seconds) || seconds < 0.0f) throw std::invalid_argument("");
        } catch (const std::exception&) {
            throw std::runtime_error("--time " + timeText + ": not a non-negative number of seconds");
        }

        gpu::Context ctx(args.contextOptions());
        if (sceneName == "plaza") {
            app::writePng(outDir + "/plaza_lit.png", size, size, renderPlazaLit(ctx, size, seconds));
            ctx.waitIdle();
            return app::validationClean(ctx) ? 0 : 2;
        }
        passes::SmokeTracer tracer(ctx, scene::makeSmokeScene());
        for (auto backend : passes::availableBackends(ctx)) {
            const auto result = tracer.trace(backend, size, size);
            const std::string path = outDir + "/smoke_" + passes::backendName(backend) + ".png";
            app::writePng(path, size, size, passes::smokeImage(result.hits, size, size));
            if (result.gpuMilliseconds) {
                spdlog::info("{}: {:.3f} ms GPU, {:.2f} Mrays/s", passes::backendName(backend), *result.gpuMilliseconds,
                             double(size) * size / (*result.gpuMilliseconds * 1e3));
            }
        }
        ctx.waitIdle();
        return app::validationClean(ctx) ? 0 : 2;
    });
}
