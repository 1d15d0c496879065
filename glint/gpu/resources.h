#pragma once
// Buffers, images and samplers. A resource either owns its memory (the usual
// case) or is placed into a MemoryRange it does not own, which is how the
// render graph aliases transient resources.

#include "glint/gpu/handle.h"
#include "glint/gpu/memory.h"

#include <vulkan/vulkan.h>

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace glint::gpu {

class Context;

struct BufferDesc {
    VkDeviceSize size = 0;
    VkBufferUsageFlags usage = 0;  // SHADER_DEVICE_ADDRESS is always added
    MemoryUsage memory = MemoryUsage::DeviceLocal;
    std::string name;
    // Used by both the graphics and the async compute queue: created with
    // concurrent sharing over both families (no ownership transfers needed).
    // No effect on devices without a separate compute family.
    bool sharedAcrossQueues = false;
};

class Buffer {
public:
    Buffer() = default;
    // Allocates memory of its own.
    Buffer(Context& ctx, const BufferDesc& desc);
    // Binds to `memory` (owned elsewhere, possibly shared with other resources).
    Buffer(Context& ctx, const BufferDesc& desc, const MemoryRange& memory);
    Buffer(Buffer&&) noexcept = default;
    Buffer& operator=(Buffer&&) noexcept = default;

    // Size, alignment and memory types a buffer of `desc` needs.
    static VkMemoryRequirements requirements(Context& ctx, const BufferDesc& desc);

    VkBuffer handle() const { return buffer_.get(); }
    explicit operator bool() const { return static_cast<bool>(buffer_); }
    const BufferDesc& desc() const { return desc_; }
    VkDeviceSize size() const { return desc_.size; }
    VkDeviceAddress address() const { return address_; }
    // Host pointer of a host-visible buffer (Upload/Readback), else null.
    std::byte* mapped() const { return mapped_; }
    template <typename T> std::span<T> mappedSpan() const {
        return {reinterpret_cast<T*>(mapped_), mapped_ ? static_cast<size_t>(desc_.size / sizeof(T)) : 0};
    }

private:
    void create(Context& ctx, const MemoryRange* placed);

    BufferDesc desc_;
    Allocation allocation_;  // declared first: released after the buffer
    Unique<VkBuffer> buffer_;
    VkDeviceAddress address_ = 0;
    std::byte* mapped_ = nullptr;
};

struct ImageDesc {
    uint32_t width = 1;
    uint32_t height = 1;
    uint32_t depth = 1;
    uint32_t mips = 1;
    uint32_t layers = 1;
    VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
    VkImageUsageFlags usage = 0;
    std::string name;
    bool sharedAcrossQueues = false;  // as BufferDesc::sharedAcrossQueues
    // A 2D array view even of one layer (shaders declaring an array of a
    // runtime number of layers).
    bool arrayView = false;
};

class Image {
public:
    Image() = default;
    Image(Context& ctx, const ImageDesc& desc);
    Image(Context& ctx, const ImageDesc& desc, const MemoryRange& memory);
    Image(Image&&) noexcept = default;
    Image& operator=(Image&&) noexcept = default;

    static VkMemoryRequirements requirements(Context& ctx, const ImageDesc& desc);

    // A non-owning wrapper of an image created elsewhere (a swapchain image):
    // it owns the views it makes, never the image or its memory. `desc`
    // describes the image as created (usage decides whether a view is made);
    // the owner keeps the image alive while the wrapper is in use.
    static Image external(Context& ctx, VkImage image, const ImageDesc& desc);
    bool isExternal() const { return external_; }

    VkImage handle() const { return image_.get(); }
    explicit operator bool() const { return static_cast<bool>(image_); }
    // A view of every mip and layer (null for transfer-only images).
    VkImageView view() const { return view_.get(); }
    // A view of one mip (2D storage images with mips only; throws otherwise).
    VkImageView mipView(uint32_t mip) const;
    const ImageDesc& desc() const { return desc_; }
    VkFormat format() const { return desc_.format; }
    VkExtent3D extent() const { return {desc_.width, desc_.height, desc_.depth}; }
    VkImageAspectFlags aspect() const;
    VkImageSubresourceRange fullRange() const;

private:
    void create(Context& ctx, const MemoryRange* placed);
    void createViews(Context& ctx);

    ImageDesc desc_;
    bool external_ = false;
    Allocation allocation_;  // declared first: released after the image and view
    Unique<VkImage> image_;
    Unique<VkImageView> view_;
    std::vector<Unique<VkImageView>> mipViews_;
};

VkImageAspectFlags aspectOf(VkFormat format);
// Bytes per texel of the uncompressed formats Glint uses; throws otherwise.
uint32_t bytesPerTexel(VkFormat format);

struct SamplerDesc {
    VkFilter filter = VK_FILTER_LINEAR;
    VkSamplerMipmapMode mipmap = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    VkSamplerAddressMode address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    float maxLod = VK_LOD_CLAMP_NONE;
    std::string name;
    // V's (and W's) address mode where it differs from `address` (U's):
    // glTF samplers wrap S and T independently; an equirectangular image
    // repeats in u and clamps at the poles.
    std::optional<VkSamplerAddressMode> addressV;
};

class Sampler {
public:
    Sampler() = default;
    Sampler(Context& ctx, const SamplerDesc& desc);
    VkSampler handle() const { return sampler_.get(); }

private:
    Unique<VkSampler> sampler_;
};

} // namespace glint::gpu
