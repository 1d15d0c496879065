// Culling, usage derived after culling, and the schedule's order.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

TEST_CASE("culls a pass whose output nobody reads") {
    Graph g(twoQueues());
    Texture used = g.createTexture("used", tex());
    Texture unused = g.createTexture("debug_view", tex());
    g.addPass(
        "main", Queue::Graphics, [&](Builder& b) { used = b.write(used, Access::StorageWrite); }, noop);
    g.addPass(
        "debug", Queue::Graphics, [&](Builder& b) { unused = b.write(unused, Access::StorageWrite); }, noop);
    g.markOutput(used);
    Plan plan = compileChecked(g);
    CHECK(plan.passes.size() == 1);
    CHECK(culled(plan, "debug"));
    CHECK_FALSE(plan.resources[resourceNamed(plan, "debug_view")].used);
    CHECK(plan.resources[resourceNamed(plan, "debug_view")].heap == kNoIndex);
    CHECK(plan.stats.culledPasses == 1);
}

TEST_CASE("keeps a pass with side effects when nothing reads its outputs") {
    Graph g(twoQueues());
    Buffer readback = g.createBuffer("readback", {4096});
    Texture t = g.createTexture("t", tex());
    g.addPass(
        "render", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "copy_to_host", Queue::Graphics,
        [&](Builder& b) {
            b.markSideEffects();
            b.read(t, Access::TransferSrc);
            readback = b.write(readback, Access::TransferDst);
        },
        noop);
    Plan plan = compileChecked(g);
    CHECK(plan.passes.size() == 2);
    CHECK_FALSE(culled(plan, "render"));
    CHECK_FALSE(culled(plan, "copy_to_host"));
}

TEST_CASE("keeps the producers of an output and what they read, transitively") {
    Graph g(twoQueues());
    Texture a = g.createTexture("a", tex()), b2 = g.createTexture("b", tex()), c = g.createTexture("c", tex());
    Texture side = g.createTexture("side", tex());
    g.addPass(
        "make_a", Queue::Graphics, [&](Builder& b) { a = b.write(a, Access::StorageWrite); }, noop);
    g.addPass(
        "make_side", Queue::Graphics, [&](Builder& b) { side = b.write(side, Access::StorageWrite); }, noop);
    g.addPass(
        "make_b", Queue::AsyncCompute,
        [&](Builder& b) {
            b.read(a, Access::SampledRead);
            b2 = b.write(b2, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "make_c", Queue::Graphics,
        [&](Builder& b) {
            b.read(b2, Access::SampledRead);
            c = b.write(c, Access::StorageWrite);
        },
        noop);
    g.markOutput(c);
    Plan plan = compileChecked(g);
    CHECK(plan.passes.size() == 3);
    CHECK(culled(plan, "make_side"));
}

TEST_CASE("writes to imports and to history are observable: their writers stay") {
    Graph g(twoQueues());
    Texture swapchain =
        g.importTexture("swapchain", {tex(), BoundaryState::of(Access::None), BoundaryState::of(Access::Present)});
    HistoryTexture history = g.createHistoryTexture("taa", tex());
    g.addPass(
        "present_blit", Queue::Graphics, [&](Builder& b) { swapchain = b.write(swapchain, Access::TransferDst); },
        noop);
    g.addPass(
        "accumulate", Queue::Graphics,
        [&](Builder& b) {
            b.read(history.previous, Access::SampledRead);
            history.current = b.write(history.current, Access::StorageWrite);
        },
        noop);
    Plan plan = compileChecked(g);
    CHECK(plan.passes.size() == 2);
}

TEST_CASE("keeps an earlier writer whose contents a later partial write preserves") {
    Graph g(twoQueues());
    Buffer list = g.createBuffer("list", {1024});
    g.addPass(
        "clear", Queue::Graphics, [&](Builder& b) { list = b.write(list, Access::TransferDst); }, noop);
    g.addPass(
        "append", Queue::Graphics, [&](Builder& b) { list = b.write(list, Access::StorageWrite); }, noop);
    g.markOutput(list);
    Plan plan = compileChecked(g);
    CHECK_FALSE(culled(plan, "clear"));
}

TEST_CASE("usage flags come from surviving passes only") {
    Graph g(twoQueues());
    Texture t = g.createTexture("t", tex());
    Buffer out = g.createBuffer("out", {256});
    Buffer dead = g.createBuffer("dead", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "sample", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "copy_out", Queue::Graphics, // culled: `dead` is never output
        [&](Builder& b) {
            b.read(t, Access::TransferSrc);
            dead = b.write(dead, Access::TransferDst);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    CHECK(culled(plan, "copy_out"));
    CHECK(plan.resources[resourceNamed(plan, "t")].imageUsage ==
          (VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT));
}

TEST_CASE("independent passes keep declaration order") {
    Graph g(twoQueues());
    std::vector<Texture> outs;
    for (const char* name : {"e", "b", "d", "a", "c"}) {
        Texture t = g.createTexture(name, tex());
        g.addPass(
            name, Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
        g.markOutput(t);
    }
    Plan plan = compileChecked(g);
    std::string order;
    for (const PlannedPass& p : plan.passes) order += plan.passName(p);
    CHECK(order == "ebdac");
}

TEST_CASE("an explicit order moves a pass ahead of independent ones") {
    Graph g(twoQueues());
    std::vector<PassId> ids;
    for (const char* name : {"upload", "render", "readback"}) {
        Texture t = g.createTexture(name, tex());
        ids.push_back(g.addPass(
            name, Queue::Graphics,
            [&](Builder& b) {
                b.markSideEffects();
                t = b.write(t, Access::StorageWrite);
            },
            noop));
    }
    g.order(ids[2], ids[1]); // readback of the previous frame's data before rendering
    Plan plan = compileChecked(g);
    std::string order;
    for (const PlannedPass& p : plan.passes) order += std::string(plan.passName(p)) + " ";
    CHECK(order == "upload readback render ");
}

TEST_CASE("one queue or two: the same passes in the same order per queue") {
    Graph g(twoQueues());
    synthetic::RandomOptions options;
    options.passes = 40;
    options.seed = 7;
    synthetic::declare(g, synthetic::randomFrame(options));
    const Plan two = compileChecked(g, twoQueues());
    const Plan one = compileChecked(g, oneQueue());
    CHECK(two.culled == one.culled);
    // On one queue everything is graphics; the order of any queue's passes in
    // the two-queue plan is a subsequence of the one-queue order.
    std::vector<uint32_t> oneOrder;
    for (const PlannedPass& p : one.passes) {
        CHECK((p.queue == Queue::Graphics));
        oneOrder.push_back(p.pass);
    }
    for (Queue q : {Queue::Graphics, Queue::AsyncCompute}) {
        size_t at = 0;
        for (const PlannedPass& p : two.passes) {
            if (p.queue != q) continue;
            while (at < oneOrder.size() && oneOrder[at] != p.pass) ++at;
            CHECK(at < oneOrder.size());
        }
    }
    CHECK(one.waits.empty());
    CHECK(one.batches.size() == 1);
}
