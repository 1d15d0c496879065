#include "glint/gpu/commands.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <string>
#include <bit>

namespace glint::gpu {

// ---------------------------------------------------------------- CommandPool

CommandPool::CommandPool(Context& ctx, uint32_t family, std::string_view name) : device_(ctx.device()) {
    VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    info.queueFamilyIndex = family;
    VkCommandPool pool = VK_NULL_HANDLE;
    check(vkCreateCommandPool(device_, &info, nullptr, &pool), "vkCreateCommandPool");
    pool_ = Unique<VkCommandPool>(device_, pool, vkDestroyCommandPool);
    ctx.setName(pool, VK_OBJECT_TYPE_COMMAND_POOL, name);
}

VkCommandBuffer CommandPool::allocate() {
    if (used_ < buffers_.size()) return buffers_[used_++];
    VkCommandBufferAllocateInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    info.commandPool = pool_.get();
    info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    info.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device_, &info, &cmd), "vkAllocateCommandBuffers");
    buffers_.push_back(cmd);
    ++used_;
    return cmd;
}

void CommandPool::reset() {
    check(vkResetCommandPool(device_, pool_.get(), 0), "vkResetCommandPool");
    used_ = 0;
}

// ---------------------------------------------------------------- TimelineSemaphore

TimelineSemaphore::TimelineSemaphore(Context& ctx, std::string_view name, uint64_t initial)
    : device_(ctx.device()), faults_(&ctx.faults()), name_(name) {
    VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    type.initialValue = initial;
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    info.pNext = &type;
    VkSemaphore semaphore = VK_NULL_HANDLE;
    check(vkCreateSemaphore(device_, &info, nullptr, &semaphore), "vkCreateSemaphore");
    semaphore_ = Unique<VkSemaphore>(device_, semaphore, vkDestroySemaphore);
    ctx.setName(semaphore, VK_OBJECT_TYPE_SEMAPHORE, name);
}

uint64_t TimelineSemaphore::value() const {
    uint64_t v = 0;
    check(vkGetSemaphoreCounterValue(device_, semaphore_.get(), &v), "vkGetSemaphoreCounterValue");
    return v;
}

void TimelineSemaphore::wait(uint64_t value, uint64_t timeoutNs) const {
    VkSemaphore s = semaphore_.get();
    VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
    info.semaphoreCount = 1;
    info.pSemaphores = &s;
    info.pValues = &value;
    VkResult r = vkWaitSemaphores(device_, &info, timeoutNs);
    if (r == VK_SUCCESS && faults_) r = faults_->next(FaultSite::Wait);
    if (r == VK_TIMEOUT) {
        throw GpuError("timeline semaphore '" + name_ + "' did not reach " + std::to_string(value) +
                       " in time (GPU hang or a wait that nothing signals)");
    }
    check(r, "vkWaitSemaphores '" + name_ + "'");
}

bool TimelineSemaphore::reached(uint64_t value) const {
    VkSemaphore s = semaphore_.get();
    VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
    info.semaphoreCount = 1;
    info.pSemaphores = &s;
    info.pValues = &value;
    const VkResult r = vkWaitSemaphores(device_, &info, 0);
    if (r == VK_TIMEOUT) return false;
    check(r, "vkWaitSemaphores '" + name_ + "'");
    return true;
}

// ---------------------------------------------------------------- submission

