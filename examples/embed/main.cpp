// An engine's frame built on the installed Glint package: the reflection
// passes and a pass of the engine's own (a blur of the composited image,
// with its own shader) declared in one graph, so the graph orders,
// synchronizes and allocates both. Renders 4 frames of the built-in plaza
// with the Khronos validation layer and synchronization validation on,
// writes the last blurred frame as a PNG, and fails on any validation
// message.
//
//   glint-embed OUT.png [WIDTHxHEIGHT]
#include <glint/gpu/context.h>
#include <glint/gpu/descriptors.h>
#include <glint/gpu/pipeline.h>
#include <glint/graph/executor.h>
#include <glint/graph/transfer.h>
#include <glint/graph/verify.h>
#include <glint/passes/reflection_frame.h>
#include <glint/scene/animation.h>
#include <glint/scene/builtin_scenes.h>
#include <glint/scene/image_io.h>

#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <string>

using namespace glint;

namespace {

// The engine's pass: reads the frame's composited image, writes a new one.
rg::Texture addBlurPass(rg::Graph& graph, const gpu::Context& ctx, const gpu::Pipeline& blur, rg::Texture source,
                        uint32_t width, uint32_t height) {
    struct BlurData {
        rg::Texture source, target;
    };
    const BlurData& data = graph.addPass<BlurData>(
        "engine.blur", rg::Queue::Graphics,
        [&](rg::Builder& b, BlurData& d) {
            d.source = b.read(source, rg::Access::StorageRead);
            d.target = b.write(b.createTexture("engine.blurred", {width, height, 1, 1, 1, VK_FORMAT_R8G8B8A8_UNORM}),
                               rg::Access::StorageWrite);
        },
        [&ctx, &blur, width, height](const BlurData& d, rg::PassContext& pc) {
            gpu::PushDescriptors(blur)
                .storageImage(0, pc.view(d.source))
                .storageImage(1, pc.view(d.target))
                .push(ctx, pc.cmd());
            pc.dispatch(blur, (width + 7) / 8, (height + 7) / 8);
        });
    return data.target;
}

} // namespace

int main(int argc, char** argv) {
    try {
        const std::string out = argc > 1 ? argv[1] : "embed.png";
        uint32_t width = 96, height = 64;
        if (argc > 2 && std::sscanf(argv[2], "%ux%u", &width, &height) != 2) {
            throw std::runtime_error(std::string("size '") + argv[2] + "': expected WIDTHxHEIGHT");
        }
        gpu::ContextOptions contextOptions;
        contextOptions.validation = true;
        gpu::Context ctx(contextOptions);
        spdlog::info("device: {}; Glint's shaders from {}", ctx.caps().deviceName, gpu::shaderDirectory().string());

        scene::Scene scene = scene::makeBuiltinScene("plaza");
        passes::ReflectionRenderer renderer(ctx, scene);
        rg::Executor executor(ctx);
        const gpu::Pipeline blur = gpu::createComputePipeline(
            ctx, {EMBED_BLUR_SPV,
                  {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_SHADER_STAGE_COMPUTE_BIT},
                   {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_SHADER_STAGE_COMPUTE_BIT}},
                  0,
                  "engine.blur"});
        const rg::HostReadback image(ctx, VkDeviceSize(width) * height * 4, "engine.readback");

        scene::Camera camera;
        camera.resolution = {width, height};
        camera.lens = scene.lens;
        constexpr uint32_t kFrames = 4;
        for (uint32_t i = 0; i < kFrames; ++i) {
            const float seconds = 3.0f + float(i) / 60.0f;
            const scene::CameraPose pose = scene.cameraPath.evaluate(seconds);
            i == 0 ? camera.reset(pose, i) : camera.advance(pose, i);
            scene::advanceScene(scene, seconds, &camera);

            passes::ReflectionFrameSettings settings;
            settings.resetHistory = i == 0;
            rg::Graph graph(executor.queueCaps());
            const passes::ReflectionFrame frame = renderer.addFrame(graph, camera, settings);
            const rg::Texture blurred = addBlurPass(graph, ctx, blur, frame.output.color, width, height);
            rg::FrameResources resources;
            renderer.bind(resources, frame);
            if (i + 1 == kFrames) image.copy(graph, resources, blurred);

            const rg::Plan plan = graph.compile(executor.compileOptions());
            if (const rg::VerifyReport report = rg::verify(plan); !report.ok()) {
                throw std::runtime_error("frame " + std::to_string(i) + ": the plan verifier rejects the plan:\n" +
                                         report.text());
            }
            executor.run(plan, resources);
        }
        executor.waitIdle();
        scene::writePng(out, width, height, image.as<uint8_t>());
        spdlog::info("wrote {} ({}x{}, {} mode)", out, width, height, passes::modeName(renderer.tracesRays()
                                                                                           ? passes::ReflectionMode::Hybrid
                                                                                           : passes::ReflectionMode::Ssr));
        ctx.waitIdle();
        if (const size_t messages = ctx.validation().count(); messages != 0) {
            spdlog::error("{}", ctx.validation().summary());
            return 2;
        }
        spdlog::info("validation: 0 messages");
        return 0;
    } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
        return 1;
    }
}
