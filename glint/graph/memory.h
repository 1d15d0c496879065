#pragma once

// Memory sizes of transient resources. The executor passes the driver's
// answers (vkGetDeviceImageMemoryRequirements and friends) through a
// MemoryRequirementsFn, called once per transient per compile -- worth
// caching by description, since a frame's graph repeats them every frame.
// Tests and the benchmark use the deterministic estimate below, which
// follows what desktop drivers report closely enough for aliasing decisions
// (64 KiB-aligned optimal images, 256-byte buffers). compile() asks the
// estimate, the format blocks and the aspects for every transient (every
// texture) of every frame: they are inline here, with block-compressed sizes
// and the errors out of line.

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <string_view>

#include "glint/graph/types.h"

namespace glint::rg {

struct MemoryRequirements {
    uint64_t size = 0;
    uint64_t alignment = 1;
    uint32_t memoryTypeBits = ~0u;
};

// What a transient will be created as; usage is derived from the uses that
// survived culling.
struct TransientDescription {
    std::string_view name;
    ResourceKind kind = ResourceKind::Texture;
    TextureDesc texture;
    BufferDesc buffer;
    VkImageUsageFlags imageUsage = 0;
    VkBufferUsageFlags bufferUsage = 0;
};

using MemoryRequirementsFn = std::function<MemoryRequirements(const TransientDescription&)>;

// Bytes per texel block and block extent; {0,0,0} for formats the estimate
// does not know.
struct FormatBlock {
    uint32_t bytes;
    uint32_t width;
    uint32_t height;
};

namespace detail {
// Every format the estimate knows is a core format: a table over those,
// indexed by VkFormat.
inline constexpr uint32_t kCoreFormatCount = VK_FORMAT_ASTC_12x12_SRGB_BLOCK + 1;
extern const std::array<FormatBlock, kCoreFormatCount> kCoreFormatBlocks;

// Optimal-tiling images are placed at 64 KiB granularity by the desktop
// drivers we target (NVIDIA, AMD, lavapipe report 4 KiB..64 KiB); the larger
// value keeps the estimate on the safe side of real placement.
inline constexpr uint64_t kImageAlignment = 64 * 1024;
// minStorageBufferOffsetAlignment and friends top out at 256 bytes.
inline constexpr uint64_t kBufferAlignment = 256;

uint64_t blockCompressedBytes(const TextureDesc& texture, FormatBlock block); // one layer, every mip
[[noreturn]] void notTransient();
[[noreturn]] void unknownFormat(const TransientDescription& description);
} // namespace detail

inline FormatBlock formatBlock(VkFormat format) {
    const auto index = static_cast<uint32_t>(format);
    return index < detail::kCoreFormatCount ? detail::kCoreFormatBlocks[index] : FormatBlock{0, 0, 0};
}

inline VkImageAspectFlags aspectOf(VkFormat format) {
    switch (format) {
        case VK_FORMAT_D16_UNORM:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
        case VK_FORMAT_D32_SFLOAT:
            return VK_IMAGE_ASPECT_DEPTH_BIT;
        case VK_FORMAT_S8_UINT:
            return VK_IMAGE_ASPECT_STENCIL_BIT;
        case VK_FORMAT_D16_UNORM_S8_UINT:
        case VK_FORMAT_D24_UNORM_S8_UINT:
        case VK_FORMAT_D32_SFLOAT_S8_UINT:
            return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
        default:
            return VK_IMAGE_ASPECT_COLOR_BIT;
    }
}

inline MemoryRequirements estimateMemoryRequirements(const TransientDescription& d) {
    using detail::kBufferAlignment, detail::kImageAlignment;
    if (d.kind == ResourceKind::Buffer)
        return {(d.buffer.size + kBufferAlignment - 1) / kBufferAlignment * kBufferAlignment, kBufferAlignment, ~0u};
    if (d.kind != ResourceKind::Texture) detail::notTransient();
    const TextureDesc& t = d.texture;
    const FormatBlock block = formatBlock(t.format);
    if (block.bytes == 0) detail::unknownFormat(d);
    uint64_t bytes = 0;
    if (block.width == 1 && block.height == 1) {
        // Uncompressed formats (nearly every transient): texels are blocks,
        // no rounding to block extents.
        uint64_t texels = 0;
        for (uint32_t m = 0; m < t.mips; ++m)
            texels += uint64_t{std::max(1u, t.width >> m)} * std::max(1u, t.height >> m) * std::max(1u, t.depth >> m);
        bytes = texels * block.bytes;
    } else {
        bytes = detail::blockCompressedBytes(t, block);
    }
    return {(bytes * t.layers + kImageAlignment - 1) / kImageAlignment * kImageAlignment, kImageAlignment, ~0u};
}

} // namespace glint::rg
