// Skipped passes (Builder::skip, rg::skipPasses): their barriers carried on
// and merged, every such frame accepted by the verifier (random graphs with
// random passes skipped), and the verifier rejecting the frame where they
// are simply dropped.

#include <doctest/doctest.h>

#include <random>
#include <string>

#include "glint/graph/skip.h"
#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

VerifyOptions noRedundancy() {
    // A carried barrier may have served only the pass that skipped.
    VerifyOptions options;
    options.checkRedundancy = false;
    return options;
}

void expectVerified(const Plan& plan, const std::string& what) {
    const VerifyReport report = verify(plan, noRedundancy());
    if (!report.ok()) {
        INFO(what);
        INFO(plan.toText());
        FAIL_CHECK(report.text());
    }
}

// a writes t; s1 samples it, s2 writes it again, s3 reads a buffer a wrote
// (all three skipped when `skip`); z samples t; s4 (a side effect, skipped
// too) samples it last, so its barrier lands in the batch's end.
Plan runOfSkips(bool skip) {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    Buffer buf = g.createBuffer("buf", {1024});
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "a", Queue::Graphics,
        [&](Builder& b) {
            t = b.write(t, Access::StorageWrite);
            buf = b.write(buf, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "s1", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
            if (skip) b.skip();
        },
        noop);
    g.addPass(
        "s2", Queue::Graphics,
        [&](Builder& b) {
            t = b.write(t, Access::StorageWrite);
            if (skip) b.skip();
        },
        noop);
    g.addPass(
        "s3", Queue::Graphics,
        [&](Builder& b) {
            b.read(buf, Access::StorageRead);
            out = b.write(out, Access::StorageWrite);
            if (skip) b.skip();
        },
        noop);
    g.addPass(
        "z", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "s4", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::TransferSrc);
            b.markSideEffects();
            if (skip) b.skip();
        },
        noop);
    g.markOutput(out);
    return compileChecked(g);
}

} // namespace

TEST_CASE("a run of skipped passes costs the next pass's one barrier call") {
    const Plan declared = runOfSkips(false);
    CHECK_FALSE(hasSkippedPasses(declared));
    CHECK(skipPasses(declared).barriers.size() == declared.barriers.size());

    const Plan plan = runOfSkips(true);
    REQUIRE(hasSkippedPasses(plan));
    // compile() ignores the flag: the same plan either way.
    CHECK(plan.toText() == declared.toText());
    const Plan frame = skipPasses(plan);
    INFO(frame.toText());
    expectVerified(frame, "the run of skips");

    for (const char* name : {"s1", "s2", "s3", "s4"}) {
        CHECK(passNamed(frame, name).skipped);
        CHECK(passNamed(frame, name).barrierCount == 0);
    }
    CHECK_FALSE(passNamed(frame, "a").skipped);
    CHECK_FALSE(passNamed(frame, "z").skipped);
    CHECK(passNamed(plan, "s1").barrierCount > 0);
    CHECK(passNamed(plan, "s2").barrierCount > 0);
    CHECK(frame.barrierCallCount() < plan.barrierCallCount());

    // t's three transitions (a -> s1, s1 -> s2, s2 -> z) are one before z:
    // from a's write to z's read, in z's layout.
    const std::vector<Barrier> onT = barriersOn(frame, "z", "t");
    REQUIRE(onT.size() == 1);
    CHECK(onT[0].oldLayout == VK_IMAGE_LAYOUT_GENERAL);
    CHECK(onT[0].newLayout == barriersOn(plan, "z", "t").at(0).newLayout);
    CHECK((onT[0].srcAccess & VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT) != 0);
    CHECK((onT[0].dstAccess & VK_ACCESS_2_SHADER_SAMPLED_READ_BIT) != 0);

    // s4's transition to a transfer source is carried to the batch's end.
    const Batch& batch = frame.batches.back();
    bool transferAtEnd = false;
    for (const Barrier& b : frame.barriersAfter(batch))
        transferAtEnd |= b.resource == resourceNamed(frame, "t") && b.newLayout == VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    CHECK(transferAtEnd);
}