void submitAndWait(Context& ctx, const Queue& queue, std::string_view what,
                   const std::function<void(VkCommandBuffer)>& record) {
    ctx.countBlockingSubmit();
    CommandPool pool(ctx, queue.family, what);
    VkCommandBuffer cmd = pool.allocate();
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    record(cmd);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    check(vkCreateFence(ctx.device(), &fenceInfo, nullptr, &fence), "vkCreateFence");
    Unique<VkFence> fenceOwner(ctx.device(), fence, vkDestroyFence);

    VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmdInfo.commandBuffer = cmd;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmdInfo;
    VkResult submitted = ctx.faults().next(FaultSite::Submit);
    if (submitted == VK_SUCCESS) submitted = vkQueueSubmit2(queue.queue, 1, &submit, fence);
    check(submitted, std::string("vkQueueSubmit2 (") + std::string(what) + ")");
    VkResult r = vkWaitForFences(ctx.device(), 1, &fence, VK_TRUE, 10'000'000'000ull);
    if (r == VK_SUCCESS) r = ctx.faults().next(FaultSite::Wait);
    if (r == VK_TIMEOUT) {
        // The pool cannot be destroyed while the GPU may still use it; a
        // device wait would hang too. Report and let the device be torn down.
        throw GpuError(std::string(what) + ": GPU work did not finish within 10 s");
    }
    check(r, std::string("vkWaitForFences (") + std::string(what) + ")");
}

void beginRenderingOverDepth(VkCommandBuffer cmd, VkImageView color, VkImageLayout colorLayout, VkImageView depth,
                             VkImageLayout depthLayout, VkExtent2D extent) {
    VkRenderingAttachmentInfo colorAttachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    colorAttachment.imageView = color;
    colorAttachment.imageLayout = colorLayout;
    colorAttachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    colorAttachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingAttachmentInfo depthAttachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depthAttachment.imageView = depth;
    depthAttachment.imageLayout = depthLayout;
    depthAttachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    depthAttachment.storeOp = VK_ATTACHMENT_STORE_OP_NONE;  // tested, never written
    VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
    rendering.renderArea = {{0, 0}, extent};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachments = &colorAttachment;
    rendering.pDepthAttachment = &depthAttachment;
    vkCmdBeginRendering(cmd, &rendering);
    const VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, extent};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

// ---------------------------------------------------------------- barriers

void bufferBarrier(VkCommandBuffer cmd, const Buffer& buffer, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
    VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.buffer = buffer.handle();
    b.offset = 0;
    b.size = VK_WHOLE_SIZE;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.bufferMemoryBarrierCount = 1;
    dep.pBufferMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

void imageBarrier(VkCommandBuffer cmd, const Image& image, VkImageLayout oldLayout, VkImageLayout newLayout,
                  VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess) {
    imageBarrier(cmd, image, image.fullRange(), oldLayout, newLayout, srcStage, srcAccess, dstStage, dstAccess);
}

void imageBarrier(VkCommandBuffer cmd, const Image& image, const VkImageSubresourceRange& range,
                  VkImageLayout oldLayout, VkImageLayout newLayout, VkPipelineStageFlags2 srcStage,
                  VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    b.oldLayout = oldLayout;
    b.newLayout = newLayout;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image.handle();
    b.subresourceRange = range;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
    VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

// ---------------------------------------------------------------- labels

ScopedLabel::ScopedLabel(const Context& ctx, VkCommandBuffer cmd, std::string_view name) : ctx_(ctx), cmd_(cmd) {
    if (ctx_.fn().cmdBeginDebugUtilsLabel) {
        const std::string n(name);
        VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
        label.pLabelName = n.c_str();
        ctx_.fn().cmdBeginDebugUtilsLabel(cmd_, &label);
    }
}

ScopedLabel::~ScopedLabel() {
    if (ctx_.fn().cmdEndDebugUtilsLabel) {
        ctx_.fn().cmdEndDebugUtilsLabel(cmd_);
    }
}

// ---------------------------------------------------------------- transfers

void uploadBuffer(Context& ctx, const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset) {
    if (offset + size > dst.size()) {
        throw GpuError("upload to '" + dst.desc().name + "': " + std::to_string(size) + " bytes at offset " +
                       std::to_string(offset) + " exceed its " + std::to_string(dst.size()) + " bytes");
    }
    if (dst.mapped()) {
        std::memcpy(dst.mapped() + offset, data, size);
        return;
    }
    Buffer staging(ctx, {size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::Upload, dst.desc().name + ".staging"});
    std::memcpy(staging.mapped(), data, size);
    submitAndWait(ctx, ctx.graphicsQueue(), "upload '" + dst.desc().name + "'", [&](VkCommandBuffer cmd) {
        const VkBufferCopy region{0, offset, size};
        vkCmdCopyBuffer(cmd, staging.handle(), dst.handle(), 1, &region);
        // Make the copy visible to whatever reads the buffer next.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    });
}

Buffer createBufferWithData(Context& ctx, const BufferDesc& desc, const void* data) {
    BufferDesc d = desc;
    d.usage |= VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    Buffer buffer(ctx, d);
    uploadBuffer(ctx, buffer, data, d.size);
    return buffer;
}

Image createSampledImageWithMips(Context& ctx, const ImageDesc& desc, const void* texels) {
    ImageDesc d = desc;
    d.mips = uint32_t(std::bit_width(std::max(d.width, d.height)));
    d.usage |= VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    Image image(ctx, d);
    const VkDeviceSize bytes = VkDeviceSize(d.width) * d.height * d.layers * bytesPerTexel(d.format);
    Buffer staging(ctx, {bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::Upload, d.name + ".staging"});
    std::memcpy(staging.mapped(), texels, bytes);
    submitAndWait(ctx, ctx.graphicsQueue(), "upload '" + d.name + "'", [&](VkCommandBuffer cmd) {
        const auto mipBarrier = [&](uint32_t mip, VkImageLayout from, VkImageLayout to, VkPipelineStageFlags2 srcStage,
                                    VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                                    VkAccessFlags2 dstAccess) {
            imageBarrier(cmd, image, {VK_IMAGE_ASPECT_COLOR_BIT, mip, 1, 0, d.layers}, from, to, srcStage, srcAccess,
                         dstStage, dstAccess);
        };
        // Every mip to TRANSFER_DST; mip 0 gets the texels.
        for (uint32_t mip = 0; mip < d.mips; ++mip) {
            mipBarrier(mip, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        }
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, d.layers};
        region.imageExtent = {d.width, d.height, 1};
        vkCmdCopyBufferToImage(cmd, staging.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        // Each mip from the one above it, which then becomes readable.
        for (uint32_t mip = 1; mip < d.mips; ++mip) {
            mipBarrier(mip - 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
            const int32_t srcW = int32_t(std::max(d.width >> (mip - 1), 1u));
            const int32_t srcH = int32_t(std::max(d.height >> (mip - 1), 1u));
            const int32_t dstW = int32_t(std::max(d.width >> mip, 1u));
            const int32_t dstH = int32_t(std::max(d.height >> mip, 1u));
            VkImageBlit blit{};
            blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip - 1, 0, d.layers};
            blit.srcOffsets[1] = {srcW, srcH, 1};
            blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, d.layers};
            blit.dstOffsets[1] = {dstW, dstH, 1};
            vkCmdBlitImage(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image.handle(),
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
            mipBarrier(mip - 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                       VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT);
        }
        mipBarrier(d.mips - 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                   VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT);
    });
    return image;
}

std::vector<std::byte> readbackBuffer(Context& ctx, const Buffer& src, const Queue* queue) {
    std::vector<std::byte> out(src.size());
    if (src.mapped()) {
        std::memcpy(out.data(), src.mapped(), out.size());
        return out;
    }
    Buffer staging(ctx, {src.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::Readback, src.desc().name + ".readback"});
    submitAndWait(ctx, queue ? *queue : ctx.graphicsQueue(), "readback '" + src.desc().name + "'", [&](VkCommandBuffer cmd) {
        // Whatever wrote the buffer before this submission is made available
        // by the submission order plus this barrier.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                      VK_ACCESS_2_TRANSFER_READ_BIT);
        const VkBufferCopy region{0, 0, src.size()};
        vkCmdCopyBuffer(cmd, src.handle(), staging.handle(), 1, &region);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                      VK_ACCESS_2_HOST_READ_BIT);
    });
    std::memcpy(out.data(), staging.mapped(), out.size());
    return out;
}

std::vector<std::byte> readbackImage(Context& ctx, const Image& src, VkImageLayout layout,
                                     VkPipelineStageFlags2 lastStage, VkAccessFlags2 lastAccess, uint32_t mip) {
    if (mip >= src.desc().mips) {
        throw GpuError("readback of image '" + src.desc().name + "': no mip " + std::to_string(mip) + " (it has " +
                       std::to_string(src.desc().mips) + ")");
    }
    const VkExtent3D full = src.extent();
    const VkExtent3D e{std::max(full.width >> mip, 1u), std::max(full.height >> mip, 1u), std::max(full.depth >> mip, 1u)};
    const VkDeviceSize size = VkDeviceSize(e.width) * e.height * e.depth * bytesPerTexel(src.format());
    Buffer staging(ctx, {size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::Readback, src.desc().name + ".readback"});
    submitAndWait(ctx, ctx.graphicsQueue(), "readback '" + src.desc().name + "'", [&](VkCommandBuffer cmd) {
        imageBarrier(cmd, src, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, lastStage, lastAccess,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        VkBufferImageCopy region{};
        region.imageSubresource = {src.aspect(), mip, 0, 1};
        region.imageExtent = e;
        vkCmdCopyImageToBuffer(cmd, src.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(), 1, &region);
        imageBarrier(cmd, src, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout, VK_PIPELINE_STAGE_2_COPY_BIT, 0, lastStage, 0);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                      VK_ACCESS_2_HOST_READ_BIT);
    });
    std::vector<std::byte> out(size);
    std::memcpy(out.data(), staging.mapped(), size);
    return out;
}

} // namespace glint::gpu
