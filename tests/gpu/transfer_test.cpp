// The graph's transfer helpers (glint/graph/transfer.h): bytes uploaded
// into a frame with rg::addUpload come back unchanged through
// rg::HostReadback, with no pass of their own, and frames in flight each
// keep their own bytes; misuse is refused where it is declared, naming the
// upload or the readback.
#include "support/gpu_test.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/error.h"
#include "glint/graph/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan_cache.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

using namespace glint;

TEST_CASE("a large upload reads back byte for byte, and the frame runs no pass to upload it") {
    test::GpuTest gpu;
    rg::Executor executor(gpu.ctx());
    std::vector<uint32_t> words(70000 / 4);  // 68.4 KiB
    for (size_t i = 0; i < words.size(); ++i) words[i] = uint32_t(i * 2654435761u);
    const rg::HostReadback readback(gpu.ctx(), words.size() * 4, "transfer_test.readback");
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const rg::Buffer uploaded = rg::addUpload(graph, "transfer_test.upload", std::as_bytes(std::span(words)));
    readback.copy(graph, resources, uploaded);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const rg::VerifyReport report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    // The host writes the bytes: the readback's copy is the frame's only pass.
    REQUIRE(plan.passes.size() == 1);
    CHECK(plan.passName(plan.passes.front()) != "transfer_test.upload");
    executor.run(plan, resources);
    executor.waitIdle();
    const std::span<const uint32_t> back = readback.as<uint32_t>();
    REQUIRE(back.size() == words.size());
    CHECK(std::equal(back.begin(), back.end(), words.begin()));

    struct Constants {
        float a[3];
        uint32_t b;
    };
    const rg::Buffer one = rg::addUpload(graph, "transfer_test.constants", Constants{{1, 2, 3}, 4});
    CHECK(one.valid());
}

TEST_CASE("frames in flight each read their own upload, through a reused plan") {
    test::GpuTest gpu;
    constexpr uint32_t kFrames = 6;
    rg::Executor executor(gpu.ctx(), 2);
    rg::PlanCache cache(4);
    std::vector<std::unique_ptr<rg::HostReadback>> readbacks;
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        // A compute-free frame: the bytes go from the upload straight to the
        // readback's copy; nothing waits between the frames but the slots.
        readbacks.push_back(
            std::make_unique<rg::HostReadback>(gpu.ctx(), 64, "transfer_test.frame" + std::to_string(frame)));
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        std::vector<uint32_t> words(16);
        for (uint32_t i = 0; i < words.size(); ++i) words[i] = frame * 1000u + i;
        readbacks.back()->copy(graph, resources, rg::addUpload(graph, "transfer_test.constants",
                                                               std::as_bytes(std::span(words))));
        const rg::Plan plan = cache.compile(graph, executor.compileOptions());
        const rg::VerifyReport report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor.run(plan, resources);
    }
    CHECK(cache.hits() == kFrames - 1);
    executor.waitIdle();
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        CAPTURE(frame);
        const std::span<const uint32_t> back = readbacks[frame]->as<uint32_t>();
        REQUIRE(back.size() == 16);
        for (uint32_t i = 0; i < back.size(); ++i) CHECK(back[i] == frame * 1000u + i);
    }
}

