// The plan of the real reflection frame (passes::ReflectionRenderer::
// addFrame, the declaration the samples run), compiled for a device with a
// separate async compute family and for one without. Nothing is executed:
// the renderer needs a device for its pipelines, the plans do not, so the
// two-queue plan is compiled here on lavapipe's one family too.
//
// Where graphics waits for the BVH: Far Cry 6 waits before SSLR; our SSLR
// does not read the TLAS, so the wait sits at the first pass that does (the
// ray tracer), later, with more of the frame overlapping the build. The
// graph tests (tests/graph/reflection_test.cpp) check the same rules on a
// synthetic frame whose SSLR reads the TLAS; these check the real one.
#include "support/gpu_test.h"

#include "glint/graph/graph.h"
#include "glint/graph/ir.h"
#include "glint/graph/plan.h"
#include "glint/graph/plan_cache.h"
#include "glint/graph/synthetic.h"
#include "glint/graph/verify.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/camera.h"

#include <doctest/doctest.h>

#include <string>
#include <string_view>
#include <vector>

using namespace glint;

namespace {

struct RealFrame {
    scene::Scene plaza = scene::makeBuiltinScene("plaza");
    passes::ReflectionRenderer renderer;
    scene::Camera camera;
    uint64_t frameIndex = 0;

    RealFrame(gpu::Context& ctx, glm::uvec2 size) : renderer(ctx, plaza) {
        camera.lens = plaza.lens;
        camera.resolution = size;
        camera.reset(plaza.cameraPath.evaluate(3.0f), 0);
    }

    // Declares the next frame (a still camera) and compiles it.
    rg::Plan plan(const rg::QueueCaps& caps, passes::ReflectionMode mode, bool aliasing = true) {
        camera.advance(plaza.cameraPath.evaluate(3.0f), ++frameIndex);
        rg::Graph graph(caps);
        passes::ReflectionFrameSettings settings;
        settings.mode = mode;
        renderer.addFrame(graph, camera, settings);
        rg::CompileOptions options;
        options.aliasing = aliasing;
        rg::Plan plan = graph.compile(options);
        const rg::VerifyReport report = rg::verify(plan);
        INFO(plan.toText());
        REQUIRE_MESSAGE(report.ok(), report.text());
        return plan;
    }
};

// The device's ray tracing support with the queue families of `base`.
rg::QueueCaps capsFor(gpu::Context& ctx, rg::QueueCaps base) {
    base.rayQuery = ctx.caps().rayQuery;
    base.rayTracingPipeline = ctx.caps().rayTracingPipeline;
    return base;
}

std::string_view nameOf(const rg::Plan& plan, const rg::PlannedPass& p) { return plan.passName(p); }

bool reads(const rg::Plan& plan, const rg::PlannedPass& p, uint32_t resource) {
    const rg::ir::Pass& pass = plan.declaration->passes[p.pass];
    for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
        const rg::ir::Use& use = plan.declaration->uses[u];
        if (use.resource == resource && !use.writes) return true;
    }
    return false;
}

// Planned-pass index of the first pass (submission order) reading a TLAS.
size_t firstTlasReader(const rg::Plan& plan) {
    const uint32_t tlas = plan.findResource("bvh.tlas");
    REQUIRE(tlas != rg::kNoIndex);
    for (size_t i = 0; i < plan.passes.size(); ++i) {
        if (reads(plan, plan.passes[i], tlas)) return i;
    }
    FAIL("no pass reads bvh.tlas");
    return 0;
}

} // namespace

