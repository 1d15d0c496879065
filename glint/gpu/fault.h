#pragma once
// Driver failures on demand, so that tests can check what a real device
// failure does to the program: the Nth device memory allocation, queue
// submission or host wait (fence or timeline semaphore) reports the chosen
// VkResult, as a driver would. ContextOptions::fault sets it up; every call
// site of the three kinds asks the Context's injector (before allocating
// or submitting, after waiting).
//
// A submission that fails was not made (nothing of it runs); a wait that
// fails waited first, so the work it waited for is finished (a test's
// objects can be destroyed without racing the GPU). VK_ERROR_DEVICE_LOST
// is sticky, as on a lost device: once injected, every later call of every
// kind fails with it.

#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string_view>

namespace glint::gpu {

enum class FaultSite : uint8_t { Allocation, Submit, Wait };
inline constexpr size_t kFaultSites = 3;
std::string_view faultSiteName(FaultSite site);

struct FaultInjection {
    FaultSite site = FaultSite::Submit;
    // The call at `site`, counted from 1, that fails; 0: none.
    uint64_t failAt = 0;
    VkResult result = VK_ERROR_DEVICE_LOST;
};

class FaultInjector {
public:
    explicit FaultInjector(std::optional<FaultInjection> plan = std::nullopt) : plan_(plan) {}

    // Counts a call at `site`: VK_SUCCESS, or the failure to report instead
    // of the driver's answer.
    VkResult next(FaultSite site);
    // Calls counted at `site` so far.
    uint64_t calls(FaultSite site) const { return calls_[size_t(site)].load(); }
    // Whether the planned failure has been reported.
    bool fired() const { return fired_.load(); }

private:
    std::optional<FaultInjection> plan_;
    std::array<std::atomic<uint64_t>, kFaultSites> calls_{};
    std::atomic<bool> fired_{false};
    std::atomic<bool> lost_{false};
};

} // namespace glint::gpu
