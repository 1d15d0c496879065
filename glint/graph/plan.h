#pragma once

// The compiled frame: a plain value the executor walks and tests assert on.
//
// Executing a Plan, frame after frame:
//   for each batch in `batches` (submission order):
//     wait  : for w in waitsOf(batch): the timeline semaphore of w.queue at
//             waitValue(frame, w), in stage mask w.stages (skip when nullopt:
//             the first frame has no previous one, or the queue has no
//             batch to wait for)
//     record: for p in passesOf(batch): barriersBefore(p) as one
//             vkCmdPipelineBarrier2, then timestamp p.timestampQuery, the
//             pass's execute callback (none where p.skipped), timestamp
//             p.timestampQuery + 1; then barriersAfter(batch) as one
//             vkCmdPipelineBarrier2
//     signal: the timeline semaphore of batch.queue at
//             signalValue(frame, batch), stage ALL_COMMANDS
// One timeline semaphore per queue; every batch signals. History pairs swap
// their images every frame. Transient memory keeps its placement across
// frames: the plan's first barriers of a frame synchronise with the last
// uses of the same memory in the previous frame, so the memory must not be
// recycled by anyone else while frames are in flight.
//
// Lowering a Barrier: textures -> VkImageMemoryBarrier2 (range, aspect,
// layouts, VK_QUEUE_FAMILY_IGNORED); buffers -> VkBufferMemoryBarrier2 over
// the whole buffer; acceleration structures -> VkMemoryBarrier2. A barrier
// with `aliasing` set also goes out as a VkMemoryBarrier2 with the same
// masks: its source accesses were made through another resource bound to
// the same memory, outside the image/buffer barrier's own scope.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "glint/graph/ir.h"
#include "glint/graph/types.h"

namespace glint::rg {

struct Barrier {
    uint32_t resource = kNoIndex;  // declaration index
    Subresource range;             // textures: resolved mips/layers; others: {0,1,0,1}
    VkImageAspectFlags aspect = 0; // textures only
    VkPipelineStageFlags2 srcStages = 0;
    VkAccessFlags2 srcAccess = 0;
    VkPipelineStageFlags2 dstStages = 0;
    VkAccessFlags2 dstAccess = 0;
    VkImageLayout oldLayout = VK_IMAGE_LAYOUT_UNDEFINED; // UNDEFINED also when contents are discarded
    VkImageLayout newLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    bool aliasing = false;
};

// A batch waits on another queue's timeline: `queue` is the signalling
// queue, `batch` its batch ordinal, `frameOffset` 0 for this frame or -1 for
// the previous one (the write-after-read edge from a frame's graphics reads
// to the next frame's async work, and cross-frame reuse of memory).
struct SemaphoreWait {
    // With frameOffset -1: whatever `queue` signalled last before this
    // frame. An import whose initial state is on a queue that has no batch
    // in the plan waits so (its last access was before this plan ran).
    static constexpr uint32_t kLastSignalled = UINT32_MAX;

