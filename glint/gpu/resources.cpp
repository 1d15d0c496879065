#include "glint/gpu/resources.h"

#include "glint/gpu/context.h"
#include "glint/gpu/error.h"

namespace glint::gpu {

namespace {

// The graphics and compute families, for concurrent sharing; empty when the
// resource stays on one queue family.
struct Sharing {
    uint32_t families[2] = {0, 0};
    uint32_t count = 0;
};

Sharing sharingFor(const Context& ctx, bool sharedAcrossQueues) {
    Sharing s;
    if (sharedAcrossQueues && ctx.caps().computeFamily) {
        s.families[0] = ctx.caps().graphicsFamily;
        s.families[1] = *ctx.caps().computeFamily;
        s.count = 2;
    }
    return s;
}

VkBufferCreateInfo bufferInfo(const BufferDesc& desc, const Sharing& sharing) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = desc.size;
    info.usage = desc.usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    info.sharingMode = sharing.count ? VK_SHARING_MODE_CONCURRENT : VK_SHARING_MODE_EXCLUSIVE;
    info.queueFamilyIndexCount = sharing.count;
    info.pQueueFamilyIndices = sharing.count ? sharing.families : nullptr;
    return info;
}

VkImageCreateInfo imageInfo(const ImageDesc& desc, const Sharing& sharing) {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = desc.depth > 1 ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
    info.format = desc.format;
    info.extent = {desc.width, desc.height, desc.depth};
    info.mipLevels = desc.mips;
    info.arrayLayers = desc.layers;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = desc.usage;
    info.sharingMode = sharing.count ? VK_SHARING_MODE_CONCURRENT : VK_SHARING_MODE_EXCLUSIVE;
    info.queueFamilyIndexCount = sharing.count;
    info.pQueueFamilyIndices = sharing.count ? sharing.families : nullptr;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    return info;
}

// The memory a new resource binds to: `placed` when given (checked against
// what the resource needs), else a fresh suballocation kept in `owned`.
MemoryRange memoryFor(Context& ctx, const VkMemoryRequirements& req, const MemoryRange* placed, MemoryUsage usage,
                      bool linear, const char* kind, const std::string& name, Allocation& owned) {
    if (!placed) {
        owned = ctx.memory().allocate(req, usage, linear, name);
        return owned.range();
    }
    if (placed->size < req.size || placed->offset % req.alignment != 0 ||
        !(req.memoryTypeBits & (1u << placed->memoryTypeIndex))) {
        throw GpuError(std::string(kind) + " '" + name + "': the memory range given cannot hold it (needs " +
                       std::to_string(req.size) + " bytes aligned to " + std::to_string(req.alignment) +
                       ", memory type mask " + std::to_string(req.memoryTypeBits) + ")");
    }
    return *placed;
}

} // namespace

// ---------------------------------------------------------------- Buffer

Buffer::Buffer(Context& ctx, const BufferDesc& desc) : desc_(desc) { create(ctx, nullptr); }

Buffer::Buffer(Context& ctx, const BufferDesc& desc, const MemoryRange& memory) : desc_(desc) {
    create(ctx, &memory);
}