TEST_CASE("an empty or unaligned upload, a readback too small or a foreign handle are refused by name") {
    test::GpuTest gpu;
    rg::Executor executor(gpu.ctx());
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    CHECK_THROWS_WITH_AS(rg::addUpload(graph, "empty", std::span<const std::byte>()), doctest::Contains("not 0"),
                         rg::GraphError);
    const std::byte three[3] = {};
    CHECK_THROWS_WITH_AS(rg::addUpload(graph, "odd", std::span<const std::byte>(three)),
                         doctest::Contains("multiple of 4"), rg::GraphError);

    rg::Texture image;
    graph.addPass("transfer_test.fill", rg::Queue::Graphics, [&](rg::Builder& b) {
        image = b.write(b.createTexture("image", {64, 64, 1, 1, 1, VK_FORMAT_R8G8B8A8_UNORM}), rg::Access::TransferDst);
    });
    const rg::HostReadback small(gpu.ctx(), 64 * 64 * 4 - 4, "transfer_test.small");
    CHECK_THROWS_WITH_AS(small.copy(graph, resources, image), doctest::Contains("transfer_test.small"), rg::GraphError);

    rg::Graph other(executor.queueCaps());
    const rg::HostReadback fits(gpu.ctx(), 64 * 64 * 4, "transfer_test.fits");
    CHECK_THROWS_WITH_AS(fits.copy(other, resources, image), doctest::Contains("not a resource of this graph"),
                         rg::GraphError);
}

TEST_CASE("an upload declared in a pass whose setup throws goes with the pass") {
    test::GpuTest gpu;
    rg::Executor executor(gpu.ctx());
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const std::vector<uint32_t> kept = {7, 8, 9, 10};
    const rg::Buffer first = rg::addUpload(graph, "transfer_test.kept", std::as_bytes(std::span(kept)));
    CHECK_THROWS_AS(graph.addPass("transfer_test.failing", rg::Queue::Graphics,
                                  [&](rg::Builder&) {
                                      const std::vector<uint32_t> lost = {1, 2, 3, 4};
                                      (void)rg::addUpload(graph, "transfer_test.lost", std::as_bytes(std::span(lost)));
                                      throw rg::GraphError(rg::ErrorKind::InvalidDescription, "transfer_test.failing",
                                                           "", "setup failed on purpose");
                                  }),
                    rg::GraphError);
    REQUIRE(graph.declaration().uploads.size() == 1);
    CHECK(graph.declaration().uploadBytes.size() == kept.size() * 4);
    const rg::HostReadback readback(gpu.ctx(), kept.size() * 4, "transfer_test.kept_back");
    readback.copy(graph, resources, first);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    REQUIRE(rg::verify(plan).ok());
    executor.run(plan, resources);
    executor.waitIdle();
    const std::span<const uint32_t> back = readback.as<uint32_t>();
    CHECK(std::equal(back.begin(), back.end(), kept.begin()));
}

TEST_CASE("uploads under a new name every frame do not pile up: a name unused for a while is let go") {
    test::GpuTest gpu;
    rg::Executor executor(gpu.ctx(), 2);
    const rg::HostReadback readback(gpu.ctx(), 4096, "transfer_test.every_frame");
    const std::vector<uint32_t> words(1024, 7u);
    std::vector<uint64_t> used;
    for (uint32_t frame = 0; frame < 300; ++frame) {
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        readback.copy(graph, resources,
                      rg::addUpload(graph, "transfer_test.frame" + std::to_string(frame), std::as_bytes(std::span(words))));
        executor.run(graph.compile(executor.compileOptions()), resources);
        if (frame == 149 || frame == 299) {
            executor.waitIdle();
            used.push_back(gpu.ctx().memory().stats().usedBytes);
        }
    }
    // 150 more names, 600 KB had they been kept; the same set of recent
    // ones at both points.
    CHECK(used[1] == used[0]);
}

namespace {

// A pass copying `source` into a frame readback's target; the target as written.
rg::Buffer copyInto(rg::Graph& graph, rg::Buffer source, rg::Buffer target, VkDeviceSize bytes) {
    struct Data {
        rg::Buffer source, target;
    };
    const Data& data = graph.addPass<Data>(
        "transfer_test.copy", rg::Queue::Graphics,
        [&](rg::Builder& b, Data& d) {
            d.source = b.read(source, rg::Access::TransferSrc);
            d.target = b.write(target, rg::Access::TransferDst);
        },
        [bytes](const Data& d, rg::PassContext& pc) {
            const VkBufferCopy region{0, 0, bytes};
            vkCmdCopyBuffer(pc.cmd(), pc.buffer(d.source).handle(), pc.buffer(d.target).handle(), 1, &region);
        });
    return data.target;
}

} // namespace