    Queue queue = Queue::Graphics;
    uint32_t batch = 0;
    int32_t frameOffset = 0;
    VkPipelineStageFlags2 stages = 0;
};

struct PlannedPass {
    uint32_t pass = kNoIndex;      // declaration index (name, uses, execute callback)
    Queue queue = Queue::Graphics; // assigned queue
    uint32_t batch = 0;            // index into Plan::batches
    uint32_t firstBarrier = 0;     // barriersBefore(): [firstBarrier, +barrierCount) of Plan::barriers
    uint32_t barrierCount = 0;
    uint32_t timestampQuery = 0; // begin query; end is +1
    // Runs no execute callback this frame: set by skipPasses() (skip.h) for
    // the passes Builder::skip() named, whose barriers it has carried on;
    // compile() never sets it.
    bool skipped = false;
};

struct Batch {
    Queue queue = Queue::Graphics;
    uint32_t ordinal = 0;   // position among this queue's batches; fixes its timeline values
    uint32_t firstPass = 0; // [firstPass, +passCount) of Plan::passes
    uint32_t passCount = 0;
    uint32_t firstWait = 0; // [firstWait, +waitCount) of Plan::waits
    uint32_t waitCount = 0;
    uint32_t firstEndBarrier = 0; // barriers after the last pass (imports' final states)
    uint32_t endBarrierCount = 0;
};

struct PlannedResource {
    ResourceKind kind = ResourceKind::Texture;
    ir::Origin origin = ir::Origin::Transient;
    bool used = false;                // touched by a pass that survived culling
    bool crossQueue = false;          // used on both queues: VK_SHARING_MODE_CONCURRENT over both families
    Queue queue = Queue::Graphics;    // queue of its first use
    VkImageUsageFlags imageUsage = 0; // derived after culling; history pairs carry the union of both halves
    VkBufferUsageFlags bufferUsage = 0;
    VkImageAspectFlags aspect = 0;
    uint32_t firstPass = kNoIndex; // planned-pass indices of the first and last use (schedule order)
    uint32_t lastPass = kNoIndex;
    // Transients: placement in a heap.
    uint32_t heap = kNoIndex;
    uint64_t offset = 0;
    uint64_t size = 0;
    uint64_t alignment = 0;
    // History halves: the layout this half starts frame 0 in. The executor
    // creates both images, clears them and moves each into its half's layout
    // before the first frame.
    VkImageLayout entryLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    uint32_t partner = kNoIndex;
};

// One block of device memory transients are placed in. Heaps never mix
// queues (no aliasing across queues inside a frame) nor memory types;
// buffers and images share them, padded to bufferImageGranularity.
struct MemoryHeap {
    Queue queue = Queue::Graphics;
    bool crossQueue = false; // holds resources used on both queues; never aliased
    bool images = false;     // holds at least one optimal-tiling image
    bool buffers = false;    // holds at least one buffer
    uint32_t memoryTypeBits = ~0u;
    uint64_t size = 0;
    uint64_t alignment = 1;
};

struct PlanStats {
    uint32_t declaredPasses = 0;
    uint32_t culledPasses = 0;
    uint64_t transientBytes = 0;        // every transient in its own allocation
    uint64_t aliasedTransientBytes = 0; // sum of heap sizes
};

struct Plan {
    QueueCaps caps;
    std::shared_ptr<const ir::Declaration> declaration;
    std::vector<PlannedPass> passes; // submission order: batch by batch
    std::vector<Batch> batches;      // submission order
    std::vector<Barrier> barriers;
    std::vector<SemaphoreWait> waits;
    std::vector<PlannedResource> resources; // indexed like the declaration's resources
    std::vector<MemoryHeap> heaps;
    std::vector<uint32_t> culled; // declaration indices of passes nothing needed
    PlanStats stats;

    std::span<const PlannedPass> passesOf(const Batch& b) const { return {passes.data() + b.firstPass, b.passCount}; }
    std::span<const SemaphoreWait> waitsOf(const Batch& b) const { return {waits.data() + b.firstWait, b.waitCount}; }
    std::span<const Barrier> barriersBefore(const PlannedPass& p) const {
        return {barriers.data() + p.firstBarrier, p.barrierCount};
    }
    std::span<const Barrier> barriersAfter(const Batch& b) const {
        return {barriers.data() + b.firstEndBarrier, b.endBarrierCount};
    }

    // Views into the declaration, which the plan keeps alive.
    std::string_view passName(const PlannedPass& p) const { return declaration->passes[p.pass].name; }
    std::string_view resourceName(uint32_t resource) const { return declaration->resources[resource].name; }
    const ExecuteFn& execute(const PlannedPass& p) const { return declaration->passes[p.pass].execute; }
    std::span<const ir::Use> uses(const PlannedPass& p) const;
    Pipeline pipeline(const PlannedPass& p) const { return declaration->passes[p.pass].pipeline; }

    uint32_t batchCount(Queue q) const;
    // vkCmdPipelineBarrier2 calls a frame records: every non-empty group
    // (before a pass, at a batch's end).
    uint32_t barrierCallCount() const;
    uint32_t family(Queue q) const;
    uint32_t timestampQueryCount() const { return static_cast<uint32_t>(passes.size()) * 2; }

    // Timeline values: batch `ordinal` of a queue with n batches per frame
    // signals frame * n + ordinal + 1, so values rise across frames and 0 is
    // the semaphore's initial value.
    uint64_t signalValue(uint64_t frame, const Batch& b) const;
    std::optional<uint64_t> waitValue(uint64_t frame, const SemaphoreWait& w) const;

    // Where a caller's semaphores for an import go (FrameResources::
    // waitSemaphore / signalSemaphore, e.g. a swapchain image's acquire and
    // render-finished): the batch of its first use in submission order, with
    // the stages to wait at (that use's, plus the initial state's, where the
    // import's first barrier starts); and the batch that leaves it in its
    // final state (records its final barrier, else holds its last use).
    // Batch kNoIndex: no pass uses it (and no barrier touches it).
    struct WaitPoint {
        uint32_t batch = kNoIndex;
        VkPipelineStageFlags2 stages = 0;
    };
    WaitPoint firstUseOf(uint32_t resource) const;
    uint32_t batchEnding(uint32_t resource) const;

    // Lookup by name, for tests and tools; nullptr when absent or culled.
    const PlannedPass* findPass(std::string_view name) const;
    uint32_t findResource(std::string_view name) const; // kNoIndex when absent

    std::string toText() const;
    std::string toDot() const;
    std::string toJson() const;
};

} // namespace glint::rg
