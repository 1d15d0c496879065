#include "swapchain.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>

namespace glint::viewer {

namespace {

// The UNORM variant of an 8-bit colour format, or UNDEFINED for anything else.
VkFormat unormOf(VkFormat format) {
    switch (format) {
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB: return VK_FORMAT_B8G8R8A8_UNORM;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB: return VK_FORMAT_R8G8B8A8_UNORM;
    default: return VK_FORMAT_UNDEFINED;
    }
}

constexpr VkImageUsageFlags kImageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;

} // namespace

Swapchain::Swapchain(gpu::Context& ctx, VkSurfaceKHR surface, VkExtent2D wanted) : ctx_(ctx), surface_(surface) {
    VkBool32 supported = VK_FALSE;
    gpu::check(vkGetPhysicalDeviceSurfaceSupportKHR(ctx_.physicalDevice(), ctx_.caps().graphicsFamily, surface_,
                                                    &supported),
               "vkGetPhysicalDeviceSurfaceSupportKHR");
    if (!supported) {
        throw gpu::GpuError("the graphics queue of '" + ctx_.caps().deviceName +
                            "' cannot present to this window (the viewer presents from the queue it renders on)");
    }
    uint32_t count = 0;
    gpu::check(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physicalDevice(), surface_, &count, nullptr),
               "vkGetPhysicalDeviceSurfaceFormatsKHR");
    std::vector<VkSurfaceFormatKHR> formats(count);
    gpu::check(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physicalDevice(), surface_, &count, formats.data()),
               "vkGetPhysicalDeviceSurfaceFormatsKHR");
    // UNORM first (what the bytes are), then SRGB (the same bytes, read as
    // encoded); both in the sRGB colour space. Chosen once: ImGui's
    // pipeline is built for this format.
    for (const bool wantUnorm : {true, false}) {
        for (const VkSurfaceFormatKHR& f : formats) {
            const VkFormat unorm = unormOf(f.format);
            if (unorm == VK_FORMAT_UNDEFINED || f.colorSpace != VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) continue;
            if ((unorm == f.format) != wantUnorm) continue;
            format_ = f.format;
            copyFormat_ = unorm;
            colorSpace_ = f.colorSpace;
            break;
        }
        if (format_ != VK_FORMAT_UNDEFINED) break;
    }
    if (format_ == VK_FORMAT_UNDEFINED) {
        throw gpu::GpuError("the window's surface offers no 8-bit BGRA/RGBA format in the sRGB colour space");
    }
    create(wanted);
}

Swapchain::~Swapchain() = default;

void Swapchain::recreate(VkExtent2D wanted) { create(wanted); }

void Swapchain::create(VkExtent2D wanted) {
    VkSurfaceCapabilitiesKHR caps;
    gpu::check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physicalDevice(), surface_, &caps),
               "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    // Colour attachment use is always supported; the blit (or the compose
    // copy) writes them as a transfer destination.
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
        throw gpu::GpuError(
            "the window's swapchain images cannot be transfer destinations (the viewer blits into them)");
    }
    // The surface's size where it has one; otherwise ours, within its limits.
    if (caps.currentExtent.width != std::numeric_limits<uint32_t>::max()) {
        extent_ = caps.currentExtent;
    } else {
        extent_.width = std::clamp(wanted.width, caps.minImageExtent.width, caps.maxImageExtent.width);
        extent_.height = std::clamp(wanted.height, caps.minImageExtent.height, caps.maxImageExtent.height);
    }
    // One more than the minimum so acquiring rarely waits for the display.
    minImageCount_ = std::max(caps.minImageCount + 1, 2u);
    if (caps.maxImageCount != 0) minImageCount_ = std::min(minImageCount_, caps.maxImageCount);

    VkCompositeAlphaFlagBitsKHR alpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    if (!(caps.supportedCompositeAlpha & alpha)) {
        for (const auto a : {VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR, VK_COMPOSITE_ALPHA_PRE_MULTIPLIED_BIT_KHR,
                             VK_COMPOSITE_ALPHA_POST_MULTIPLIED_BIT_KHR}) {
            if (caps.supportedCompositeAlpha & a) {
                alpha = a;
                break;
            }
        }
    }

    VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    info.surface = surface_;
    info.minImageCount = minImageCount_;
    info.imageFormat = format_;
    info.imageColorSpace = colorSpace_;
    info.imageExtent = extent_;
    info.imageArrayLayers = 1;
    info.imageUsage = kImageUsage;
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = alpha;
    // FIFO: the one mode every surface has; paces the loop to the display.
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;
    info.clipped = VK_TRUE;
    info.oldSwapchain = swapchain_.get();
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    gpu::check(vkCreateSwapchainKHR(ctx_.device(), &info, nullptr, &swapchain), "vkCreateSwapchainKHR");
    // Replacing the old one destroys it (the device is idle); its images'
    // wrappers (their views) go first.
    wrapped_.clear();
    swapchain_ = gpu::Unique<VkSwapchainKHR>(ctx_.device(), swapchain, vkDestroySwapchainKHR);

    uint32_t count = 0;
    gpu::check(vkGetSwapchainImagesKHR(ctx_.device(), swapchain, &count, nullptr), "vkGetSwapchainImagesKHR");
    images_.resize(count);
    gpu::check(vkGetSwapchainImagesKHR(ctx_.device(), swapchain, &count, images_.data()), "vkGetSwapchainImagesKHR");

    presentReady_.clear();
    for (uint32_t i = 0; i < count; ++i) {
        wrapped_.push_back(gpu::Image::external(
            ctx_, images_[i],
            gpu::ImageDesc{extent_.width, extent_.height, 1, 1, 1, format_, kImageUsage,
                           "viewer.swapchain" + std::to_string(i), false}));
        VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
        VkSemaphore semaphore = VK_NULL_HANDLE;
        gpu::check(vkCreateSemaphore(ctx_.device(), &semaphoreInfo, nullptr, &semaphore), "vkCreateSemaphore");
        presentReady_.emplace_back(ctx_.device(), semaphore, vkDestroySemaphore);
        ctx_.setName(semaphore, VK_OBJECT_TYPE_SEMAPHORE, "viewer.present_ready" + std::to_string(i));
    }
    spdlog::info("swapchain: {}x{}, {} images, format {}", extent_.width, extent_.height, count, int(format_));
}

std::optional<uint32_t> Swapchain::acquire(VkSemaphore signal) {
    uint32_t index = 0;
    const VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_.get(), std::numeric_limits<uint64_t>::max(),
                                             signal, VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) return std::nullopt;
    // Suboptimal still signals `signal` and gives an image: use it, and let
    // present() report the swapchain for recreation.
    if (r != VK_SUBOPTIMAL_KHR) gpu::check(r, "vkAcquireNextImageKHR");
    return index;
}

bool Swapchain::present(uint32_t index) {
    const VkSemaphore wait = presentReady(index);
    const VkSwapchainKHR swapchain = swapchain_.get();
    VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    info.waitSemaphoreCount = 1;
    info.pWaitSemaphores = &wait;
    info.swapchainCount = 1;
    info.pSwapchains = &swapchain;
    info.pImageIndices = &index;
    const VkResult r = vkQueuePresentKHR(ctx_.graphicsQueue().queue, &info);
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return false;
    gpu::check(r, "vkQueuePresentKHR");
    return true;
}

} // namespace glint::viewer
