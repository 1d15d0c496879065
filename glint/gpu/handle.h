#pragma once
// Move-only owner of one Vulkan device-level handle.

#include <vulkan/vulkan.h>

#include <utility>

namespace glint::gpu {

template <typename T>
class Unique {
public:
    using Destroy = void (*)(VkDevice, T, const VkAllocationCallbacks*);

    Unique() = default;
    Unique(VkDevice device, T handle, Destroy destroy) : device_(device), handle_(handle), destroy_(destroy) {}
    Unique(Unique&& other) noexcept
        : device_(other.device_), handle_(std::exchange(other.handle_, T(VK_NULL_HANDLE))), destroy_(other.destroy_) {}
    Unique& operator=(Unique&& other) noexcept {
        if (this != &other) {
            reset();
            device_ = other.device_;
            handle_ = std::exchange(other.handle_, T(VK_NULL_HANDLE));
            destroy_ = other.destroy_;
        }
        return *this;
    }
    Unique(const Unique&) = delete;
    Unique& operator=(const Unique&) = delete;
    ~Unique() { reset(); }

    T get() const { return handle_; }
    explicit operator bool() const { return handle_ != T(VK_NULL_HANDLE); }
    void reset() {
        if (handle_ != T(VK_NULL_HANDLE)) {
            destroy_(device_, handle_, nullptr);
            handle_ = T(VK_NULL_HANDLE);
        }
    }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    T handle_ = T(VK_NULL_HANDLE);
    Destroy destroy_ = nullptr;
};

} // namespace glint::gpu
