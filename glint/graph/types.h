#pragma once

// Vocabulary of the render graph: queues, pipelines, resource descriptions,
// versioned handles and the device description compile() needs. Pure data;
// only Vulkan's enum and flag types are used, never a Vulkan call.

#include <cstdint>
#include <functional>
#include <limits>

#include <vulkan/vulkan_core.h>

namespace glint::rg {

inline constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();

// The queue a pass is declared for. AsyncCompute passes run on a separate
// compute family when the device has one and on the graphics queue otherwise,
// with the rest of the plan unchanged.
enum class Queue : uint8_t { Graphics = 0, AsyncCompute = 1 };
inline constexpr uint32_t kQueueCount = 2;

// Which shader stages a pass's shader accesses (sampled, storage, ray query)
// happen in. Raster covers the vertex and fragment stages together: the
// graph does not know which of the two touches a binding, so it synchronises
// both. Fixed-function accesses (attachments, indirect args, transfers,
// acceleration-structure builds) have their own stages whatever this says.
enum class Pipeline : uint8_t { Compute = 0, Raster = 1, RayTracing = 2 };

enum class ResourceKind : uint8_t { Texture = 0, Buffer = 1, AccelStruct = 2 };

// What compile() needs to know about the device. The executor fills it from
// gpu::Capabilities; tests write it by hand.
struct QueueCaps {
    bool separateComputeFamily = false; // an async compute family distinct from graphics
    uint32_t graphicsFamily = 0;
    uint32_t computeFamily = 0;      // equals graphicsFamily when not separate
    bool rayQuery = false;           // VK_KHR_ray_query
    bool rayTracingPipeline = false; // VK_KHR_ray_tracing_pipeline
    // VkPhysicalDeviceLimits::bufferImageGranularity. Transient buffers and
    // optimal images share heaps; placements are padded to this so the two
    // kinds never share a page. The default is the largest value in the wild.
    uint64_t bufferImageGranularity = 64 * 1024;
};

// A range of mips and array layers; kAll counts run to the end of the
// resource (like VK_REMAINING_MIP_LEVELS). Buffers and acceleration
// structures are always used whole.
struct Subresource {
    static constexpr uint32_t kAll = kNoIndex;
    uint32_t baseMip = 0;
    uint32_t mipCount = kAll;
    uint32_t baseLayer = 0;
    uint32_t layerCount = kAll;

    static constexpr Subresource mip(uint32_t m) { return {m, 1, 0, kAll}; }
    static constexpr Subresource layer(uint32_t l) { return {0, kAll, l, 1}; }
    friend constexpr bool operator==(const Subresource&, const Subresource&) = default;
};

struct TextureDesc {
    uint32_t width = 1;
    uint32_t height = 1;
    uint32_t depth = 1; // > 1 makes a 3D image (then layers must be 1)
    uint32_t layers = 1;
    uint32_t mips = 1;
    VkFormat format = VK_FORMAT_UNDEFINED;
    friend constexpr bool operator==(const TextureDesc&, const TextureDesc&) = default;
};

struct BufferDesc {
    uint64_t size = 0;
    friend constexpr bool operator==(const BufferDesc&, const BufferDesc&) = default;
};

// A versioned handle. Every write returns the next version; declaring a use
// of an older one is an error where it happens, not a GPU hang later. The
// graph id catches handles carried over from another graph (last frame's).
template <ResourceKind K>
struct Handle {
    static constexpr ResourceKind kind = K;
    uint32_t index = kNoIndex;
    uint32_t version = 0;
    uint32_t graph = 0;

    constexpr bool valid() const { return index != kNoIndex; }
    friend constexpr bool operator==(const Handle&, const Handle&) = default;
};

using Texture = Handle<ResourceKind::Texture>;
using Buffer = Handle<ResourceKind::Buffer>;
using AccelStruct = Handle<ResourceKind::AccelStruct>;

// History resources are ping-pong pairs: `previous` holds what `current`
// held at the end of last frame and may be read without anyone writing it
// this frame; `current` must be written before it is read.
struct HistoryTexture {
    Texture previous;
    Texture current;
};
struct HistoryBuffer {
    Buffer previous;
    Buffer current;
};

struct PassId {
    uint32_t index = kNoIndex;
    uint32_t graph = 0;
    constexpr bool valid() const { return index != kNoIndex; }
    friend constexpr bool operator==(const PassId&, const PassId&) = default;
};

// Implemented by the executor; a pass's execute callback records through it.
class PassContext;
using ExecuteFn = std::function<void(PassContext&)>;

} // namespace glint::rg
