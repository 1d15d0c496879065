// glint-minimal: the reflection frame in one sitting. Loads a scene (a
// built-in name or a glTF file), renders 16 frames of hybrid reflections
// along the scene's camera path and writes the last one as a PNG.
//
//   glint-minimal [SCENE] [OUT.png]     (defaults: plaza build/out/minimal.png)
// GLINT_VALIDATION=1 runs it under the validation layer (a message fails it).
#include "glint/gpu/context.h"
#include "glint/graph/executor.h"
#include "glint/graph/plan_cache.h"
#include "glint/graph/transfer.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/image_io.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <exception>
#include <string>

using namespace glint;

int main(int argc, char** argv) {
    std::string sceneName = "plaza", out = "build/out/minimal.png";
    CLI::App cli("glint-minimal: the reflection frame in one sitting");
    cli.add_option("scene", sceneName, "a built-in scene or a glTF file (default plaza)");
    cli.add_option("out", out, "the PNG written (default build/out/minimal.png)");
    CLI11_PARSE(cli, argc, argv);
    try {
        constexpr uint32_t kWidth = 640, kHeight = 360, kFrames = 16;

        // The device (GLINT_DEVICE picks one), the scene, and the three
        // objects an engine keeps: the renderer (pipelines, G-buffer
        // geometry, BVHs), the executor (command buffers, transient memory,
        // queues) and a host buffer the last frame is copied into.
        gpu::ContextOptions options;
        options.requireRayTracing = false;  // without ray tracing: screen space only
        gpu::Context ctx(options);
        scene::Scene scene = scene::loadScene(sceneName);
        passes::ReflectionRenderer renderer(ctx, scene);
        rg::Executor executor(ctx);
        rg::PlanCache plans;  // frames of one shape reuse one compiled plan
        const rg::HostReadback image(ctx, kWidth * kHeight * 4, "minimal.image");

        scene::Camera camera;
        camera.resolution = {kWidth, kHeight};
        camera.lens = scene.lens;
        for (uint32_t frame = 0; frame < kFrames; ++frame) {
            // Move the camera and the scene's animations to this frame's time.
            const float seconds = float(frame) / 30.0f;
            const scene::CameraPose pose = scene.cameraPath.evaluate(seconds);
            frame == 0 ? camera.reset(pose, frame) : camera.advance(pose, frame);
            scene::advanceScene(scene, seconds, &camera);

            // The wiring: declare the frame, bind its imports, compile, run.
            passes::ReflectionFrameSettings settings;
            settings.resetHistory = frame == 0;
            rg::Graph graph(executor.queueCaps());
            const passes::ReflectionFrame declared = renderer.addFrame(graph, camera, settings);
            rg::FrameResources resources;
            renderer.bind(resources, declared);
            if (frame + 1 == kFrames) image.copy(graph, resources, declared.output.color);
            executor.run(plans.compile(graph, executor.compileOptions()), resources);
        }
        executor.waitIdle();
        scene::writePng(out, kWidth, kHeight, image.as<uint8_t>());
        spdlog::info("{}: {} frames of {} reflections, wrote {}", scene.name, kFrames,
                     passes::modeName(renderer.tracesRays() ? passes::ReflectionMode::Hybrid : passes::ReflectionMode::Ssr),
                     out);
        ctx.waitIdle();
        if (ctx.validationEnabled() && ctx.validation().count() != 0) {
            spdlog::error("{}", ctx.validation().summary());
            return 2;
        }
        return 0;
    } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
        return 1;
    }
}
