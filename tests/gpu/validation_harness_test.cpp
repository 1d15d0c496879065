// The validation harness must catch what it exists to catch: these tests
// provoke known hazards and expect them reported, and run the same work
// correctly synchronised and expect silence.
#include "support/gpu_test.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/pipeline.h"

using namespace glint;

namespace {

constexpr uint32_t kWords = 256;

struct FillPush {
    uint32_t count;
    uint32_t value;
};

gpu::Pipeline fillPipeline(gpu::Context& ctx) {
    return gpu::createComputePipeline(
        ctx, {"test/fill_buffer.comp", {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_SHADER_STAGE_COMPUTE_BIT}},
              sizeof(FillPush), "test.fill"});
}

void recordFill(gpu::Context& ctx, VkCommandBuffer cmd, const gpu::Pipeline& p, const gpu::Buffer& b, uint32_t value) {
    p.bind(cmd);
    gpu::PushDescriptors(p).storageBuffer(0, b).push(ctx, cmd);
    p.pushConstants(cmd, FillPush{kWords, value});
    vkCmdDispatch(cmd, kWords / 64, 1, 1);
}

} // namespace

TEST_CASE("validation harness reports a dispatch write followed by an unsynchronised copy") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto pipeline = fillPipeline(ctx);
    gpu::Buffer src(ctx, {kWords * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          gpu::MemoryUsage::DeviceLocal, "hazard.src"});
    gpu::Buffer dst(ctx, {kWords * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback, "hazard.dst"});
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "hazard", [&](VkCommandBuffer cmd) {
        recordFill(ctx, cmd, pipeline, src, 7);
        // No barrier: the copy reads what the dispatch may still be writing.
        const VkBufferCopy region{0, 0, kWords * 4};
        vkCmdCopyBuffer(cmd, src.handle(), dst.handle(), 1, &region);
    });
    CHECK(gpu.log().countMatching("SYNC-HAZARD-READ-AFTER-WRITE") >= 1);
    gpu.log().clear();  // expected; the fixture checks nothing else was said
}

TEST_CASE("validation harness reports a hazard between two submissions") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto pipeline = fillPipeline(ctx);
    gpu::Buffer src(ctx, {kWords * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          gpu::MemoryUsage::DeviceLocal, "submit-hazard.src"});
    gpu::Buffer dst(ctx, {kWords * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback, "submit-hazard.dst"});
    gpu::CommandPool pool(ctx, ctx.graphicsQueue().family, "submit-hazard");
    VkCommandBuffer cmds[2] = {pool.allocate(), pool.allocate()};
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cmds[0], &begin);
    recordFill(ctx, cmds[0], pipeline, src, 3);
    vkEndCommandBuffer(cmds[0]);
    vkBeginCommandBuffer(cmds[1], &begin);
    const VkBufferCopy region{0, 0, kWords * 4};
    vkCmdCopyBuffer(cmds[1], src.handle(), dst.handle(), 1, &region);
    vkEndCommandBuffer(cmds[1]);
    // Two submissions in one call, no barrier between them: each command
    // buffer alone is fine; only submit-time validation sees the hazard.
    VkCommandBufferSubmitInfo infos[2] = {{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO},
                                          {VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO}};
    infos[0].commandBuffer = cmds[0];
    infos[1].commandBuffer = cmds[1];
    VkSubmitInfo2 submits[2] = {{VK_STRUCTURE_TYPE_SUBMIT_INFO_2}, {VK_STRUCTURE_TYPE_SUBMIT_INFO_2}};
    submits[0].commandBufferInfoCount = 1;
    submits[0].pCommandBufferInfos = &infos[0];
    submits[1].commandBufferInfoCount = 1;
    submits[1].pCommandBufferInfos = &infos[1];
    REQUIRE(vkQueueSubmit2(ctx.graphicsQueue().queue, 2, submits, VK_NULL_HANDLE) == VK_SUCCESS);
    ctx.waitIdle();
    CHECK(gpu.log().countMatching("SYNC-HAZARD-READ-AFTER-WRITE") >= 1);
    gpu.log().clear();
}

TEST_CASE("validation harness is silent when the copy waits for the dispatch") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto pipeline = fillPipeline(ctx);
    gpu::Buffer src(ctx, {kWords * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          gpu::MemoryUsage::DeviceLocal, "clean.src"});
    gpu::Buffer dst(ctx, {kWords * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback, "clean.dst"});
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "clean", [&](VkCommandBuffer cmd) {
        recordFill(ctx, cmd, pipeline, src, 100);
        gpu::bufferBarrier(cmd, src, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        const VkBufferCopy region{0, 0, kWords * 4};
        vkCmdCopyBuffer(cmd, src.handle(), dst.handle(), 1, &region);
        gpu::bufferBarrier(cmd, dst, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    });
    const auto words = dst.mappedSpan<uint32_t>();
    REQUIRE(words.size() == kWords);
    for (uint32_t i = 0; i < kWords; ++i) {
        REQUIRE(words[i] == 100 + i);
    }
    CHECK(gpu.log().count() == 0);
}
