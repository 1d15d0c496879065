// The verifier: every compiled plan passes it, and broken plans do not.

#include <doctest/doctest.h>

#include <string>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

Plan randomPlan(uint64_t seed, const QueueCaps& caps, synthetic::RandomOptions options = {},
                const CompileOptions& compileOptions = {}) {
    options.seed = seed;
    if (options.passes == synthetic::RandomOptions{}.passes) options.passes = 6 + static_cast<uint32_t>(seed % 40);
    Graph g(caps);
    synthetic::declare(g, synthetic::randomFrame(options));
    return compile(g, caps, compileOptions);
}

void expectClean(const Plan& plan, uint64_t seed) {
    const VerifyReport report = verify(plan);
    if (!report.ok()) {
        INFO("seed " << seed);
        INFO(plan.toText());
        FAIL_CHECK(report.text());
    }
}

// write -> read -> write -> read of one texture and one buffer on one queue:
// every barrier in it matters.
Plan chainPlan() {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    Buffer buf = g.createBuffer("buf", {1024});
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "w1", Queue::Graphics,
        [&](Builder& b) {
            t = b.write(t, Access::StorageWrite);
            buf = b.write(buf, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "r1", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(t, Access::SampledRead);
            b.read(buf, Access::IndirectArgs);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "w2", Queue::Graphics,
        [&](Builder& b) {
            t = b.write(t, Access::TransferDst);
            buf = b.write(buf, Access::StorageReadWrite);
        },
        noop);
    g.addPass(
        "r2", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::TransferSrc);
            b.read(buf, Access::StorageRead);
            out = b.write(out, Access::TransferDst);
        },
        noop);
    g.markOutput(out);
    return compileChecked(g);
}

} // namespace

TEST_CASE("random graphs verify on two queues") {
    for (uint64_t seed = 1; seed <= 300; ++seed) expectClean(randomPlan(seed, twoQueues()), seed);
}

TEST_CASE("random graphs verify on one queue") {
    for (uint64_t seed = 1; seed <= 300; ++seed) expectClean(randomPlan(seed, oneQueue()), seed);
}

TEST_CASE("random graphs verify with aliasing off and without imports, history or subresources") {
    for (uint64_t seed = 1; seed <= 150; ++seed) {
        synthetic::RandomOptions options;
        options.imports = seed % 2 == 0;
        options.history = seed % 3 == 0;
        options.subresources = seed % 5 != 0;
        options.asyncCompute = seed % 7 != 0;
        options.passes = 4 + static_cast<uint32_t>(seed % 80);
        CompileOptions compileOptions;
        compileOptions.aliasing = seed % 2 == 1;
        for (const QueueCaps& caps : {twoQueues(), oneQueue()})
            expectClean(randomPlan(seed * 7919, caps, options, compileOptions), seed);
    }
}

TEST_CASE("the verifier catches any deleted barrier of a plan where each one matters") {
    const Plan plan = chainPlan();
    REQUIRE(plan.barriers.size() >= 6);
    VerifyOptions options;
    options.checkRedundancy = false;
    for (uint32_t i = 0; i < plan.barriers.size(); ++i) {
        INFO("barrier " << i << " on " << plan.resourceName(plan.barriers[i].resource));
        CHECK_FALSE(verify(withoutBarrier(plan, i), options).ok());
    }
}

TEST_CASE("the verifier catches a barrier that does not flush the write") {
    Plan plan = chainPlan();
    const uint32_t i = barrierIndex(plan, "r1", "buf");
    REQUIRE(plan.barriers[i].srcAccess != 0);
    plan.barriers[i].srcAccess = 0;
    const VerifyReport report = verify(plan);
    CHECK(report.has(Violation::Kind::ReadAfterWrite));
    CHECK(contains(report.text(), "'r1'"));
    CHECK(contains(report.text(), "'buf'"));
}

TEST_CASE("the verifier catches a barrier with the wrong destination stage") {
    Plan plan = chainPlan();
    const uint32_t i = barrierIndex(plan, "r1", "buf");
    plan.barriers[i].dstStages = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT; // the indirect stage is left out
    CHECK(verify(plan).has(Violation::Kind::ReadAfterWrite));
}