TEST_CASE("a frame readback gives each frame's bytes once that frame has finished, and never another frame's") {
    test::GpuTest gpu;
    constexpr uint32_t kFrames = 12;
    constexpr uint32_t kDepth = 3;
    rg::Executor executor(gpu.ctx(), 2);
    rg::PlanCache cache(4);
    rg::FrameReadback readback(gpu.ctx(), 64, "transfer_test.frames", kDepth);
    const auto expect = [](uint64_t sequence, std::span<const std::byte> bytes) {
        REQUIRE(bytes.size() == 64);
        std::vector<uint32_t> words(16);
        std::memcpy(words.data(), bytes.data(), 64);
        for (uint32_t i = 0; i < words.size(); ++i) CHECK(words[i] == sequence * 1000u + i);
    };
    uint32_t readEarly = 0;
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        rg::Graph graph(executor.queueCaps());
        // More buffers than frames in flight: one is always free.
        const auto target = readback.declare(graph);
        REQUIRE(target);
        CHECK(target->sequence == frame + 1);
        std::vector<uint32_t> words(16);
        for (uint32_t i = 0; i < words.size(); ++i) words[i] = uint32_t(target->sequence) * 1000u + i;
        graph.markOutput(copyInto(graph, rg::addUpload(graph, "transfer_test.words", std::as_bytes(std::span(words))),
                                  target->buffer, 64));
        rg::FrameResources resources;
        readback.bind(resources, *target);
        const rg::Plan& plan = cache.compile(graph, executor.compileOptions());
        const rg::VerifyReport report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor.run(plan, resources);
        // Without waiting: an earlier frame is either not read yet or right.
        for (uint64_t s = target->sequence >= kDepth ? target->sequence - kDepth + 1 : 1; s <= target->sequence; ++s) {
            CAPTURE(s);
            if (const auto bytes = readback.read(s)) {
                expect(s, *bytes);
                ++readEarly;
            }
        }
    }
    executor.waitIdle();
    // The last kDepth frames can still be read; older buffers took newer frames.
    for (uint64_t s = 1; s <= kFrames; ++s) {
        CAPTURE(s);
        const bool kept = s + kDepth > kFrames;
        CHECK(readback.overwritten(s) == !kept);
        const auto bytes = readback.read(s);
        REQUIRE(bytes.has_value() == kept);
        if (bytes) expect(s, *bytes);
    }
    CHECK(readback.read(kFrames + 1) == std::nullopt);
    MESSAGE(readEarly << " reads answered before waiting");
}

TEST_CASE("a semaphore signalled by a buffer that is not an import of the plan is refused by name") {
    test::GpuTest gpu;
    rg::Executor executor(gpu.ctx());
    rg::FrameReadback readback(gpu.ctx(), 4, "transfer_test.gate");
    rg::Graph graph(executor.queueCaps());
    const auto target = readback.declare(graph);
    REQUIRE(target);
    const std::vector<uint32_t> word{7};
    const rg::Buffer uploaded = rg::addUpload(graph, "transfer_test.word", std::as_bytes(std::span(word)));
    graph.markOutput(copyInto(graph, uploaded, target->buffer, 4));
    rg::FrameResources resources;
    readback.bind(resources, *target);
    gpu::TimelineSemaphore other(gpu.ctx(), "transfer_test.other");
    resources.signalSemaphore(rg::Buffer{target->buffer.index + 100, 0, target->buffer.graph}, other.handle(), 1);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    CHECK_THROWS_WITH_AS(executor.run(plan, resources), doctest::Contains("names a buffer that is not an import"),
                         gpu::GpuError);
    CHECK_THROWS_WITH_AS(rg::FrameReadback(gpu.ctx(), 4, "transfer_test.shallow", 1),
                         doctest::Contains("transfer_test.shallow"), rg::GraphError);
}
