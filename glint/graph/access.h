#pragma once

// The access table: the one place that says which sync2 stages, access
// masks and image layout each kind of use means. Passes name what they do
// ("storage write", "ray query read"); barriers, layouts, usage flags and
// the verifier all derive from here.

#include <cstdint>
#include <string_view>

#include "glint/graph/types.h"

namespace glint::rg {

enum class Access : uint8_t {
    None = 0,    // boundary states only: nothing touched it, contents undefined
    SampledRead, // textures: sampled in a shader; buffers: read as a uniform buffer
    StorageRead,
    StorageWrite,
    StorageReadWrite,
    ColorAttachment, // raster passes on the graphics queue
    DepthWrite,      // depth test and write
    DepthRead,       // depth test without write
    IndirectArgs,    // draw/dispatch/trace indirect arguments (buffers)
    TransferSrc,
    TransferDst,
    AccelBuildInput, // buffers: vertex/index/instance input; structures: update source, BLAS under a TLAS
    AccelBuildWrite, // structures: build or update target; buffers: build scratch
    AccelRead,       // ray query (compute/raster) or trace rays (ray-tracing pipeline)
    Present,         // boundary states only: handed to the presentation engine (see kSemaphoreSignalStages)
    Count
};
inline constexpr uint32_t kAccessCount = static_cast<uint32_t>(Access::Count);

// The stage mask the executor signals semaphores with (its timelines and the
// caller's binary semaphores, FrameResources::signalSemaphore). The Present
// boundary state ends at these stages: presentation needs no access mask
// (vkQueuePresentKHR makes the image visible to the presentation engine),
// but the layout transition into PRESENT_SRC_KHR must be in the signal's
// first synchronisation scope, so the final barrier's destination stages
// must meet the signal's stage mask (a NONE destination leaves the
// transition outside it: a present-after-write hazard).
inline constexpr VkPipelineStageFlags2 kSemaphoreSignalStages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;

// Several read kinds of one subresource in one pass (depth test plus
// sampling the same depth) merge into one use; a set holds them.
using AccessSet = uint16_t;
constexpr AccessSet accessBit(Access a) { return static_cast<AccessSet>(1u << static_cast<uint32_t>(a)); }

// Stage, access mask and layout of a use (or a union of uses).
struct SyncScope {
    VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 access = VK_ACCESS_2_NONE;
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED; // textures only
};

// The state of an imported resource at a frame boundary: which use touched
// it last before the frame (initial) or will touch it first after it (final),
// on which queue. The plan synchronises against the initial state as work of
// the previous frame on that queue (a use on the other queue waits for that
// queue's last batch of the previous frame), and leaves the resource in the
// final state: every use of the frame either is described by it (same
// queue, within its stages and write access) or ordered before it. Work
// outside the plan that established the initial state must be finished or
// ordered by the caller (a host wait, an acquire semaphore). A state naming
// a queue that runs no pass in the plan stands for the other queue.
//
// Most states are an access kind. The escape hatch, raw(), takes explicit
// masks for states no kind names. A swapchain image goes from acquired() to
// of(Access::Present):
//   graph.importTexture("swapchain", {desc,
//       BoundaryState::acquired(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT),
//       BoundaryState::of(Access::Present)});
// with FrameResources::waitSemaphore / signalSemaphore naming the acquire
// and render-finished semaphores (graph/executor.h).
struct BoundaryState {
    Access access = Access::None;
    Queue queue = Queue::Graphics;
    Pipeline pipeline = Pipeline::Compute;
    bool isRaw = false;
    SyncScope rawScope;

