// The graph's transfer helpers (glint/graph/transfer.h): bytes uploaded
// into a frame with rg::addUpload come back unchanged through
// rg::HostReadback, across vkCmdUpdateBuffer's 64 KiB pieces; misuse is
// refused where it is declared, naming the readback.
#include "support/gpu_test.h"

#include "glint/graph/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"

#include <cstddef>
#include <cstdint>
#include <vector>

using namespace glint;

TEST_CASE("an upload larger than one vkCmdUpdateBuffer reads back byte for byte") {
    test::GpuTest gpu;
    rg::Executor executor(gpu.ctx());
    std::vector<uint32_t> words(70000 / 4);  // 68.4 KiB: two pieces
    for (size_t i = 0; i < words.size(); ++i) words[i] = uint32_t(i * 2654435761u);
    const rg::HostReadback readback(gpu.ctx(), words.size() * 4, "transfer_test.readback");
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const rg::Buffer uploaded = rg::addUpload(graph, "transfer_test.upload", std::as_bytes(std::span(words)));
    readback.copy(graph, resources, uploaded);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const rg::VerifyReport report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
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