TEST_CASE("the real frame on two queues: the BVH update alone on async compute overlaps shadow map, G-buffer, ray "
          "generation and SSLR; graphics waits for it once, at the first TLAS reader") {
    test::GpuTest gpu;
    RealFrame frame(gpu.ctx(), {320, 180});
    const rg::QueueCaps caps = capsFor(gpu.ctx(), rg::synthetic::twoQueueCaps());
    for (const passes::ReflectionMode mode : {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Rt}) {
        CAPTURE(std::string(passes::modeName(mode)));
        const rg::Plan plan = frame.plan(caps, mode);
        INFO(plan.toText());

        // The build: one pass, alone in the one async compute batch, first
        // in submission order so the GPU starts it at once.
        const rg::PlannedPass* bvh = plan.findPass("bvh_update");
        REQUIRE(bvh != nullptr);
        CHECK((bvh->queue == rg::Queue::AsyncCompute));
        CHECK(plan.batchCount(rg::Queue::AsyncCompute) == 1u);
        CHECK(plan.batches[bvh->batch].passCount == 1u);
        CHECK(bvh == &plan.passes.front());
        for (const rg::PlannedPass& p : plan.passes) {
            if (&p != bvh) CHECK_MESSAGE((p.queue == rg::Queue::Graphics), nameOf(plan, p));
        }

        // The first pass that reads the TLAS is the ray tracer, and it opens
        // the graphics batch that waits for the build: in this frame (offset
        // 0), from the async compute queue, in the tracer's stage.
        const size_t reader = firstTlasReader(plan);
        CHECK(nameOf(plan, plan.passes[reader]) == "rt_trace");
        const rg::Batch& waiting = plan.batches[plan.passes[reader].batch];
        CHECK(plan.passes.data() + waiting.firstPass == &plan.passes[reader]);
        uint32_t sameFrameWaits = 0;
        for (const rg::Batch& batch : plan.batches) {
            if (batch.queue != rg::Queue::Graphics) continue;
            for (const rg::SemaphoreWait& w : plan.waitsOf(batch)) {
                if (w.frameOffset != 0) continue;
                ++sameFrameWaits;
                CHECK(&batch == &waiting);
                CHECK((w.queue == rg::Queue::AsyncCompute));
                CHECK(w.batch == plan.batches[bvh->batch].ordinal);
                const bool tracerStage = (w.stages & (VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                                                      VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR)) != 0;
                CHECK(tracerStage);
            }
        }
        CHECK(sameFrameWaits == 1u);

        // Everything before the reader runs in graphics batches that do not
        // wait for this frame's build: they overlap it.
        std::vector<std::string_view> overlapping;
        for (size_t i = 0; i < reader; ++i) {
            const rg::PlannedPass& p = plan.passes[i];
            if (&p == bvh) continue;
            overlapping.push_back(nameOf(plan, p));
            for (const rg::SemaphoreWait& w : plan.waitsOf(plan.batches[p.batch])) CHECK(w.frameOffset != 0);
        }
        std::vector<std::string_view> expected = {"shadow_map", "gbuffer", "ray_generation"};
        if (mode == passes::ReflectionMode::Hybrid) {
            expected.push_back("feedback");
            expected.push_back("sslr");
        }
        for (const std::string_view name : expected) {
            CHECK_MESSAGE(std::find(overlapping.begin(), overlapping.end(), name) != overlapping.end(), name);
        }
        // The TLAS crosses queues: concurrent sharing, no ownership transfer.
        CHECK(plan.resources[plan.findResource("bvh.tlas")].crossQueue);
    }
}

TEST_CASE("the real frame on one queue: the same passes in the same order on graphics, synchronised by barriers") {
    test::GpuTest gpu;
    RealFrame frame(gpu.ctx(), {320, 180});
    const rg::QueueCaps two = capsFor(gpu.ctx(), rg::synthetic::twoQueueCaps());
    const rg::QueueCaps one = capsFor(gpu.ctx(), rg::synthetic::oneQueueCaps());
    const rg::Plan twoPlan = frame.plan(two, passes::ReflectionMode::Hybrid);
    const rg::Plan onePlan = frame.plan(one, passes::ReflectionMode::Hybrid);
    INFO(onePlan.toText());
    REQUIRE(onePlan.passes.size() == twoPlan.passes.size());
    for (size_t i = 0; i < onePlan.passes.size(); ++i) {
        CHECK(nameOf(onePlan, onePlan.passes[i]) == nameOf(twoPlan, twoPlan.passes[i]));
        CHECK((onePlan.passes[i].queue == rg::Queue::Graphics));
    }
    CHECK(onePlan.batchCount(rg::Queue::AsyncCompute) == 0u);
    for (const rg::Batch& batch : onePlan.batches) {
        for (const rg::SemaphoreWait& w : onePlan.waitsOf(batch)) CHECK(w.frameOffset != 0);
    }
    // The ray tracer's read of the TLAS is ordered after the build by a
    // barrier before it.
    const size_t reader = firstTlasReader(onePlan);
    const uint32_t tlas = onePlan.findResource("bvh.tlas");
    bool barrier = false;
    for (const rg::Barrier& b : onePlan.barriersBefore(onePlan.passes[reader])) {
        barrier = barrier || (b.resource == tlas && (b.srcStages & VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR));
    }
    CHECK(barrier);
    CHECK_FALSE(onePlan.resources[tlas].crossQueue);
}

