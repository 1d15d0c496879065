#pragma once

// The Executor's resource state, shared by executor.cpp (frames: recording,
// submission, timing; it creates and destroys the Executor) and
// executor_resources.cpp (transient heaps, history pairs, imports bound,
// and the memory-requirements cache behind compileOptions()). Not part of
// the interface: nothing outside glint/graph includes it.

#include "glint/graph/executor.h"

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

namespace glint::rg {

// Transient memory and the resources placed in it. `key` is everything that,
// if changed, means the placement must be redone.
struct Executor::Transients {
    using Key = std::vector<std::tuple<uint32_t, std::string, uint32_t, uint32_t, uint32_t, uint32_t, uint32_t,
                                       uint32_t, uint64_t, uint64_t, uint32_t, uint64_t, bool>>;
    Key key;
    std::vector<gpu::Allocation> heaps;
    std::vector<std::unique_ptr<gpu::Image>> images;
    std::vector<std::unique_ptr<gpu::Buffer>> buffers;
    std::map<uint32_t, Physical> byResource;
    uint64_t bytes = 0;
};

struct Executor::History {
    ResourceKind kind = ResourceKind::Texture;
    std::unique_ptr<gpu::Image> images[2];
    std::unique_ptr<gpu::Buffer> buffers[2];
    uint32_t current = 0;  // which of the two is this frame's `current`
    bool flippedThisFrame = false;
    // What the pair was made from, and the layout each image was left in
    // by the last frame that used it: a later plan may expect others.
    TextureDesc texture;
    BufferDesc buffer;
    VkImageUsageFlags imageUsage = 0;
    VkBufferUsageFlags bufferUsage = 0;
    bool shared = false;
    VkImageLayout layout[2] = {VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_UNDEFINED};
    // The uses of both halves in the last plan (queue, access kinds, writes,
    // in plan order): barriers at a frame's start assume the previous frame
    // ended the way this plan ends, so another plan needs a full barrier.
    uint64_t useSignature = 0;
};

// The driver's memory requirements by transient description. Asking is a
// driver call (and a name copied into the description it takes) per
// transient per compile; the descriptions repeat frame after frame. Locked:
// plans may be compiled on several threads with one executor's options.
struct Executor::RequirementsCache {
    struct Key {
        ResourceKind kind;
        TextureDesc texture;      // textures only
        uint64_t bufferSize;      // buffers only
        VkFlags usage;            // image or buffer usage
        friend bool operator==(const Key&, const Key&) = default;
    };
    struct Hash {
        size_t operator()(const Key& k) const noexcept {
            uint64_t h = uint64_t(k.kind) * 0x9E3779B97F4A7C15ull;
            for (const uint64_t v : {uint64_t(k.texture.width) << 32 | k.texture.height,
                                     uint64_t(k.texture.depth) << 32 | k.texture.layers,
                                     uint64_t(k.texture.mips) << 32 | uint32_t(k.texture.format), k.bufferSize,
                                     uint64_t(k.usage)})
                h = (h ^ v) * 0x100000001B3ull + (h >> 29);
            return size_t(h);
        }
    };
    std::mutex mutex;
    std::unordered_map<Key, MemoryRequirements, Hash> answers;
};

}  // namespace glint::rg