TEST_CASE("the verifier rejects skipped passes whose barriers are dropped, not carried") {
    const Plan plan = runOfSkips(true);
    Plan dropped = plan;
    for (PlannedPass& p : dropped.passes) {
        if (plan.declaration->passes[p.pass].skipped) {
            p.skipped = true;
            p.barrierCount = 0;
        }
    }
    const VerifyReport report = verify(dropped, noRedundancy());
    INFO(dropped.toText());
    INFO(report.text());
    CHECK_FALSE(report.ok());
    // t ends the frame in z's layout, not s4's, where the next frame's
    // first barrier expects it; nothing orders a's write of buf after the
    // previous frame's (s3's barrier did).
    CHECK(report.has(Violation::Kind::TransitionRace));
    CHECK(report.has(Violation::Kind::WriteAfterWrite));
}

TEST_CASE("a carried barrier whose memory an alias takes is absorbed by the alias's barrier") {
    // x's last use is the skipped s; y, the same size, takes x's memory at z.
    Graph g(oneQueue());
    Texture x = g.createTexture("x", tex(256));
    Texture y = g.createTexture("y", tex(256));
    Buffer out = g.createBuffer("out", {256});
    g.addPass("a", Queue::Graphics, [&](Builder& b) { x = b.write(x, Access::StorageWrite); }, noop);
    g.addPass(
        "s", Queue::Graphics,
        [&](Builder& b) {
            b.read(x, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
            b.skip();
        },
        noop);
    g.addPass(
        "z", Queue::Graphics,
        [&](Builder& b) {
            y = b.write(y, Access::StorageWrite);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "r", Queue::Graphics,
        [&](Builder& b) {
            b.read(y, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    const Plan plan = compileChecked(g);
    const PlannedResource& rx = plan.resources[resourceNamed(plan, "x")];
    const PlannedResource& ry = plan.resources[resourceNamed(plan, "y")];
    REQUIRE(rx.heap == ry.heap);
    REQUIRE(rx.offset == ry.offset);

    const Plan frame = skipPasses(plan);
    INFO(frame.toText());
    expectVerified(frame, "the alias");
    // x's transition for s is gone (y takes the memory); y's barrier now
    // also waits for a's write of x, which s's barrier used to order.
    CHECK(passNamed(frame, "s").barrierCount == 0);
    CHECK(barriersOn(frame, "z", "x").empty());
    const std::vector<Barrier> onY = barriersOn(frame, "z", "y");
    REQUIRE(onY.size() == 1);
    CHECK(onY[0].aliasing);
    CHECK((onY[0].srcAccess & VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT) != 0);
    CHECK((barriersOn(plan, "z", "y").at(0).srcAccess & VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT) == 0);
}

TEST_CASE("random graphs with random skipped passes verify") {
    for (const bool two : {true, false}) {
        const QueueCaps caps = two ? twoQueues() : oneQueue();
        for (uint64_t seed = 1; seed <= 200; ++seed) {
            synthetic::RandomOptions options;
            options.seed = seed;
            options.passes = 6 + static_cast<uint32_t>(seed % 40);
            synthetic::Script script = synthetic::randomFrame(options);
            std::mt19937_64 rng(seed * 7919);
            for (synthetic::ScriptPass& pass : script.passes) pass.skipped = rng() % 3 == 0;
            Graph g(caps);
            synthetic::declare(g, script);
            const Plan plan = compile(g, caps);
            const Plan frame = skipPasses(plan);
            const std::string what = std::string(two ? "two queues" : "one queue") + ", seed " + std::to_string(seed);
            expectVerified(frame, what);
            INFO(what);
            CHECK(frame.barrierCallCount() <= plan.barrierCallCount());
            REQUIRE(frame.passes.size() == plan.passes.size());
            for (size_t i = 0; i < plan.passes.size(); ++i) {
                CHECK(frame.passes[i].pass == plan.passes[i].pass);
                CHECK(frame.passes[i].batch == plan.passes[i].batch);
                CHECK(frame.passes[i].skipped == plan.declaration->passes[plan.passes[i].pass].skipped);
                // A pass that runs keeps at least its own barriers' count
                // of subresources (merging adds, never loses one).
                if (!frame.passes[i].skipped) CHECK(frame.passes[i].barrierCount >= plan.passes[i].barrierCount);
            }
        }
    }
}
