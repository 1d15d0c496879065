#pragma once
// Command recording and submission helpers: a command pool per queue family,
// one-shot submissions, timeline semaphores, sync2 barriers, debug labels,
// and upload / readback of buffers and images.

#include "glint/gpu/context.h"
#include "glint/gpu/handle.h"
#include "glint/gpu/resources.h"

#include <cstring>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

namespace glint::gpu {

class CommandPool {
public:
    CommandPool() = default;
    CommandPool(Context& ctx, uint32_t family, std::string_view name);
    // A primary command buffer in the initial state, freed with the pool.
    // After reset() the pool hands out the buffers it already has before it
    // allocates more (vkResetCommandPool returns buffers to the initial
    // state but does not free them), so a pool reset every frame holds as
    // many buffers as the busiest frame needed, not one more per frame.
    VkCommandBuffer allocate();
    // Returns every command buffer of the pool to the initial state and
    // makes them all available to allocate() again.
    void reset();
    VkCommandPool handle() const { return pool_.get(); }
    // Command buffers the pool holds, in use or not.
    size_t allocatedCount() const { return buffers_.size(); }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    Unique<VkCommandPool> pool_;
    std::vector<VkCommandBuffer> buffers_;
    size_t used_ = 0;
};

class TimelineSemaphore {
public:
    TimelineSemaphore() = default;
    TimelineSemaphore(Context& ctx, std::string_view name, uint64_t initial = 0);
    VkSemaphore handle() const { return semaphore_.get(); }
    uint64_t value() const;
    // Waits on the host; throws GpuError naming the semaphore on timeout
    // or failure.
    void wait(uint64_t value, uint64_t timeoutNs = 10'000'000'000ull) const;
    // Whether the semaphore has reached `value`, without waiting. A host
    // wait when it has: what the device made available to the host before
    // signalling it is then visible (a readback's bytes).
    bool reached(uint64_t value) const;

private:
    VkDevice device_ = VK_NULL_HANDLE;
    FaultInjector* faults_ = nullptr;
    std::string name_;
    Unique<VkSemaphore> semaphore_;
};

// Records with `record`, submits to `queue` and waits (10 s limit: a hang
// becomes an error naming `what`, never a frozen process).
void submitAndWait(Context& ctx, const Queue& queue, std::string_view what,
                   const std::function<void(VkCommandBuffer)>& record);

// ---- barriers (sync2). The render graph derives its masks from its access
// table; these are for code below the graph (uploads, tests).
void bufferBarrier(VkCommandBuffer cmd, const Buffer& buffer, VkPipelineStageFlags2 srcStage,
                   VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess);
void imageBarrier(VkCommandBuffer cmd, const Image& image, VkImageLayout oldLayout, VkImageLayout newLayout,
                  VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess);
// The same for part of the image (mips, layers).
void imageBarrier(VkCommandBuffer cmd, const Image& image, const VkImageSubresourceRange& range,
                  VkImageLayout oldLayout, VkImageLayout newLayout, VkPipelineStageFlags2 srcStage,
                  VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess);
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess);

// Dynamic rendering that draws over what a colour attachment holds (loaded
// and stored) behind a depth attachment that is tested, never written
// (loaded, not stored), both in the layouts given; the viewport and scissor
// cover `extent` (positive height: Glint's projections flip Y themselves).
// The forward passes over the G-buffer (particles, blended surfaces) draw
// this way. End with vkCmdEndRendering.
void beginRenderingOverDepth(VkCommandBuffer cmd, VkImageView color, VkImageLayout colorLayout, VkImageView depth,
                             VkImageLayout depthLayout, VkExtent2D extent);

// Debug-utils label around a region of a command buffer.
class ScopedLabel {
public:
    ScopedLabel(const Context& ctx, VkCommandBuffer cmd, std::string_view name);
    ~ScopedLabel();
    ScopedLabel(const ScopedLabel&) = delete;
    ScopedLabel& operator=(const ScopedLabel&) = delete;

private:
    const Context& ctx_;
    VkCommandBuffer cmd_;
};

// ---- transfers. Each waits for completion; for setup and tests, not for
// per-frame streaming.
void uploadBuffer(Context& ctx, const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset = 0);
template <typename T> void uploadBuffer(Context& ctx, const Buffer& dst, std::span<const T> data) {
    uploadBuffer(ctx, dst, data.data(), data.size_bytes());
}
// Creates a device-local buffer holding `data`.
Buffer createBufferWithData(Context& ctx, const BufferDesc& desc, const void* data);

// A sampled 2D image of `desc` (usage and mips are set here: the full chain)
// holding `texels` (tightly packed rows of mip 0, layer after layer), the smaller mips
// filtered down by linear blits; left in SHADER_READ_ONLY_OPTIMAL, visible
// to every later command. `desc.format` must support linear blits.
Image createSampledImageWithMips(Context& ctx, const ImageDesc& desc, const void* texels);

std::vector<std::byte> readbackBuffer(Context& ctx, const Buffer& src, const Queue* queue = nullptr);
template <typename T> std::vector<T> readbackBufferAs(Context& ctx, const Buffer& src) {
    const auto bytes = readbackBuffer(ctx, src);
    std::vector<T> out(bytes.size() / sizeof(T));
    std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
    return out;
}
// Copies mip `mip`, layer 0 of `src`, currently in `layout` (every mip; left
// there), and returns tightly packed texels.
std::vector<std::byte> readbackImage(Context& ctx, const Image& src, VkImageLayout layout,
                                     VkPipelineStageFlags2 lastStage, VkAccessFlags2 lastAccess, uint32_t mip = 0);

} // namespace glint::gpu
