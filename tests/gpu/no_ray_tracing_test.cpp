// A device without ray tracing (gpu::ContextOptions::disableRayTracing, or
// GLINT_NO_RAY_TRACING=1, makes lavapipe one): the context enables no ray
// tracing extension, the reflection renderer builds no BVH and declares
// every mode as ssr, and the images are ssr's, with validation on.
#include "support/gpu_test.h"
#include "support/frame_render.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/builtin_scenes.h"

#include <doctest/doctest.h>

#include <cstdlib>
#include <string>

using namespace glint;

namespace {

gpu::ContextOptions withoutRayTracing() {
    gpu::ContextOptions o;
    o.disableRayTracing = true;
    o.requireRayTracing = false;
    return o;
}

} // namespace

TEST_CASE("without ray tracing the context enables none of it, and requiring it fails naming why") {
    {
        test::GpuTest gpu(withoutRayTracing());
        const gpu::Capabilities& caps = gpu.ctx().caps();
        CHECK_FALSE(caps.accelerationStructure);
        CHECK_FALSE(caps.rayQuery);
        CHECK_FALSE(caps.rayTracingPipeline);
        CHECK_FALSE(caps.canTraceRays());
    }
    gpu::ContextOptions required = withoutRayTracing();
    required.requireRayTracing = true;
    CHECK_THROWS_WITH_AS(gpu::Context{required}, doctest::Contains("ray tracing disabled"), gpu::GpuError);
    // The environment variable does the same as the option.
    setenv("GLINT_NO_RAY_TRACING", "1", 1);
    gpu::ContextOptions plain;
    plain.requireRayTracing = false;
    CHECK(gpu::rayTracingDisabled(plain));
    {
        test::GpuTest gpu(plain);
        CHECK_FALSE(gpu.ctx().caps().canTraceRays());
    }
    unsetenv("GLINT_NO_RAY_TRACING");
    CHECK_FALSE(gpu::rayTracingDisabled(plain));
}

TEST_CASE("without ray tracing every mode renders as ssr: no BVH pass, no BVH memory, ssr's image") {
    test::GpuTest gpu(withoutRayTracing());
    scene::Scene plaza = scene::makeBuiltinScene("plaza");
    const glm::uvec2 size{64, 48};

    // The plan: declared in ssr mode whatever was asked, with no BVH.
    {
        rg::Executor executor(gpu.ctx());
        passes::ReflectionRenderer renderer(gpu.ctx(), plaza);
        CHECK_FALSE(renderer.tracesRays());
        scene::Camera camera;
        camera.resolution = size;
        camera.lens = plaza.lens;
        camera.reset(plaza.cameraPath.evaluate(0.0f), 0);
        for (const passes::ReflectionMode mode :
             {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Rt, passes::ReflectionMode::Ssr}) {
            CAPTURE(std::string(passes::modeName(mode)));
            rg::Graph graph(executor.queueCaps());
            passes::ReflectionFrameSettings settings;
            settings.mode = mode;
            const passes::ReflectionFrame f = renderer.addFrame(graph, camera, settings);
            CHECK(f.mode == passes::ReflectionMode::Ssr);
            CHECK_FALSE(f.bvh.has_value());
            CHECK_FALSE(f.rt.has_value());
            const rg::Plan plan = graph.compile(executor.compileOptions());
            CHECK(plan.findPass("bvh_update") == nullptr);
            CHECK(plan.findPass("rt_trace") == nullptr);
            CHECK(plan.findPass("sslr") != nullptr);
        }
        CHECK(renderer.bvhGpuStats().blasBuilds == 0u);
        CHECK(renderer.bvhGpuStats().tlasInstances == 0u);
    }

    // The images: hybrid's and rt's are ssr's, bit for bit.
    std::vector<std::vector<uint8_t>> images;
    for (const passes::ReflectionMode mode :
         {passes::ReflectionMode::Ssr, passes::ReflectionMode::Hybrid, passes::ReflectionMode::Rt}) {
        passes::ReflectionFrameSettings settings;
        settings.mode = mode;
        images.push_back(test::renderComposited(gpu.ctx(), plaza, size, 3, settings));
    }
    CHECK(images[1] == images[0]);
    CHECK(images[2] == images[0]);
}