    static constexpr BoundaryState of(Access a, Queue q = Queue::Graphics, Pipeline p = Pipeline::Compute) {
        return BoundaryState{a, q, p, false, {}};
    }
    static constexpr BoundaryState raw(VkPipelineStageFlags2 stages, VkAccessFlags2 access, VkImageLayout layout,
                                       Queue q = Queue::Graphics) {
        return BoundaryState{Access::None, q, Pipeline::Compute, true, SyncScope{stages, access, layout}};
    }
    // Made available by a semaphore the frame waits on at `waitStages` (a
    // swapchain image after vkAcquireNextImageKHR): contents undefined, and
    // the first barrier starts from `waitStages`, so its layout transition
    // is ordered after the wait. Name the stages of the image's first use.
    static constexpr BoundaryState acquired(VkPipelineStageFlags2 waitStages, Queue q = Queue::Graphics) {
        return raw(waitStages, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_UNDEFINED, q);
    }
    friend constexpr bool operator==(const BoundaryState& a, const BoundaryState& b) {
        if (a.isRaw != b.isRaw || a.queue != b.queue) return false;
        if (a.isRaw)
            return a.rawScope.stages == b.rawScope.stages && a.rawScope.access == b.rawScope.access &&
                   a.rawScope.layout == b.rawScope.layout;
        return a.access == b.access && a.pipeline == b.pipeline;
    }
};

// ---- Queries on the table -------------------------------------------------

std::string_view toString(Access);
std::string_view toString(Queue);
std::string_view toString(Pipeline);
std::string_view toString(ResourceKind);

namespace detail {
// The table's rules for declaring a use, inline: Builder checks every use.
struct AccessRules {
    uint8_t on = 0; // bit per ResourceKind it applies to
    bool needsContents = false;
    bool writes = false;
    bool boundaryOnly = false;
    bool needsRaster = false;
};
extern const AccessRules kAccessRules[kAccessCount];
} // namespace detail

// Whether a use needs the resource to hold data already (reading something
// nobody wrote is an error). Attachments and storage writes do not: a first
// use may clear.
inline bool accessNeedsContents(Access a) { return detail::kAccessRules[static_cast<uint32_t>(a)].needsContents; }
inline bool accessWrites(Access a) { return detail::kAccessRules[static_cast<uint32_t>(a)].writes; }
// Boundary-only kinds (None, Present) cannot be declared by passes.
inline bool accessIsBoundaryOnly(Access a) { return detail::kAccessRules[static_cast<uint32_t>(a)].boundaryOnly; }
inline bool accessAllowedOn(Access a, ResourceKind k) {
    return (detail::kAccessRules[static_cast<uint32_t>(a)].on & (1u << static_cast<uint32_t>(k))) != 0;
}
// Attachments need a raster pipeline.
inline bool accessNeedsRaster(Access a) { return detail::kAccessRules[static_cast<uint32_t>(a)].needsRaster; }
// What a queue can do: async compute queues have no raster pipeline and no
// attachments.
inline bool queueSupports(Queue q, Access a, Pipeline p) {
    return q == Queue::Graphics || (p != Pipeline::Raster && !accessNeedsRaster(a));
}

// Union over a set of kinds (they share one layout; Builder guarantees it).
SyncScope accessScope(AccessSet, ResourceKind, Pipeline);

namespace detail {
// accessScope() for every (kind, resource kind, pipeline), computed from
// the table at compile time: compile() asks for each use, so the lookup
// stays inline.
struct ScopeLut {
    SyncScope scope[kAccessCount][3][3];
};
extern ScopeLut kScopeLut;

// The barrier walk's own table derived from this one (barriers.cpp): one
// entry computed again after ScopeOverride changed it.
void refreshUseInfo(Access a, ResourceKind k, Pipeline p);

// Tests only: replaces one entry of the table compile() reads (stages,
// access mask, layout of one kind on one resource kind from one pipeline)
// until destroyed, to check that the verifier rejects the plans a wrong
// entry produces. Not thread-safe: nothing may compile meanwhile.
class ScopeOverride {
public:
    ScopeOverride(Access a, ResourceKind k, Pipeline p, const SyncScope& scope);
    ~ScopeOverride();
    ScopeOverride(const ScopeOverride&) = delete;
    ScopeOverride& operator=(const ScopeOverride&) = delete;

private:
    SyncScope& entry_;
    SyncScope saved_;
    Access access_;
    ResourceKind kind_;
    Pipeline pipeline_;
};
} // namespace detail

inline const SyncScope& scopeOf(Access a, ResourceKind k, Pipeline p) {
    return detail::kScopeLut.scope[static_cast<uint32_t>(a)][static_cast<uint32_t>(k)][static_cast<uint32_t>(p)];
}
// Stage/access/layout of one kind used on one resource kind from one
// pipeline. Layout is VK_IMAGE_LAYOUT_UNDEFINED for buffers and structures.
inline SyncScope accessScope(Access a, ResourceKind k, Pipeline p) { return scopeOf(a, k, p); }

// A boundary state in masks (raw states pass through). Inline: declaring
// an import and finishing the frame ask for every import's states.
inline SyncScope boundaryScope(const BoundaryState& b, ResourceKind k) {
    if (b.isRaw) {
        SyncScope s = b.rawScope;
        if (k != ResourceKind::Texture) s.layout = VK_IMAGE_LAYOUT_UNDEFINED;
        return s;
    }
    return scopeOf(b.access, k, b.pipeline);
}

namespace detail {
// Usage flags of every access set, computed from the table at compile time
// and split by byte (an AccessSet is 16 bits): the union of a set is two
// lookups. compile() asks for every resource, so the lookup stays inline.
struct UsageLut {
    VkImageUsageFlags image[2][256];
    VkBufferUsageFlags buffer[2][256];
};
extern const UsageLut kUsageLut;
} // namespace detail

inline VkImageUsageFlags imageUsageFor(AccessSet set) {
    return detail::kUsageLut.image[0][set & 0xffu] | detail::kUsageLut.image[1][set >> 8];
}
inline VkBufferUsageFlags bufferUsageFor(AccessSet set) {
    return detail::kUsageLut.buffer[0][set & 0xffu] | detail::kUsageLut.buffer[1][set >> 8];
}

// Write bits of an access mask (the part a later access must wait to see).
VkAccessFlags2 writeAccessBits(VkAccessFlags2);
bool hasWriteAccess(VkAccessFlags2);

} // namespace glint::rg
