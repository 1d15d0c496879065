// Hazards within a queue: which barrier each one gets, and which get none.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkPipelineStageFlags2 kFragment = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;

} // namespace

TEST_CASE("read after write: from the writer's stage and access to the reader's, with the layout change") {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "read", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "read", "t");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].srcStages == kCompute);
    CHECK(bs[0].srcAccess == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK(bs[0].dstStages == kCompute);
    CHECK(bs[0].dstAccess == VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    CHECK(bs[0].oldLayout == VK_IMAGE_LAYOUT_GENERAL);
    CHECK(bs[0].newLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(bs[0].aspect == VK_IMAGE_ASPECT_COLOR_BIT);
    CHECK(bs[0].range == Subresource{0, 1, 0, 1});
}

TEST_CASE("write after read: an execution dependency, no access to flush") {
    Graph g(oneQueue());
    Buffer data = g.createBuffer("data", {1024});
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "fill", Queue::Graphics, [&](Builder& b) { data = b.write(data, Access::StorageWrite); }, noop);
    g.addPass(
        "consume", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(data, Access::StorageRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "refill", Queue::Graphics, [&](Builder& b) { data = b.write(data, Access::StorageWrite); }, noop);
    g.markOutput(data);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "refill", "data");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].srcStages == (VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | kFragment));
    CHECK(bs[0].srcAccess == 0);
    CHECK(bs[0].dstStages == kCompute);
}

TEST_CASE("write after write: the first write is made available to the second") {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    g.addPass(
        "clear", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::TransferDst); }, noop);
    g.addPass(
        "splat", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.markOutput(t);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "splat", "t");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].srcStages == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
    CHECK(bs[0].srcAccess == VK_ACCESS_2_TRANSFER_WRITE_BIT);
    CHECK(bs[0].dstAccess == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK(bs[0].oldLayout == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    CHECK(bs[0].newLayout == VK_IMAGE_LAYOUT_GENERAL);
}

TEST_CASE("read after read in one layout needs no barrier; a second stage or access needs its own visibility") {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    Buffer o1 = g.createBuffer("o1", {256}), o2 = g.createBuffer("o2", {256}), o3 = g.createBuffer("o3", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "read1", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            o1 = b.write(o1, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "read2", Queue::Graphics, // same stage, same access, same layout
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            o2 = b.write(o2, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "read3", Queue::Graphics, // the fragment stage has not seen the write yet
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(t, Access::SampledRead);
            o3 = b.write(o3, Access::StorageWrite);
        },
        noop);
    for (Buffer o : {o1, o2, o3}) g.markOutput(o);
    Plan plan = compileChecked(g);
    CHECK(barriersOn(plan, "read1", "t").size() == 1);
    CHECK(barriersOn(plan, "read2", "t").empty());
    const auto third = barriersOn(plan, "read3", "t");
    REQUIRE(third.size() == 1);
    CHECK(third[0].oldLayout == third[0].newLayout);
    CHECK((third[0].dstStages & kFragment) != 0);
    // It chains from read1's layout transition, which already made the write
    // available: only visibility at the fragment stage is new.
    CHECK(third[0].srcStages == kCompute);
    CHECK(third[0].srcAccess == 0);
}

TEST_CASE("read after read with a layout change gets a transition ordered after the first reads") {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    Buffer o1 = g.createBuffer("o1", {256}), o2 = g.createBuffer("o2", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "sample", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(t, Access::SampledRead);
            o1 = b.write(o1, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "load", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::StorageRead);
            o2 = b.write(o2, Access::StorageWrite);
        },
        noop);
    g.markOutput(o1);
    g.markOutput(o2);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "load", "t");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].oldLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(bs[0].newLayout == VK_IMAGE_LAYOUT_GENERAL);
    CHECK((bs[0].srcStages & kFragment) != 0); // the sampling reads finish before the transition
}

