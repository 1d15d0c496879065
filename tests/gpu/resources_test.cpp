// Buffers, images, memory placement (aliasing), transfers and timestamps.
#include "support/gpu_test.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/timestamps.h"

#include <numeric>

using namespace glint;

TEST_CASE("upload then readback returns the same bytes") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    std::vector<uint32_t> data(1000);
    std::iota(data.begin(), data.end(), 42u);
    const auto buffer = gpu::createBufferWithData(
        ctx, {data.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
              gpu::MemoryUsage::DeviceLocal, "roundtrip"},
        data.data());
    CHECK(gpu::readbackBufferAs<uint32_t>(ctx, buffer) == data);
    CHECK(buffer.address() != 0);
}

TEST_CASE("two buffers placed in the same memory see each other's writes") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    constexpr uint32_t kWords = 512;
    const gpu::BufferDesc descA{kWords * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal, "alias.a"};
    const gpu::BufferDesc descB{kWords * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::DeviceLocal, "alias.b"};
    VkMemoryRequirements req = gpu::Buffer::requirements(ctx, descA);
    const VkMemoryRequirements reqB = gpu::Buffer::requirements(ctx, descB);
    req.size = std::max(req.size, reqB.size);
    req.alignment = std::max(req.alignment, reqB.alignment);
    req.memoryTypeBits &= reqB.memoryTypeBits;
    gpu::Allocation memory = ctx.memory().allocate(req, gpu::MemoryUsage::DeviceLocal, true, "alias.heap");
    gpu::Buffer a(ctx, descA, memory.range());
    gpu::Buffer b(ctx, descB, memory.range());

    const auto pipeline = gpu::createComputePipeline(
        ctx, {"test/fill_buffer.comp", {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_SHADER_STAGE_COMPUTE_BIT}}, 8,
              "alias.fill"});
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "alias", [&](VkCommandBuffer cmd) {
        pipeline.bind(cmd);
        gpu::PushDescriptors(pipeline).storageBuffer(0, a).push(ctx, cmd);
        const uint32_t push[2] = {kWords, 1000};
        pipeline.pushConstants(cmd, push, sizeof(push));
        vkCmdDispatch(cmd, kWords / 64, 1, 1);
        // The alias takes over the bytes: a memory dependency covers both.
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    });
    const auto words = gpu::readbackBufferAs<uint32_t>(ctx, b);
    REQUIRE(words.size() == kWords);
    for (uint32_t i = 0; i < kWords; ++i) {
        REQUIRE(words[i] == 1000 + i);
    }
}

TEST_CASE("memory allocator reuses a block for small resources and frees dedicated ones") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto before = ctx.memory().stats();
    {
        gpu::Buffer x(ctx, {4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal, "x"});
        gpu::Buffer y(ctx, {4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal, "y"});
        const auto during = ctx.memory().stats();
        CHECK(during.blockCount <= before.blockCount + 1);
        CHECK(during.usedBytes >= before.usedBytes + 8192);
        gpu::Buffer big(ctx, {100ull << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal, "big"});
        CHECK(ctx.memory().stats().blockCount == during.blockCount + 1);
    }
    const auto after = ctx.memory().stats();
    CHECK(after.usedBytes == before.usedBytes);
    CHECK(after.blockBytes < (100ull << 20) + before.blockBytes);  // the dedicated block went back
}

TEST_CASE("an image can be cleared and read back") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    gpu::Image image(ctx, {16, 8, 1, 1, 1, VK_FORMAT_R8G8B8A8_UNORM,
                           VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "cleared"});
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "clear", [&](VkCommandBuffer cmd) {
        gpu::imageBarrier(cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        const VkClearColorValue color{{1.0f, 0.5f, 0.0f, 1.0f}};
        const VkImageSubresourceRange range = image.fullRange();
        vkCmdClearColorImage(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color, 1, &range);
    });
    const auto texels = gpu::readbackImage(ctx, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                           VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    REQUIRE(texels.size() == 16 * 8 * 4);
    CHECK(uint8_t(texels[0]) == 255);
    CHECK(uint8_t(texels[1]) >= 127);
    CHECK(uint8_t(texels[1]) <= 128);
    CHECK(uint8_t(texels[2]) == 0);
    CHECK(uint8_t(texels[16 * 8 * 4 - 1]) == 255);
}

TEST_CASE("timestamps measure a dispatch") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    if (!ctx.caps().timestamps) {
        MESSAGE("device has no timestamps on the graphics queue");
        return;
    }
    const auto pipeline = gpu::createComputePipeline(
        ctx, {"test/fill_buffer.comp", {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_SHADER_STAGE_COMPUTE_BIT}}, 8,
              "timed.fill"});
    gpu::Buffer buffer(ctx, {1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal, "timed"});
    gpu::TimestampQueries timer(ctx, 2);
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "timed", [&](VkCommandBuffer cmd) {
        timer.begin(cmd, 0);
        pipeline.bind(cmd);
        gpu::PushDescriptors(pipeline).storageBuffer(0, buffer).push(ctx, cmd);
        const uint32_t push[2] = {(1 << 20) / 4, 0};
        pipeline.pushConstants(cmd, push, sizeof(push));
        vkCmdDispatch(cmd, (1 << 18) / 64, 1, 1);
        timer.end(cmd, 0);
    });
    const auto ms = timer.readMilliseconds();
    REQUIRE(ms.size() == 2);
    REQUIRE(ms[0].has_value());
    CHECK(*ms[0] >= 0.0);
    CHECK(*ms[0] < 10000.0);
    CHECK_FALSE(ms[1].has_value());  // pair 1 was never written
}
