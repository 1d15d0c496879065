// The synthetic reflection frame (glint/graph/synthetic.h, shaped after
// DESIGN §3, its SSLR reading the TLAS as Far Cry 6's does) must compile to
// the shape the technique asks for: BVH update on async compute overlapping
// G-buffer and ray generation, graphics waiting for it exactly before SSLR;
// and on one queue, the same frame correctly synchronised on graphics
// alone. The real frame's plan: tests/gpu/reflection_frame_plan_test.cpp.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

Plan reflectionPlan(const QueueCaps& caps, const synthetic::ReflectionOptions& options = {}) {
    Graph g(caps);
    synthetic::declare(g, synthetic::reflectionFrame(options));
    return compileChecked(g);
}

} // namespace

TEST_CASE("synthetic frame, two queues: the BVH update runs on compute beside G-buffer and ray generation, graphics waits before SSLR") {
    const Plan plan = reflectionPlan(twoQueues());
    const PlannedPass& bvh = passNamed(plan, "bvh_update");
    CHECK((bvh.queue == Queue::AsyncCompute));
    CHECK(plan.batches[bvh.batch].passCount == 1); // its signal covers nothing else

    // G-buffer and ray generation share a batch that waits for nothing this
    // frame, so they overlap the build.
    const Batch& early = batchOf(plan, "gbuffer");
    CHECK(&early == &batchOf(plan, "generate_rays"));
    for (const SemaphoreWait& w : plan.waitsOf(early)) CHECK(w.frameOffset == -1);
    CHECK((early.queue == Queue::Graphics));

    // SSLR starts the next graphics batch, which waits on the BVH batch in
    // SSLR's own stage.
    const Batch& sslr = batchOf(plan, "sslr");
    CHECK(&sslr != &early);
    REQUIRE(sslr.passCount >= 1);
    CHECK(plan.passName(plan.passesOf(sslr)[0]) == "sslr");
    const auto waits = plan.waitsOf(sslr);
    REQUIRE(waits.size() == 1);
    CHECK((waits[0].queue == Queue::AsyncCompute));
    CHECK(waits[0].batch == plan.batches[bvh.batch].ordinal);
    CHECK(waits[0].frameOffset == 0);
    CHECK(waits[0].stages == VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);

    // The rest of the frame follows in that batch; nothing else waits this frame.
    for (const char* pass : {"trace_reflections", "trace_particles", "integrate", "temporal", "composite", "tonemap"})
        CHECK(&batchOf(plan, pass) == &sslr);
    CHECK(plan.batchCount(Queue::Graphics) == 2);
    CHECK(plan.batchCount(Queue::AsyncCompute) == 1);

    // Submission: the build goes first so the GPU starts it at once.
    CHECK(indexOf(plan, "bvh_update") == 0);
    CHECK(plan.resources[resourceNamed(plan, "bvh.tlas")].crossQueue);
}

TEST_CASE("synthetic frame, two queues: next frame's BVH rebuild waits for this frame's trace reads of the TLAS") {
    const Plan plan = reflectionPlan(twoQueues());
    const auto waits = plan.waitsOf(batchOf(plan, "bvh_update"));
    REQUIRE(waits.size() == 1);
    CHECK((waits[0].queue == Queue::Graphics));
    CHECK(waits[0].frameOffset == -1);
    CHECK(waits[0].batch == plan.batchCount(Queue::Graphics) - 1);
    CHECK(waits[0].stages == VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
}

TEST_CASE("synthetic frame, one queue: the same frame runs on graphics alone, synchronised by barriers") {
    const Plan plan = reflectionPlan(oneQueue());
    CHECK(plan.batches.size() == 1);
    CHECK(plan.waits.empty());
    CHECK(plan.passes.size() == 12);
    for (const PlannedPass& p : plan.passes) CHECK((p.queue == Queue::Graphics));
    // Declaration order: the build comes first.
    CHECK(indexOf(plan, "bvh_update") == 0);
    // SSLR's ray query sees the build through a barrier instead of a semaphore.
    const auto tlas = barriersOn(plan, "sslr", "bvh.tlas");
    REQUIRE(tlas.size() == 1);
    CHECK(tlas[0].srcStages == VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    CHECK((tlas[0].srcAccess & VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR) != 0);
    CHECK(tlas[0].dstAccess == VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    // And the rebuild waits for last frame's tracing on the same queue.
    const auto rebuild = barriersOn(plan, "bvh_update", "bvh.tlas");
    REQUIRE(rebuild.size() == 1);
    CHECK(rebuild[0].dstStages == VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    CHECK(rebuild[0].srcAccess == 0);
}

TEST_CASE("the synthetic reflection frame with a ray tracing pipeline verifies on both queue setups") {
    synthetic::ReflectionOptions options;
    options.tracePipeline = Pipeline::RayTracing;
    for (const QueueCaps& caps : {twoQueues(), oneQueue()}) {
        const Plan plan = reflectionPlan(caps, options);
        const auto bs = barriersOn(plan, "trace_reflections", "bvh.tlas");
        // SSLR's compute-stage ray query already saw the build; the ray tracing
        // stage needs its own visibility.
        REQUIRE(bs.size() == 1);
        CHECK(bs[0].dstStages == VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR);
    }
}

TEST_CASE("the synthetic reflection frame saves at least 40% of its transient memory at 1080p by aliasing") {
    const Plan plan = reflectionPlan(twoQueues());
    const double saved =
        1.0 - static_cast<double>(plan.stats.aliasedTransientBytes) / static_cast<double>(plan.stats.transientBytes);
    INFO(plan.toText());
    CHECK(saved >= 0.40);
    // Aliases start from UNDEFINED.
    for (const Barrier& b : plan.barriers)
        if (b.aliasing && plan.resources[b.resource].kind == ResourceKind::Texture)
            CHECK(b.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
}

TEST_CASE("the synthetic reflection frame's output ends ready to present") {
    const Plan plan = reflectionPlan(twoQueues());
    const uint32_t output = resourceNamed(plan, "output");
    bool presented = false;
    for (const Batch& b : plan.batches)
        for (const Barrier& br : plan.barriersAfter(b))
            if (br.resource == output) {
                CHECK(br.newLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
                presented = true;
            }
    CHECK(presented);
}
