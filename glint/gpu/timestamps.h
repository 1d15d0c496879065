#pragma once
// GPU timestamps: a query pool with begin/end pairs, read back in
// milliseconds. Devices (or queues) without timestamps give no numbers
// rather than wrong ones.

#include "glint/gpu/handle.h"

#include <vulkan/vulkan.h>

#include <optional>
#include <vector>

namespace glint::gpu {

class Context;

class TimestampQueries {
public:
    TimestampQueries() = default;
    TimestampQueries(Context& ctx, uint32_t pairCount);

    bool enabled() const { return static_cast<bool>(pool_); }
    uint32_t pairCount() const { return pairCount_; }
    // Host-side reset of every query (before the command buffers that write them).
    void reset();
    void begin(VkCommandBuffer cmd, uint32_t pair, VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT);
    void end(VkCommandBuffer cmd, uint32_t pair, VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT);
    // Milliseconds per pair; nothing for pairs not written or not yet available.
    std::vector<std::optional<double>> readMilliseconds() const;

private:
    VkDevice device_ = VK_NULL_HANDLE;
    Unique<VkQueryPool> pool_;
    uint32_t pairCount_ = 0;
    double periodNs_ = 1.0;
    uint64_t validMask_ = ~0ull;
};

} // namespace glint::gpu
