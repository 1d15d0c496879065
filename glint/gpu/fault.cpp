#include "glint/gpu/fault.h"

namespace glint::gpu {

std::string_view faultSiteName(FaultSite site) {
    switch (site) {
    case FaultSite::Allocation: return "allocation";
    case FaultSite::Submit: return "submit";
    case FaultSite::Wait: return "wait";
    }
    return "?";
}

VkResult FaultInjector::next(FaultSite site) {
    const uint64_t call = ++calls_[size_t(site)];
    if (lost_.load()) return VK_ERROR_DEVICE_LOST;
    if (!plan_ || plan_->site != site || plan_->failAt != call) return VK_SUCCESS;
    fired_ = true;
    if (plan_->result == VK_ERROR_DEVICE_LOST) lost_ = true;
    return plan_->result;
}

} // namespace glint::gpu