TEST_CASE("a pass's barriers come as one per resource range, and none for untouched resources") {
    Graph g(oneQueue());
    Texture a = g.createTexture("a", tex()), b2 = g.createTexture("b", tex());
    Texture untouched = g.createTexture("untouched", tex());
    Texture out = g.createTexture("out", tex());
    g.addPass(
        "make", Queue::Graphics,
        [&](Builder& b) {
            a = b.write(a, Access::StorageWrite);
            b2 = b.write(b2, Access::StorageWrite);
            untouched = b.write(untouched, Access::StorageWrite);
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
    g.markOutput(untouched);
    Plan plan = compileChecked(g);
    const PlannedPass& use = passNamed(plan, "use");
    CHECK(barriersOn(plan, "use", "a").size() == 1);
    CHECK(barriersOn(plan, "use", "b").size() == 1);
    CHECK(barriersOn(plan, "use", "untouched").empty());
    CHECK(plan.barriersBefore(use).size() == 3); // a, b, and out's first use this frame
}

TEST_CASE("storage images stay in GENERAL between compute passes") {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    g.addPass(
        "a", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "b", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageReadWrite); }, noop);
    g.addPass(
        "c", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageReadWrite); }, noop);
    g.markOutput(t);
    Plan plan = compileChecked(g);
    for (const char* p : {"b", "c"}) {
        const auto bs = barriersOn(plan, p, "t");
        REQUIRE(bs.size() == 1);
        CHECK(bs[0].oldLayout == VK_IMAGE_LAYOUT_GENERAL);
        CHECK(bs[0].newLayout == VK_IMAGE_LAYOUT_GENERAL);
    }
}

TEST_CASE("a transient starts each frame from UNDEFINED, after last frame's uses of its memory") {
    Graph g(oneQueue());
    Texture t = g.createTexture("t", tex());
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "write", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "read", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(t, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "write", "t");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
    CHECK(bs[0].newLayout == VK_IMAGE_LAYOUT_GENERAL);
    // Last frame's sampling of the same memory finishes first.
    CHECK(bs[0].srcStages == (VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | kFragment));
}

