// History resources: last frame's image read, this frame's written, swapped.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

// A TAA-like loop: read last frame's result, write this frame's, show it.
Graph temporal(const QueueCaps& caps) {
    Graph g(caps);
    HistoryTexture history = g.createHistoryTexture("taa", tex());
    Texture frame = g.createTexture("frame", tex());
    Texture shown = g.createTexture("shown", tex());
    g.addPass(
        "render", Queue::Graphics, [&](Builder& b) { frame = b.write(frame, Access::StorageWrite); }, noop);
    g.addPass(
        "accumulate", Queue::Graphics,
        [&](Builder& b) {
            b.read(frame, Access::SampledRead);
            b.read(history.previous, Access::SampledRead);
            history.current = b.write(history.current, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "show", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(history.current, Access::SampledRead);
            shown = b.write(shown, Access::ColorAttachment);
        },
        noop);
    g.markOutput(shown);
    return g;
}

} // namespace

TEST_CASE("last frame's history is readable without a writer this frame") {
    Graph g = temporal(oneQueue());
    Plan plan = compileChecked(g);
    CHECK(plan.passes.size() == 3);
    const uint32_t previous = resourceNamed(plan, "taa.previous");
    const uint32_t current = resourceNamed(plan, "taa.current");
    CHECK(plan.resources[previous].partner == current);
    CHECK(plan.resources[current].partner == previous);
    CHECK((plan.resources[previous].origin == ir::Origin::HistoryPrevious));
}

TEST_CASE("this frame's history must be written before it is read") {
    Graph g(oneQueue());
    HistoryTexture history = g.createHistoryTexture("taa", tex());
    CHECK_THROWS_AS(
        g.addPass(
            "early_read", Queue::Graphics, [&](Builder& b) { b.read(history.current, Access::SampledRead); }, noop),
        GraphError);
}

TEST_CASE("both history images carry the usage of both roles") {
    Graph g = temporal(oneQueue());
    Plan plan = compileChecked(g);
    const VkImageUsageFlags both = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
    CHECK(plan.resources[resourceNamed(plan, "taa.previous")].imageUsage == both);
    CHECK(plan.resources[resourceNamed(plan, "taa.current")].imageUsage == both);
}

TEST_CASE("the previous image starts the frame in the layout the current one ended in") {
    Graph g = temporal(oneQueue());
    Plan plan = compileChecked(g);
    // current ends sampled by "show"; previous is sampled by "accumulate", so
    // it needs no transition, only visibility at the compute stage.
    CHECK(plan.resources[resourceNamed(plan, "taa.previous")].entryLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(plan.resources[resourceNamed(plan, "taa.current")].entryLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    const auto read = barriersOn(plan, "accumulate", "taa.previous");
    REQUIRE(read.size() == 1);
    CHECK(read[0].oldLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(read[0].newLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(read[0].dstStages == VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    // The write into current waits for last frame's reads of that image.
    const auto write = barriersOn(plan, "accumulate", "taa.current");
    REQUIRE(write.size() == 1);
    CHECK(write[0].oldLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(write[0].newLayout == VK_IMAGE_LAYOUT_GENERAL);
    CHECK((write[0].srcStages & VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT) != 0);
}

TEST_CASE("history holds across frames with both images in both roles, on one queue and two") {
    for (const QueueCaps& caps : {oneQueue(), twoQueues()}) {
        Graph g = temporal(caps);
        Plan plan = compile(g, caps);
        const VerifyReport report = verify(plan, {4, true});
        INFO(plan.toText());
        CHECK_MESSAGE(report.ok(), report.text());
    }
}

TEST_CASE("a history buffer written on async compute is read on graphics next frame") {
    Graph g(twoQueues());
    HistoryBuffer counters = g.createHistoryBuffer("feedback", {4096});
    Texture out = g.createTexture("out", tex());
    g.addPass(
        "classify", Queue::Graphics,
        [&](Builder& b) {
            b.read(counters.previous, Access::StorageRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "count", Queue::AsyncCompute,
        [&](Builder& b) { counters.current = b.write(counters.current, Access::StorageWrite); }, noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    CHECK(plan.resources[resourceNamed(plan, "feedback.previous")].crossQueue);
    // Graphics reads what async compute wrote last frame: a wait on the
    // previous frame's async work.
    const auto waits = plan.waitsOf(batchOf(plan, "classify"));
    REQUIRE(waits.size() == 1);
    CHECK((waits[0].queue == Queue::AsyncCompute));
    CHECK(waits[0].frameOffset == -1);
    // And async compute overwrites what graphics read last frame: the other way.
    const auto back = plan.waitsOf(batchOf(plan, "count"));
    REQUIRE(back.size() == 1);
    CHECK((back[0].queue == Queue::Graphics));
}

TEST_CASE("a history texture that ends the frame in mixed layouts is refused") {
    Graph g(oneQueue());
    HistoryTexture h = g.createHistoryTexture("pyramid", tex(64, VK_FORMAT_R16G16B16A16_SFLOAT, 2));
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { h.current = b.write(h.current, Access::StorageWrite); }, noop);
    g.addPass(
        "sample_top", Queue::Graphics,
        [&](Builder& b) {
            b.read(h.current, Access::SampledRead, Subresource::mip(0));
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    try {
        (void)g.compile();
        FAIL("no GraphError");
    } catch (const GraphError& e) {
        CHECK((e.kind() == ErrorKind::ConflictingAccess));
        CHECK(e.resource() == "pyramid.previous");
    }
}
