#pragma once
// Errors of the GPU layer: one exception type carrying what failed and where,
// so an executable can catch at main, print one line and exit non-zero.

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace glint::gpu {

class GpuError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Name of a VkResult ("VK_ERROR_OUT_OF_DEVICE_MEMORY").
std::string_view resultName(VkResult result);

// Throws GpuError("<what>: <VkResult name>") unless result is VK_SUCCESS.
inline void check(VkResult result, std::string_view what) {
    if (result != VK_SUCCESS) {
        throw GpuError(std::string(what) + " failed: " + std::string(resultName(result)));
    }
}

} // namespace glint::gpu
