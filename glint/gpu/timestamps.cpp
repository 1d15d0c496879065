#include "glint/gpu/timestamps.h"

#include "glint/gpu/context.h"
#include "glint/gpu/error.h"

namespace glint::gpu {

TimestampQueries::TimestampQueries(Context& ctx, uint32_t pairCount) : device_(ctx.device()), pairCount_(pairCount) {
    const auto& caps = ctx.caps();
    if (!caps.timestamps || pairCount == 0) {
        return;
    }
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = pairCount * 2;
    VkQueryPool pool = VK_NULL_HANDLE;
    check(vkCreateQueryPool(device_, &info, nullptr, &pool), "vkCreateQueryPool");
    pool_ = Unique<VkQueryPool>(device_, pool, vkDestroyQueryPool);
    periodNs_ = caps.timestampPeriodNs;
    // The fewest valid bits of any queue that may write timestamps.
    uint32_t bits = caps.queueFamilies[caps.graphicsFamily].timestampValidBits;
    if (caps.computeFamily) {
        bits = std::min(bits, caps.queueFamilies[*caps.computeFamily].timestampValidBits);
    }
    validMask_ = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
    reset();
}

void TimestampQueries::reset() {
    if (pool_) {
        vkResetQueryPool(device_, pool_.get(), 0, pairCount_ * 2);
    }
}

void TimestampQueries::begin(VkCommandBuffer cmd, uint32_t pair, VkPipelineStageFlags2 stage) {
    if (pool_) {
        vkCmdWriteTimestamp2(cmd, stage, pool_.get(), pair * 2);
    }
}

void TimestampQueries::end(VkCommandBuffer cmd, uint32_t pair, VkPipelineStageFlags2 stage) {
    if (pool_) {
        vkCmdWriteTimestamp2(cmd, stage, pool_.get(), pair * 2 + 1);
    }
}

std::vector<std::optional<double>> TimestampQueries::readMilliseconds() const {
    std::vector<std::optional<double>> out(pairCount_);
    if (!pool_) {
        return out;
    }
    // Value + availability word per query.
    std::vector<uint64_t> raw(size_t(pairCount_) * 4);
    const VkResult r = vkGetQueryPoolResults(device_, pool_.get(), 0, pairCount_ * 2, raw.size() * sizeof(uint64_t),
                                             raw.data(), 2 * sizeof(uint64_t),
                                             VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
    if (r != VK_SUCCESS && r != VK_NOT_READY) {
        check(r, "vkGetQueryPoolResults");
    }
    for (uint32_t i = 0; i < pairCount_; ++i) {
        const uint64_t* q = &raw[size_t(i) * 4];
        if (q[1] && q[3]) {
            const uint64_t ticks = ((q[2] & validMask_) - (q[0] & validMask_)) & validMask_;
            out[i] = double(ticks) * periodNs_ * 1e-6;
        }
    }
    return out;
}

} // namespace glint::gpu
