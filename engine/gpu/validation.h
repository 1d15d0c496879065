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
class ValidationLog {
public:
    void add(ValidationMessage message);
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
};

// Name of the Khronos validation layer.
inline constexpr const char* kValidationLayerName = "VK_LAYER_KHRONOS_validation";

} // namespace glint::gpu