VkMemoryRequirements Buffer::requirements(Context& ctx, const BufferDesc& desc) {
    const Sharing sharing = sharingFor(ctx, desc.sharedAcrossQueues);
    const VkBufferCreateInfo info = bufferInfo(desc, sharing);
    VkDeviceBufferMemoryRequirements query{VK_STRUCTURE_TYPE_DEVICE_BUFFER_MEMORY_REQUIREMENTS};
    query.pCreateInfo = &info;
    VkMemoryRequirements2 out{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    vkGetDeviceBufferMemoryRequirements(ctx.device(), &query, &out);
    return out.memoryRequirements;
}

void Buffer::create(Context& ctx, const MemoryRange* placed) {
    if (desc_.size == 0) {
        throw GpuError("buffer '" + desc_.name + "': size is zero");
    }
    const Sharing sharing = sharingFor(ctx, desc_.sharedAcrossQueues);
    const VkBufferCreateInfo info = bufferInfo(desc_, sharing);
    VkBuffer buffer = VK_NULL_HANDLE;
    check(vkCreateBuffer(ctx.device(), &info, nullptr, &buffer), "vkCreateBuffer '" + desc_.name + "'");
    buffer_ = Unique<VkBuffer>(ctx.device(), buffer, vkDestroyBuffer);

    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device(), buffer, &req);
    const MemoryRange range = memoryFor(ctx, req, placed, desc_.memory, /*linear=*/true, "buffer", desc_.name, allocation_);
    check(vkBindBufferMemory(ctx.device(), buffer, range.memory, range.offset), "vkBindBufferMemory '" + desc_.name + "'");
    mapped_ = range.mapped;
    VkBufferDeviceAddressInfo addressInfo{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    addressInfo.buffer = buffer;
    address_ = vkGetBufferDeviceAddress(ctx.device(), &addressInfo);
    ctx.setName(buffer, VK_OBJECT_TYPE_BUFFER, desc_.name);
}

// ---------------------------------------------------------------- Image

Image::Image(Context& ctx, const ImageDesc& desc) : desc_(desc) { create(ctx, nullptr); }

Image::Image(Context& ctx, const ImageDesc& desc, const MemoryRange& memory) : desc_(desc) { create(ctx, &memory); }

VkMemoryRequirements Image::requirements(Context& ctx, const ImageDesc& desc) {
    const Sharing sharing = sharingFor(ctx, desc.sharedAcrossQueues);
    const VkImageCreateInfo info = imageInfo(desc, sharing);
    VkDeviceImageMemoryRequirements query{VK_STRUCTURE_TYPE_DEVICE_IMAGE_MEMORY_REQUIREMENTS};
    query.pCreateInfo = &info;
    VkMemoryRequirements2 out{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    vkGetDeviceImageMemoryRequirements(ctx.device(), &query, &out);
    return out.memoryRequirements;
}

VkImageAspectFlags Image::aspect() const { return aspectOf(desc_.format); }

VkImageSubresourceRange Image::fullRange() const { return {aspect(), 0, desc_.mips, 0, desc_.layers}; }

void Image::create(Context& ctx, const MemoryRange* placed) {
    if (desc_.width == 0 || desc_.height == 0 || desc_.depth == 0 || desc_.mips == 0 || desc_.layers == 0) {
        throw GpuError("image '" + desc_.name + "': zero extent, mip count or layer count");
    }
    const Sharing sharing = sharingFor(ctx, desc_.sharedAcrossQueues);
    const VkImageCreateInfo info = imageInfo(desc_, sharing);
    VkImageFormatProperties formatProps;
    if (vkGetPhysicalDeviceImageFormatProperties(ctx.physicalDevice(), info.format, info.imageType, info.tiling,
                                                 info.usage, 0, &formatProps) != VK_SUCCESS) {
        throw GpuError("image '" + desc_.name + "': format " + std::to_string(desc_.format) +
                       " does not support the requested usage on this device");
    }
    VkImage image = VK_NULL_HANDLE;
    check(vkCreateImage(ctx.device(), &info, nullptr, &image), "vkCreateImage '" + desc_.name + "'");
    image_ = Unique<VkImage>(ctx.device(), image, vkDestroyImage);

    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(ctx.device(), image, &req);
    const MemoryRange range =
        memoryFor(ctx, req, placed, MemoryUsage::DeviceLocal, /*linear=*/false, "image", desc_.name, allocation_);
    check(vkBindImageMemory(ctx.device(), image, range.memory, range.offset), "vkBindImageMemory '" + desc_.name + "'");
    ctx.setName(image, VK_OBJECT_TYPE_IMAGE, desc_.name);
    createViews(ctx);
}

namespace {
// The deleter of an external image: its owner destroys it.
void keepExternalImage(VkDevice, VkImage, const VkAllocationCallbacks*) {}
} // namespace

Image Image::external(Context& ctx, VkImage image, const ImageDesc& desc) {
    if (image == VK_NULL_HANDLE) {
        throw GpuError("external image '" + desc.name + "': null VkImage");
    }
    if (desc.width == 0 || desc.height == 0 || desc.depth == 0 || desc.mips == 0 || desc.layers == 0) {
        throw GpuError("external image '" + desc.name + "': zero extent, mip count or layer count");
    }
    Image out;
    out.desc_ = desc;
    out.external_ = true;
    out.image_ = Unique<VkImage>(ctx.device(), image, keepExternalImage);
    out.createViews(ctx);
    return out;
}

void Image::createViews(Context& ctx) {
    const VkImage image = image_.get();
    // Transfer-only images (staging, readback targets) cannot have views.
    constexpr VkImageUsageFlags kViewUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                             VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                             VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
    if (!(desc_.usage & kViewUsage)) {
        return;
    }
    VkImageViewCreateInfo viewInfo{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    viewInfo.image = image;
    viewInfo.viewType = desc_.depth > 1   ? VK_IMAGE_VIEW_TYPE_3D
                        : desc_.layers > 1 || desc_.arrayView ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                           : VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = desc_.format;
    viewInfo.subresourceRange = fullRange();
    VkImageView view = VK_NULL_HANDLE;
    check(vkCreateImageView(ctx.device(), &viewInfo, nullptr, &view), "vkCreateImageView '" + desc_.name + "'");
    view_ = Unique<VkImageView>(ctx.device(), view, vkDestroyImageView);
    ctx.setName(view, VK_OBJECT_TYPE_IMAGE_VIEW, desc_.name);

    // A storage image with mips is written one level at a time (a storage
    // descriptor's view must hold exactly one mip): one view per level.
    if (desc_.mips > 1 && (desc_.usage & VK_IMAGE_USAGE_STORAGE_BIT) && desc_.depth == 1) {
        for (uint32_t m = 0; m < desc_.mips; ++m) {
            viewInfo.subresourceRange.baseMipLevel = m;
            viewInfo.subresourceRange.levelCount = 1;
            VkImageView mip = VK_NULL_HANDLE;
            const std::string name = desc_.name + ".mip" + std::to_string(m);
            check(vkCreateImageView(ctx.device(), &viewInfo, nullptr, &mip), "vkCreateImageView '" + name + "'");
            mipViews_.emplace_back(ctx.device(), mip, vkDestroyImageView);
            ctx.setName(mip, VK_OBJECT_TYPE_IMAGE_VIEW, name);
        }
    }
}

VkImageView Image::mipView(uint32_t mip) const {
    if (mip >= mipViews_.size()) {
        throw GpuError("image '" + desc_.name + "': no view of mip " + std::to_string(mip) +
                       " (per-mip views exist for 2D storage images with mips)");
    }
    return mipViews_[mip].get();
}

VkImageAspectFlags aspectOf(VkFormat format) {
    switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_X8_D24_UNORM_PACK32: return VK_IMAGE_ASPECT_DEPTH_BIT;
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    default: return VK_IMAGE_ASPECT_COLOR_BIT;
    }
}

uint32_t bytesPerTexel(VkFormat format) {
    switch (format) {
    case VK_FORMAT_R8_UNORM:
    case VK_FORMAT_R8_UINT: return 1;
    case VK_FORMAT_R8G8_UNORM:
    case VK_FORMAT_R16_SFLOAT:
    case VK_FORMAT_R16_UINT:
    case VK_FORMAT_D16_UNORM: return 2;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
    case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_D32_SFLOAT: return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32_UINT: return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_UINT: return 16;
    default: throw GpuError("bytesPerTexel: format " + std::to_string(format) + " is not one Glint reads back");
    }
}

// ---------------------------------------------------------------- Sampler

Sampler::Sampler(Context& ctx, const SamplerDesc& desc) {
    VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    info.magFilter = desc.filter;
    info.minFilter = desc.filter;
    info.mipmapMode = desc.mipmap;
    info.addressModeU = desc.address;
    info.addressModeV = info.addressModeW = desc.addressV.value_or(desc.address);
    info.maxLod = desc.maxLod;
    VkSampler sampler = VK_NULL_HANDLE;
    check(vkCreateSampler(ctx.device(), &info, nullptr, &sampler), "vkCreateSampler '" + desc.name + "'");
    sampler_ = Unique<VkSampler>(ctx.device(), sampler, vkDestroySampler);
    ctx.setName(sampler, VK_OBJECT_TYPE_SAMPLER, desc.name);
}

} // namespace glint::gpu
