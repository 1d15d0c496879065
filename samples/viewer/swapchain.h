#pragma once
// The window's surface and swapchain, and the semaphores presentation needs.
//
// Colour: the reflection frame's output holds sRGB-encoded bytes in an
// RGBA8_UNORM image. The swapchain is asked for an 8-bit BGRA/RGBA format in
// the sRGB colour space, UNORM first; the viewer writes those bytes
// unchanged (a UNORM blit, or a raw copy into an SRGB image, never a
// conversion), so the presentation engine gets the encoded values once: no
// double encoding. copyFormat() is the UNORM variant, the format the viewer
// composes in (ImGui's colours are sRGB-encoded too, so it blends them in
// that space, as ImGui expects); when it equals format(), the viewer draws
// straight into the swapchain images (present_passes.h).
//
// The images are handed to the render graph through non-owning gpu::Image
// wrappers (made with each swapchain, with a view each for the UI's
// framebuffers).

#include "glint/gpu/context.h"
#include "glint/gpu/handle.h"
#include "glint/gpu/resources.h"

#include <vulkan/vulkan.h>

#include <optional>
#include <vector>

namespace glint::viewer {

class Swapchain {
public:
    // Fails (GpuError) where the graphics queue cannot present to `surface`
    // or the surface has no 8-bit colour format with transfer-destination use.
    Swapchain(gpu::Context& ctx, VkSurfaceKHR surface, VkExtent2D wanted);
    ~Swapchain();
    Swapchain(const Swapchain&) = delete;
    Swapchain& operator=(const Swapchain&) = delete;

    // A new swapchain of (about) `wanted` size. The device must be idle.
    void recreate(VkExtent2D wanted);

    VkFormat format() const { return format_; }
    // The UNORM format of the same bytes (see the file comment).
    VkFormat copyFormat() const { return copyFormat_; }
    VkExtent2D extent() const { return extent_; }
    uint32_t imageCount() const { return uint32_t(images_.size()); }
    uint32_t minImageCount() const { return minImageCount_; }
    VkImage image(uint32_t index) const { return images_.at(index); }
    // Image `index` as a gpu::Image that does not own it, for FrameResources::bind.
    const gpu::Image& wrapped(uint32_t index) const { return wrapped_.at(index); }
    // Signalled by the submission that finishes image `index`, waited by its
    // present. One per image: a semaphore handed to a present may be reused
    // only once that image is acquired again.
    VkSemaphore presentReady(uint32_t index) const { return presentReady_.at(index).get(); }

    // The next image, `signal` signalled when it may be written; none when
    // the swapchain no longer fits the surface (recreate, then try again).
    std::optional<uint32_t> acquire(VkSemaphore signal);
    // Presents image `index` once presentReady(index) is signalled; false
    // when the swapchain should be recreated (out of date or suboptimal).
    bool present(uint32_t index);

private:
    void create(VkExtent2D wanted);

    gpu::Context& ctx_;
    VkSurfaceKHR surface_;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkFormat copyFormat_ = VK_FORMAT_UNDEFINED;
    VkColorSpaceKHR colorSpace_ = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
    VkExtent2D extent_{};
    uint32_t minImageCount_ = 2;
    gpu::Unique<VkSwapchainKHR> swapchain_;
    std::vector<VkImage> images_;
    std::vector<gpu::Image> wrapped_;
    std::vector<gpu::Unique<VkSemaphore>> presentReady_;
};

} // namespace glint::viewer
