// Two queues: placement, semaphores, sharing, and the edges across frames.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;

// async "produce" writes a buffer; graphics "early" runs meanwhile; graphics
// "consume" reads it in a compute shader, "draw" in a fragment shader.
Graph producerConsumer(const QueueCaps& caps) {
    Graph g(caps);
    Buffer data = g.createBuffer("data", {4096});
    Texture early = g.createTexture("early", tex());
    Texture out = g.createTexture("out", tex());
    Texture drawn = g.createTexture("drawn", tex());
    g.addPass(
        "produce", Queue::AsyncCompute, [&](Builder& b) { data = b.write(data, Access::StorageWrite); }, noop);
    g.addPass(
        "early", Queue::Graphics, [&](Builder& b) { early = b.write(early, Access::StorageWrite); }, noop);
    g.addPass(
        "consume", Queue::Graphics,
        [&](Builder& b) {
            b.read(data, Access::StorageRead);
            b.read(early, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "draw", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(data, Access::StorageRead);
            drawn = b.write(drawn, Access::ColorAttachment);
        },
        noop);
    g.markOutput(out);
    g.markOutput(drawn);
    return g;
}

} // namespace

TEST_CASE("async compute passes run on the compute family when it is separate") {
    Graph g = producerConsumer(twoQueues());
    Plan plan = compileChecked(g);
    CHECK((passNamed(plan, "produce").queue == Queue::AsyncCompute));
    CHECK((passNamed(plan, "consume").queue == Queue::Graphics));
    CHECK(plan.family(Queue::AsyncCompute) == 1);
    CHECK(plan.family(Queue::Graphics) == 0);
}

TEST_CASE("async compute passes fall back to the graphics queue, with no semaphores") {
    Graph g = producerConsumer(oneQueue());
    Plan plan = compileChecked(g);
    for (const PlannedPass& p : plan.passes) CHECK((p.queue == Queue::Graphics));
    CHECK(plan.batches.size() == 1);
    CHECK(plan.waits.empty());
    const auto bs = barriersOn(plan, "consume", "data");
    REQUIRE(bs.size() == 1); // the same hazard as a barrier
    CHECK(bs[0].srcAccess == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK_FALSE(plan.resources[resourceNamed(plan, "data")].crossQueue);
}

TEST_CASE("the first graphics consumer of async work waits at its batch's start, in its own stage") {
    Graph g = producerConsumer(twoQueues());
    Plan plan = compileChecked(g);
    const Batch& consumer = batchOf(plan, "consume");
    REQUIRE(plan.passesOf(consumer).size() >= 1);
    CHECK(plan.passName(plan.passesOf(consumer)[0]) == "consume");
    const auto waits = plan.waitsOf(consumer);
    REQUIRE(waits.size() == 1);
    CHECK((waits[0].queue == Queue::AsyncCompute));
    CHECK(waits[0].frameOffset == 0);
    CHECK(waits[0].stages == kCompute); // not ALL_COMMANDS
    CHECK(waits[0].batch == batchOf(plan, "produce").ordinal);
    // The pass before it on graphics overlaps the async work: no wait there.
    const Batch& earlier = batchOf(plan, "early");
    CHECK(&earlier != &consumer);
    CHECK(plan.waitsOf(earlier).empty());
    // Covered by the wait: no barrier for the compute-stage read.
    CHECK(barriersOn(plan, "consume", "data").empty());
}

TEST_CASE("a later consumer in another stage chains from the wait with a barrier") {
    Graph g = producerConsumer(twoQueues());
    Plan plan = compileChecked(g);
    CHECK(batchOf(plan, "draw").ordinal == batchOf(plan, "consume").ordinal); // no second wait
    const auto bs = barriersOn(plan, "draw", "data");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].srcStages == kCompute); // the wait's stage
    CHECK(bs[0].srcAccess == 0);        // the semaphore made the write available
    CHECK((bs[0].dstStages & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT) != 0);
}