TEST_CASE("an import goes from its initial state and ends in its final one") {
    Graph g(oneQueue());
    // A swapchain image: acquired (semaphore waited at colour output), presented after.
    Texture swapchain = g.importTexture(
        "swapchain", {tex(64, VK_FORMAT_B8G8R8A8_UNORM),
                      BoundaryState::raw(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED),
                      BoundaryState::of(Access::Present)});
    g.addPass(
        "tonemap", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            swapchain = b.write(swapchain, Access::ColorAttachment);
        },
        noop);
    Plan plan = compileChecked(g);
    const auto first = barriersOn(plan, "tonemap", "swapchain");
    REQUIRE(first.size() == 1);
    CHECK(first[0].oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
    CHECK(first[0].newLayout == VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL);
    // Ordered after the acquire wait's stage.
    CHECK(first[0].srcStages == VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
    REQUIRE(plan.batches.size() == 1);
    const auto last = plan.barriersAfter(plan.batches[0]);
    REQUIRE(last.size() == 1);
    CHECK(last[0].oldLayout == VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL);
    CHECK(last[0].newLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
    CHECK(last[0].srcAccess == VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    // Ends at the stages the executor signals semaphores with, no access:
    // the transition is inside the render-finished signal's scope.
    CHECK(last[0].dstStages == kSemaphoreSignalStages);
    CHECK(last[0].dstAccess == VK_ACCESS_2_NONE);
}

TEST_CASE("an acquired swapchain image written by a transfer then drawn over ends in PRESENT_SRC before the signal") {
    // The viewer's frame: a blit into the acquired image, the UI drawn over
    // it, presented. The acquire wait is at the blit's stage.
    Graph g(oneQueue());
    Texture swapchain = g.importTexture("swapchain", {tex(64, VK_FORMAT_B8G8R8A8_UNORM),
                                                      BoundaryState::acquired(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT),
                                                      BoundaryState::of(Access::Present)});
    Texture source = g.createTexture("source", tex(64, VK_FORMAT_R8G8B8A8_UNORM));
    g.addPass("render", Queue::Graphics, [&](Builder& b) { source = b.write(source, Access::StorageWrite); }, noop);
    g.addPass(
        "blit", Queue::Graphics,
        [&](Builder& b) {
            b.read(source, Access::TransferSrc);
            swapchain = b.write(swapchain, Access::TransferDst);
        },
        noop);
    g.addPass(
        "ui", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            swapchain = b.write(swapchain, Access::ColorAttachment);
        },
        noop);
    Plan plan = compileChecked(g); // verify()s it
    const auto first = barriersOn(plan, "blit", "swapchain");
    REQUIRE(first.size() == 1);
    CHECK(first[0].oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
    CHECK(first[0].newLayout == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    CHECK(first[0].srcStages == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT); // chained to the acquire wait
    const uint32_t image = resourceNamed(plan, "swapchain");
    uint32_t toPresent = 0;
    for (const Batch& batch : plan.batches)
        for (const Barrier& b : plan.barriersAfter(batch))
            if (b.resource == image) {
                ++toPresent;
                CHECK(b.oldLayout == VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL);
                CHECK(b.newLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
                CHECK(b.srcStages == VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
                CHECK(b.srcAccess == VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
                CHECK((b.dstStages & kSemaphoreSignalStages) != 0);
            }
    CHECK(toPresent == 1);
    // Where the executor puts the caller's semaphores: the acquire wait in
    // the batch of the blit, at the blit's stage; the render-finished
    // signal from the batch that records the transition to PRESENT_SRC.
    const Plan::WaitPoint wait = plan.firstUseOf(image);
    CHECK(wait.batch == passNamed(plan, "blit").batch);
    CHECK(wait.stages == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
    const uint32_t ending = plan.batchEnding(image);
    REQUIRE(ending != kNoIndex);
    CHECK(ending >= passNamed(plan, "ui").batch);
    bool endsThere = false;
    for (const Barrier& b : plan.barriersAfter(plan.batches[ending]))
        endsThere = endsThere || (b.resource == image && b.newLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
    CHECK(endsThere);
}

TEST_CASE("an import whose final state describes its last use needs no end barrier") {
    Graph g(oneQueue());
    const BoundaryState readState = BoundaryState::of(Access::SampledRead, Queue::Graphics, Pipeline::Compute);
    Texture lut = g.importTexture("lut", {tex(), readState, readState});
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "grade", Queue::Graphics,
        [&](Builder& b) {
            b.read(lut, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    CHECK(barriersOn(plan, "grade", "lut").empty()); // read after read, same layout
    for (const Batch& b : plan.batches) CHECK(plan.barriersAfter(b).empty());
}

TEST_CASE("a build of an acceleration structure is made visible to ray queries") {
    Graph g(oneQueue());
    Buffer instances = g.importBuffer(
        "instances", {{4096}, BoundaryState::of(Access::TransferDst), BoundaryState::of(Access::AccelBuildInput)});
    AccelStruct tlas =
        g.importAccelStruct("tlas", {BoundaryState::of(Access::AccelRead), BoundaryState::of(Access::AccelRead)});
    Texture hits = g.createTexture("hits", tex());
    g.addPass(
        "build", Queue::Graphics,
        [&](Builder& b) {
            b.read(instances, Access::AccelBuildInput);
            tlas = b.write(tlas, Access::AccelBuildWrite);
        },
        noop);
    g.addPass(
        "trace", Queue::Graphics,
        [&](Builder& b) {
            b.read(tlas, Access::AccelRead);
            hits = b.write(hits, Access::StorageWrite);
        },
        noop);
    g.markOutput(hits);
    Plan plan = compileChecked(g);
    const auto input = barriersOn(plan, "build", "instances");
    REQUIRE(input.size() == 1);
    CHECK(input[0].srcAccess == VK_ACCESS_2_TRANSFER_WRITE_BIT);
    CHECK(input[0].dstStages == VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    CHECK(input[0].dstAccess == VK_ACCESS_2_SHADER_READ_BIT);
    const auto built = barriersOn(plan, "trace", "tlas");
    REQUIRE(built.size() == 1);
    CHECK(built[0].srcStages == VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    CHECK((built[0].srcAccess & VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR) != 0);
    CHECK(built[0].dstStages == kCompute);
    CHECK(built[0].dstAccess == VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    // The build itself waits for last frame's ray queries (write after read).
    const auto rebuild = barriersOn(plan, "build", "tlas");
    REQUIRE(rebuild.size() == 1);
    CHECK(rebuild[0].srcStages == kCompute);
}

TEST_CASE("indirect arguments written by a shader are made visible to the indirect stage") {
    Graph g(oneQueue());
    Buffer args = g.createBuffer("args", {64});
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "classify", Queue::Graphics, [&](Builder& b) { args = b.write(args, Access::StorageWrite); }, noop);
    g.addPass(
        "dispatch", Queue::Graphics,
        [&](Builder& b) {
            b.read(args, Access::IndirectArgs);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "dispatch", "args");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].dstStages == VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT);
    CHECK(bs[0].dstAccess == VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
    CHECK(bs[0].srcAccess == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}
