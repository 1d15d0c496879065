#pragma once

// Memory sizes of transient resources. The executor passes the driver's
// answers (vkGetDeviceImageMemoryRequirements and friends) through a
// MemoryRequirementsFn, called once per transient per compile -- worth
// caching by description, since a frame's graph repeats them every frame.
// Tests and the benchmark use the deterministic estimate below, which
// follows what desktop drivers report closely enough for aliasing decisions
// (64 KiB-aligned optimal images, 256-byte buffers).

#include <cstdint>
#include <functional>
#include <string_view>

#include "graph/types.h"

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

MemoryRequirements estimateMemoryRequirements(const TransientDescription& description);

// Bytes per texel block and block extent; {0,0,0} for formats the estimate
// does not know.
struct FormatBlock {
    uint32_t bytes;
    uint32_t width;
    uint32_t height;
};
FormatBlock formatBlock(VkFormat format);
VkImageAspectFlags aspectOf(VkFormat format);

} // namespace glint::rg
