// Device failures end cleanly: with gpu/fault.h making the Nth device
// memory allocation, queue submission or host wait fail (out of device or
// host memory, a lost device), creating the reflection renderer and running
// its frames stops with one GpuError that names the failure and what it
// was for (the resource, the batch's passes, the frame waited for); then
// everything is destroyed without a hang, without a validation message (the
// fixture checks) and, under the sanitizers, without a leak.
#include "support/gpu_test.h"

#include "glint/gpu/error.h"
#include "glint/gpu/fault.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/builtin_scenes.h"

#include <doctest/doctest.h>

#include <array>
#include <string>

using namespace glint;

namespace {

constexpr uint32_t kFrames = 3;

struct Outcome {
    bool fired = false;
    std::string error;                               // empty: no exception
    std::array<uint64_t, gpu::kFaultSites> afterCreation{};  // calls counted once the renderer exists
    std::array<uint64_t, gpu::kFaultSites> afterFrames{};    // and once its frames are done (before teardown)
};

// Creates the renderer and runs kFrames hybrid frames of the plaza at 64x48
// on a context with `fault`; what happened.
Outcome run(std::optional<gpu::FaultInjection> fault) {
    gpu::ContextOptions options;
    options.fault = fault;
    test::GpuTest gpu(options);
    Outcome out;
    const auto counts = [&] {
        std::array<uint64_t, gpu::kFaultSites> c{};
        for (size_t s = 0; s < gpu::kFaultSites; ++s) c[s] = gpu.ctx().faults().calls(gpu::FaultSite(s));
        return c;
    };
    try {
        const scene::Scene plaza = scene::makeBuiltinScene("plaza");
        rg::Executor executor(gpu.ctx());
        passes::ReflectionRenderer renderer(gpu.ctx(), plaza);
        out.afterCreation = counts();
        scene::Camera camera;
        camera.resolution = {64, 48};
        camera.lens = plaza.lens;
        for (uint32_t i = 0; i < kFrames; ++i) {
            const scene::CameraPose pose = plaza.cameraPath.evaluate(0.1f * float(i));
            if (i == 0) {
                camera.reset(pose, i);
            } else {
                camera.advance(pose, i);
            }
            rg::Graph graph(executor.queueCaps());
            passes::ReflectionFrameSettings settings;
            settings.resetHistory = i == 0;
            const passes::ReflectionFrame f = renderer.addFrame(graph, camera, settings);
            rg::FrameResources resources;
            renderer.bind(resources, f);
            executor.run(graph.compile(executor.compileOptions()), resources);
        }
        executor.waitIdle();
        out.afterFrames = counts();
    } catch (const gpu::GpuError& e) {
        out.error = e.what();
    }
    out.fired = gpu.ctx().faults().fired();
    return out;
}

} // namespace

TEST_CASE("a failing allocation, submission or wait, while the renderer is created or while it renders, ends with "
          "one error naming it, and everything is released") {
    // Without a fault: how many calls of each kind creation and frames make.
    const Outcome clean = run(std::nullopt);
    REQUIRE(clean.error.empty());
    struct Case {
        gpu::FaultSite site;
        VkResult result;
        const char* names;  // a word the error must hold besides the result
    };
    const std::array<Case, 4> cases = {{
        {gpu::FaultSite::Allocation, VK_ERROR_OUT_OF_DEVICE_MEMORY, "for '"},
        {gpu::FaultSite::Allocation, VK_ERROR_OUT_OF_HOST_MEMORY, "for '"},
        {gpu::FaultSite::Submit, VK_ERROR_DEVICE_LOST, "'"},
        {gpu::FaultSite::Wait, VK_ERROR_DEVICE_LOST, "'"},
    }};
    for (const Case& c : cases) {
        const size_t s = size_t(c.site);
        CAPTURE(std::string(gpu::faultSiteName(c.site)));
        CAPTURE(std::string(gpu::resultName(c.result)));
        // The first call, the last one of creation, the first and the last
        // of the frames (where the kind has calls there).
        std::vector<uint64_t> calls = {1, clean.afterCreation[s]};
        if (clean.afterFrames[s] > clean.afterCreation[s]) {
            calls.push_back(clean.afterCreation[s] + 1);
            calls.push_back(clean.afterFrames[s]);
        }
        for (const uint64_t n : calls) {
            if (n == 0) continue;
            CAPTURE(n);
            const Outcome o = run(gpu::FaultInjection{c.site, n, c.result});
            CAPTURE(o.error);
            CHECK(o.fired);
            REQUIRE_FALSE(o.error.empty());
            CHECK(o.error.find(gpu::resultName(c.result)) != std::string::npos);
            CHECK(o.error.find(c.names) != std::string::npos);
            // The frames' submissions name their passes (or the history
            // image they clear), their waits the frame or the resource.
            if (n > clean.afterCreation[s] && c.site == gpu::FaultSite::Submit) {
                CHECK((o.error.find("pass") != std::string::npos || o.error.find("history") != std::string::npos));
            }
        }
    }
    // Some submissions and waits happen while rendering, not only at
    // creation: the cases above reached the frames.
    CHECK(clean.afterFrames[size_t(gpu::FaultSite::Submit)] > clean.afterCreation[size_t(gpu::FaultSite::Submit)]);
    CHECK(clean.afterFrames[size_t(gpu::FaultSite::Wait)] > clean.afterCreation[size_t(gpu::FaultSite::Wait)]);
}