TEST_CASE("the verifier catches a write that does not wait for earlier reads") {
    Plan plan = chainPlan();
    const uint32_t i = barrierIndex(plan, "w2", "buf");
    plan.barriers[i].srcStages = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT; // r1 read it at DRAW_INDIRECT
    CHECK(verify(plan).has(Violation::Kind::WriteAfterRead));
}

TEST_CASE("the verifier catches a wrong layout") {
    Plan plan = chainPlan();
    const uint32_t i = barrierIndex(plan, "r1", "t");
    plan.barriers[i].newLayout = VK_IMAGE_LAYOUT_GENERAL;
    CHECK(verify(plan).has(Violation::Kind::Layout));
}

namespace {

// A swapchain image drawn and presented.
Plan presentPlan() {
    Graph g(oneQueue());
    Texture swapchain = g.importTexture(
        "swapchain", {tex(64, VK_FORMAT_B8G8R8A8_UNORM),
                      BoundaryState::acquired(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT),
                      BoundaryState::of(Access::Present)});
    g.addPass(
        "draw", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            swapchain = b.write(swapchain, Access::ColorAttachment);
        },
        noop);
    return compile(g, oneQueue());
}

uint32_t presentBarrier(const Plan& plan) {
    const uint32_t image = plan.findResource("swapchain");
    for (const Batch& batch : plan.batches)
        for (uint32_t i = batch.firstEndBarrier; i < batch.firstEndBarrier + batch.endBarrierCount; ++i)
            if (plan.barriers[i].resource == image) return i;
    return kNoIndex;
}

} // namespace