TEST_CASE("the real frame at 1920x1080: transient memory aliasing saves a quarter of it") {
    test::GpuTest gpu;
    RealFrame frame(gpu.ctx(), {1920, 1080});
    const rg::QueueCaps caps = capsFor(gpu.ctx(), rg::synthetic::twoQueueCaps());
    for (const passes::ReflectionMode mode :
         {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Ssr, passes::ReflectionMode::Rt}) {
        const rg::Plan plan = frame.plan(caps, mode);
        const rg::Plan unaliased = frame.plan(caps, mode, false);
        const double saving = 1.0 - double(plan.stats.aliasedTransientBytes) / double(plan.stats.transientBytes);
        MESSAGE(passes::modeName(mode) << ": transients " << double(plan.stats.transientBytes) / (1 << 20)
                                       << " MiB, aliased into " << double(plan.stats.aliasedTransientBytes) / (1 << 20)
                                       << " MiB (" << 100.0 * saving << "% saved)");
        // Without aliasing the heaps hold every transient on its own.
        CHECK(unaliased.stats.aliasedTransientBytes >= unaliased.stats.transientBytes);
        CHECK(plan.stats.aliasedTransientBytes < plan.stats.transientBytes);
        CHECK(saving > 0.25);
    }
}

TEST_CASE("every debug view is declared in the modes its table row names, and refused in the others") {
    test::GpuTest gpu;
    RealFrame frame(gpu.ctx(), {96, 64});
    const rg::QueueCaps caps = capsFor(gpu.ctx(), {});
    for (const passes::ReflectionMode mode :
         {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Ssr, passes::ReflectionMode::Rt}) {
        for (const passes::DebugViewInfo& view : passes::debugViews()) {
            INFO(view.name << " in " << passes::modeName(mode));
            frame.camera.advance(frame.plaza.cameraPath.evaluate(3.0f), ++frame.frameIndex);
            rg::Graph graph(caps);
            passes::ReflectionFrameSettings settings;
            settings.mode = mode;
            settings.debugView = std::string(view.name);
            if (view.modes.has(mode)) {
                const passes::ReflectionFrame f = frame.renderer.addFrame(graph, frame.camera, settings);
                CHECK(f.output.color.valid());
                const rg::VerifyReport report = rg::verify(graph.compile());
                CHECK_MESSAGE(report.ok(), report.text());
            } else {
                CHECK_THROWS_WITH(frame.renderer.addFrame(graph, frame.camera, settings),
                                  doctest::Contains("not produced in mode"));
            }
        }
    }
    frame.camera.advance(frame.plaza.cameraPath.evaluate(3.0f), ++frame.frameIndex);
    passes::ReflectionFrameSettings unknown;
    unknown.debugView = "no_such_view";
    rg::Graph graph(caps);
    CHECK_THROWS_WITH(frame.renderer.addFrame(graph, frame.camera, unknown), doctest::Contains("unknown debug view"));
}

TEST_CASE("the real frame reuses its plan on steady frames, and the reused plan is a fresh compile's") {
    test::GpuTest gpu;
    RealFrame frame(gpu.ctx(), {192, 108});
    rg::PlanCache cache;
    const rg::QueueCaps caps = capsFor(gpu.ctx(), rg::synthetic::twoQueueCaps());
    constexpr uint32_t kFrames = 8;
    for (uint32_t i = 0; i < kFrames; ++i) {
        INFO("frame " << i);
        frame.camera.advance(frame.plaza.cameraPath.evaluate(3.0f), ++frame.frameIndex);
        rg::Graph graph(caps);
        passes::ReflectionFrameSettings settings;
        settings.resetHistory = i == 0;
        frame.renderer.addFrame(graph, frame.camera, settings);
        const rg::Plan cached = cache.compile(graph);
        CHECK(cached.toText() == graph.compile().toText());
        CHECK(cached.declaration.get() == &graph.declaration());
    }
    // A still camera's frames have one shape; a BVH buffer that grows (an
    // import's size) may add a compile or two early on. Measured: only the
    // first frame is compiled.
    MESSAGE(cache.misses(), " of ", kFrames, " frames compiled");
    CHECK(cache.misses() >= 1);
    CHECK(cache.misses() <= 3);
}
