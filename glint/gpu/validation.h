#pragma once
// The validation harness: the Khronos validation layer with synchronization
// validation (including submit-time checks across command buffers), and a
// persistent debug-utils messenger that keeps every warning and error it
// reports. Tests fail on any collected message.

#include <vulkan/vulkan.h>

#include <mutex>
#include <string>
#include <vector>

namespace glint::gpu {

struct ValidationMessage {
    VkDebugUtilsMessageSeverityFlagBitsEXT severity;
    std::string id;   // e.g. "SYNC-HAZARD-READ-AFTER-WRITE", "VUID-vkCmdDispatch-..."
    std::string text;
};

// Thread-safe sink for the messenger callback. Owned by the Context.
//
// One class of message is set aside instead of kept: cross-queue "racing"
// hazards (SYNC-HAZARD-*-RACING-*) reported at queue submission. The
// 1.3.239 layer's submit-time synchronization validation does not model
// timeline semaphores (KhronosGroup/Vulkan-ValidationLayers#7600, fixed in
// 2024 releases), so every cross-queue dependency the render graph makes
// with them is reported as a race. Those dependencies are proven by the
// graph's own verifier (glint/graph/verify.h) instead; the set-aside
// messages are counted and logged at debug level.
class ValidationLog {
public:
    void add(ValidationMessage message);
    // Cross-queue races set aside (see above).
    size_t setAside() const;
    std::vector<ValidationMessage> messages() const;
    size_t count() const;
    // Messages whose id contains `idSubstring` (e.g. "SYNC-HAZARD").
    size_t countMatching(std::string_view idSubstring) const;
    void clear();
    // All messages as one readable block, for test failure output.
    std::string summary() const;

private:
    mutable std::mutex mutex_;
    std::vector<ValidationMessage> messages_;
    size_t setAside_ = 0;
};

// Name of the Khronos validation layer.
inline constexpr const char* kValidationLayerName = "VK_LAYER_KHRONOS_validation";

} // namespace glint::gpu