TEST_CASE("the verifier accepts a plan that moves a swapchain image to PRESENT_SRC before the frame's signal") {
    const Plan plan = presentPlan();
    const uint32_t i = presentBarrier(plan);
    REQUIRE(i != kNoIndex);
    CHECK(plan.barriers[i].newLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
    const VerifyReport report = verify(plan);
    CHECK_MESSAGE(report.ok(), report.text());
}

TEST_CASE("the verifier catches a swapchain image left out of PRESENT_SRC") {
    const Plan plan = presentPlan();
    const uint32_t i = presentBarrier(plan);
    REQUIRE(i != kNoIndex);
    VerifyOptions options;
    options.checkRedundancy = false;
    const VerifyReport report = verify(withoutBarrier(plan, i), options);
    CHECK(report.has(Violation::Kind::FinalState));
    CHECK(contains(report.text(), "'swapchain'"));
    CHECK(contains(report.text(), "final layout"));
}

TEST_CASE("the verifier catches a transition to PRESENT_SRC outside the semaphore signal's scope") {
    // A NONE destination stage: the transition may still run when the
    // render-finished semaphore is signalled (a present-after-write hazard).
    Plan plan = presentPlan();
    const uint32_t i = presentBarrier(plan);
    REQUIRE(i != kNoIndex);
    plan.barriers[i].dstStages = VK_PIPELINE_STAGE_2_NONE;
    const VerifyReport report = verify(plan);
    CHECK(report.has(Violation::Kind::FinalState));
    CHECK(contains(report.text(), "layout transition"));
    CHECK(contains(report.text(), "not ordered before its final state"));
}

TEST_CASE("the verifier catches a missing semaphore wait") {
    Graph g(twoQueues());
    synthetic::declare(g, synthetic::reflectionFrame({}));
    const Plan plan = compileChecked(g);
    const Batch& sslr = batchOf(plan, "sslr");
    REQUIRE(sslr.waitCount == 1);
    const VerifyReport report = verify(withoutWait(plan, sslr.firstWait));
    CHECK_FALSE(report.ok());
    CHECK(contains(report.text(), "'sslr'"));
    // And one in the wrong stage.
    Plan wrongStage = plan;
    wrongStage.waits[sslr.firstWait].stages = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    CHECK_FALSE(verify(wrongStage).ok());
    // And the write-after-read edge into next frame's rebuild.
    const Batch& bvh = batchOf(plan, "bvh_update");
    REQUIRE(bvh.waitCount == 1);
    CHECK(verify(withoutWait(plan, bvh.firstWait)).has(Violation::Kind::WriteAfterRead));
}

TEST_CASE("the verifier catches a wait on a batch submitted later") {
    Graph g(twoQueues());
    synthetic::declare(g, synthetic::reflectionFrame({}));
    Plan plan = compileChecked(g);
    // Put the async batch after the graphics batch that waits on it.
    std::swap(plan.batches[0], plan.batches[2]);
    CHECK_FALSE(verify(plan).ok());
}

TEST_CASE("the verifier catches aliases that are alive at once") {
    Graph g(oneQueue());
    Texture a = g.createTexture("a", tex()), b2 = g.createTexture("b", tex());
    Texture out = g.createTexture("out", tex());
    g.addPass(
        "make", Queue::Graphics,
        [&](Builder& b) {
            a = b.write(a, Access::StorageWrite);
            b2 = b.write(b2, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "use", Queue::Graphics,
        [&](Builder& b) {
            b.read(a, Access::SampledRead);
            b.read(b2, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    PlannedResource& ra = plan.resources[resourceNamed(plan, "a")];
    PlannedResource& rb = plan.resources[resourceNamed(plan, "b")];
    REQUIRE(ra.heap == rb.heap);
    rb.offset = ra.offset; // both live in "use"
    const VerifyReport report = verify(plan);
    CHECK(report.has(Violation::Kind::Contents));
}

TEST_CASE("the verifier catches a redundant barrier") {
    Graph g(oneQueue());
    Buffer data = g.createBuffer("data", {1024});
    Buffer o1 = g.createBuffer("o1", {256}), o2 = g.createBuffer("o2", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { data = b.write(data, Access::StorageWrite); }, noop);
    g.addPass(
        "read1", Queue::Graphics,
        [&](Builder& b) {
            b.read(data, Access::StorageRead);
            o1 = b.write(o1, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "read2", Queue::Graphics,
        [&](Builder& b) {
            b.read(data, Access::StorageRead);
            o2 = b.write(o2, Access::StorageWrite);
        },
        noop);
    g.markOutput(o1);
    g.markOutput(o2);
    Plan plan = compileChecked(g);
    REQUIRE(barriersOn(plan, "read2", "data").empty()); // read1's barrier already covers it
    // Repeat read1's barrier before read2: it orders nothing new.
    const Barrier extra = plan.barriers[barrierIndex(plan, "read1", "data")];
    PlannedPass& read2 = plan.passes[indexOf(plan, "read2")];
    const uint32_t at = read2.firstBarrier;
    plan.barriers.insert(plan.barriers.begin() + at, extra);
    for (PlannedPass& p : plan.passes)
        if (&p != &read2 && p.firstBarrier >= at && (p.barrierCount || p.firstBarrier > at)) ++p.firstBarrier;
    ++read2.barrierCount;
    for (Batch& b : plan.batches)
        if (b.endBarrierCount && b.firstEndBarrier >= at) ++b.firstEndBarrier;
    const VerifyReport report = verify(plan);
    CHECK(report.has(Violation::Kind::RedundantBarrier));
    CHECK(contains(report.text(), "before 'read2'"));
}

TEST_CASE("the verifier catches a pass run before the pass whose data it reads") {
    Plan plan = chainPlan();
    // Swap w1 and r1 in submission order (barriers go with their passes).
    std::swap(plan.passes[indexOf(plan, "w1")], plan.passes[indexOf(plan, "r1")]);
    CHECK(verify(plan).has(Violation::Kind::Order));
}

TEST_CASE("on one queue, deleting any barrier that flushes a write from a random plan is caught") {
    // Without acceleration structures or aliases there is no global memory
    // barrier around to hide a missing flush.
    VerifyOptions options;
    options.checkRedundancy = false;
    for (uint64_t seed = 1; seed <= 40; ++seed) {
        synthetic::RandomOptions random;
        random.imports = false;
        CompileOptions noAliasing;
        noAliasing.aliasing = false;
        const Plan plan = randomPlan(seed, oneQueue(), random, noAliasing);
        for (uint32_t i = 0; i < plan.barriers.size(); ++i) {
            const Barrier& b = plan.barriers[i];
            if (!b.srcAccess && b.oldLayout == b.newLayout) continue;
            INFO("seed " << seed << " barrier " << i << " on " << plan.resourceName(b.resource));
            CHECK_FALSE(verify(withoutBarrier(plan, i), options).ok());
        }
    }
}