TEST_CASE("the async batch ends at the producer so its signal does not wait for later work") {
    Graph g(twoQueues());
    Buffer a = g.createBuffer("a", {256}), later = g.createBuffer("later", {256});
    Texture out = g.createTexture("out", tex());
    g.addPass(
        "produce", Queue::AsyncCompute, [&](Builder& b) { a = b.write(a, Access::StorageWrite); }, noop);
    g.addPass(
        "consume", Queue::Graphics,
        [&](Builder& b) {
            b.read(a, Access::StorageRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "more_async", Queue::AsyncCompute, [&](Builder& b) { later = b.write(later, Access::StorageWrite); }, noop);
    g.markOutput(out);
    g.markOutput(later);
    Plan plan = compileChecked(g);
    CHECK(batchOf(plan, "produce").ordinal != batchOf(plan, "more_async").ordinal);
    CHECK(plan.waitsOf(batchOf(plan, "consume"))[0].batch == batchOf(plan, "produce").ordinal);
}

TEST_CASE("resources used on both queues are shared concurrently") {
    Graph g = producerConsumer(twoQueues());
    Plan plan = compileChecked(g);
    CHECK(plan.resources[resourceNamed(plan, "data")].crossQueue);
    CHECK_FALSE(plan.resources[resourceNamed(plan, "early")].crossQueue);
}

TEST_CASE("next frame's async write waits for this frame's graphics reads") {
    Graph g = producerConsumer(twoQueues());
    Plan plan = compileChecked(g);
    // "produce" overwrites the buffer "draw" reads on graphics last frame.
    const auto waits = plan.waitsOf(batchOf(plan, "produce"));
    REQUIRE(waits.size() == 1);
    CHECK((waits[0].queue == Queue::Graphics));
    CHECK(waits[0].frameOffset == -1);
    CHECK(waits[0].batch == plan.batchCount(Queue::Graphics) - 1);
    CHECK(waits[0].stages == kCompute);
    // And the executor skips it on the first frame.
    CHECK_FALSE(plan.waitValue(0, waits[0]).has_value());
    CHECK(plan.waitValue(1, waits[0]).has_value());
}

TEST_CASE("timeline values rise across frames and waits name earlier signals") {
    Graph g = producerConsumer(twoQueues());
    Plan plan = compileChecked(g);
    for (uint64_t frame = 0; frame < 3; ++frame) {
        for (const Batch& b : plan.batches) {
            CHECK(plan.signalValue(frame + 1, b) > plan.signalValue(frame, b));
            for (const SemaphoreWait& w : plan.waitsOf(b)) {
                const auto value = plan.waitValue(frame, w);
                if (!value) continue;
                // The batch it waits for signals exactly that value.
                for (const Batch& s : plan.batches)
                    if (s.queue == w.queue && s.ordinal == w.batch)
                        CHECK(*value == plan.signalValue(frame + static_cast<uint64_t>(w.frameOffset), s));
            }
        }
    }
}

TEST_CASE("work on the two queues in both directions splits batches without deadlock") {
    Graph g(twoQueues());
    Buffer a = g.createBuffer("a", {256}), b2 = g.createBuffer("b", {256}), c = g.createBuffer("c", {256});
    g.addPass(
        "g1", Queue::Graphics, [&](Builder& b) { a = b.write(a, Access::StorageWrite); }, noop);
    g.addPass(
        "c1", Queue::AsyncCompute,
        [&](Builder& b) {
            b.read(a, Access::StorageRead);
            b2 = b.write(b2, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "g2", Queue::Graphics,
        [&](Builder& b) {
            b.read(b2, Access::StorageRead);
            c = b.write(c, Access::StorageWrite);
        },
        noop);
    g.markOutput(c);
    Plan plan = compileChecked(g);
    CHECK(plan.batches.size() == 3);
    CHECK(indexOf(plan, "g1") < indexOf(plan, "c1"));
    CHECK(indexOf(plan, "c1") < indexOf(plan, "g2"));
    CHECK(plan.waitsOf(batchOf(plan, "c1")).size() == 1);
    CHECK(plan.waitsOf(batchOf(plan, "g2")).size() == 1);
}

TEST_CASE("an import's final state on the other queue is reached through a wait") {
    Graph g(twoQueues());
    Buffer counters = g.importBuffer("counters", {{1024},
                                                  BoundaryState::of(Access::StorageRead, Queue::Graphics),
                                                  BoundaryState::of(Access::StorageRead, Queue::Graphics)});
    Texture image = g.createTexture("image", tex());
    g.addPass(
        "render", Queue::Graphics, [&](Builder& b) { image = b.write(image, Access::StorageWrite); }, noop);
    g.addPass(
        "count", Queue::AsyncCompute, [&](Builder& b) { counters = b.write(counters, Access::StorageWrite); }, noop);
    g.markOutput(image);
    Plan plan = compileChecked(g);
    // Graphics holds the counters at the frame's end: after its last pass, a
    // batch waits for the async write so whoever comes next on graphics sees it.
    const Batch& last = plan.batches.back();
    CHECK((last.queue == Queue::Graphics));
    CHECK(last.passCount == 0);
    REQUIRE(last.waitCount == 1);
    CHECK((plan.waitsOf(last)[0].queue == Queue::AsyncCompute));
    CHECK(plan.waitsOf(last)[0].batch == batchOf(plan, "count").ordinal);
}

TEST_CASE("an import left on a queue that has no batch in the plan waits for that queue's last signal") {
    // No pass at all this frame (so no queue's passes stand in for the
    // other's), and an import left on async compute that graphics holds at
    // the frame's end: an end-only graphics batch waits for whatever async
    // compute signalled last (found by the graph fuzzer: it waited on
    // batch 4294967295, which the verifier rejected).
    Graph g(twoQueues());
    g.importTexture("left_on_compute", {tex(), BoundaryState::of(Access::StorageWrite, Queue::AsyncCompute),
                                        BoundaryState::of(Access::SampledRead, Queue::Graphics)});
    Plan plan = compileChecked(g);
    INFO(plan.toText());
    CHECK(plan.batchCount(Queue::AsyncCompute) == 0);
    std::vector<SemaphoreWait> waits;
    for (const Batch& b : plan.batches)
        for (const SemaphoreWait& w : plan.waitsOf(b)) waits.push_back(w);
    REQUIRE(waits.size() == 1);
    CHECK((waits[0].queue == Queue::AsyncCompute));
    CHECK(waits[0].frameOffset == -1);
    CHECK(waits[0].batch == SemaphoreWait::kLastSignalled);
    CHECK_FALSE(plan.waitValue(1, waits[0]).has_value());  // nothing signals under the plan's own values
}
