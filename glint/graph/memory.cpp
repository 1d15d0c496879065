#include "glint/graph/memory.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace glint::rg {
namespace {

constexpr FormatBlock blockOf(VkFormat f) {
    switch (f) {
        case VK_FORMAT_R8_UNORM:
        case VK_FORMAT_R8_SNORM:
        case VK_FORMAT_R8_UINT:
        case VK_FORMAT_R8_SINT:
        case VK_FORMAT_S8_UINT:
            return {1, 1, 1};
        case VK_FORMAT_R8G8_UNORM:
        case VK_FORMAT_R8G8_SNORM:
        case VK_FORMAT_R8G8_UINT:
        case VK_FORMAT_R16_SFLOAT:
        case VK_FORMAT_R16_UNORM:
        case VK_FORMAT_R16_UINT:
        case VK_FORMAT_R16_SINT:
        case VK_FORMAT_D16_UNORM:
        case VK_FORMAT_R5G6B5_UNORM_PACK16:
            return {2, 1, 1};
        case VK_FORMAT_D16_UNORM_S8_UINT:
            return {4, 1, 1}; // drivers pad to 32 bits
        case VK_FORMAT_R8G8B8A8_UNORM:
        case VK_FORMAT_R8G8B8A8_SNORM:
        case VK_FORMAT_R8G8B8A8_UINT:
        case VK_FORMAT_R8G8B8A8_SRGB:
        case VK_FORMAT_B8G8R8A8_UNORM:
        case VK_FORMAT_B8G8R8A8_SRGB:
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
        case VK_FORMAT_A2R10G10B10_UNORM_PACK32:
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
        case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32:
        case VK_FORMAT_R16G16_SFLOAT:
        case VK_FORMAT_R16G16_UNORM:
        case VK_FORMAT_R16G16_SNORM:
        case VK_FORMAT_R16G16_UINT:
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_R32_UINT:
        case VK_FORMAT_R32_SINT:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
        case VK_FORMAT_D24_UNORM_S8_UINT:
            return {4, 1, 1};
        case VK_FORMAT_D32_SFLOAT_S8_UINT:
            return {8, 1, 1}; // separate stencil plane, padded
        case VK_FORMAT_R16G16B16A16_SFLOAT:
        case VK_FORMAT_R16G16B16A16_UNORM:
        case VK_FORMAT_R16G16B16A16_SNORM:
        case VK_FORMAT_R16G16B16A16_UINT:
        case VK_FORMAT_R32G32_SFLOAT:
        case VK_FORMAT_R32G32_UINT:
            return {8, 1, 1};
        case VK_FORMAT_R32G32B32A32_SFLOAT:
        case VK_FORMAT_R32G32B32A32_UINT:
        case VK_FORMAT_R32G32B32A32_SINT:
            return {16, 1, 1};
        case VK_FORMAT_BC1_RGB_UNORM_BLOCK:
        case VK_FORMAT_BC1_RGB_SRGB_BLOCK:
        case VK_FORMAT_BC1_RGBA_UNORM_BLOCK:
        case VK_FORMAT_BC1_RGBA_SRGB_BLOCK:
        case VK_FORMAT_BC4_UNORM_BLOCK:
        case VK_FORMAT_BC4_SNORM_BLOCK:
            return {8, 4, 4};
        case VK_FORMAT_BC2_UNORM_BLOCK:
        case VK_FORMAT_BC2_SRGB_BLOCK:
        case VK_FORMAT_BC3_UNORM_BLOCK:
        case VK_FORMAT_BC3_SRGB_BLOCK:
        case VK_FORMAT_BC5_UNORM_BLOCK:
        case VK_FORMAT_BC5_SNORM_BLOCK:
        case VK_FORMAT_BC6H_UFLOAT_BLOCK:
        case VK_FORMAT_BC6H_SFLOAT_BLOCK:
        case VK_FORMAT_BC7_UNORM_BLOCK:
        case VK_FORMAT_BC7_SRGB_BLOCK:
            return {16, 4, 4};
        default:
            return {0, 0, 0};
    }
}

} // namespace

// The switch as a table, for formatBlock.
constinit const std::array<FormatBlock, detail::kCoreFormatCount> detail::kCoreFormatBlocks = [] {
    std::array<FormatBlock, kCoreFormatCount> table{};
    for (uint32_t f = 0; f < kCoreFormatCount; ++f) table[f] = blockOf(static_cast<VkFormat>(f));
    return table;
}();

uint64_t detail::blockCompressedBytes(const TextureDesc& t, FormatBlock block) {
    uint64_t bytes = 0;
    for (uint32_t m = 0; m < t.mips; ++m) {
        const uint64_t w = std::max(1u, t.width >> m), h = std::max(1u, t.height >> m), z = std::max(1u, t.depth >> m);
        bytes += (w + block.width - 1) / block.width * ((h + block.height - 1) / block.height) * z * block.bytes;
    }
    return bytes;
}

void detail::notTransient() {
    throw std::invalid_argument("estimateMemoryRequirements: only textures and buffers are transient");
}

void detail::unknownFormat(const TransientDescription& d) {
    throw std::invalid_argument("estimateMemoryRequirements: no size known for format " +
                                std::to_string(static_cast<int>(d.texture.format)) + " of '" + std::string(d.name) +
                                "'; pass a MemoryRequirementsFn");
}

} // namespace glint::rg
