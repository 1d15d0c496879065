#pragma once
// The viewer's "render graph" panel, without ImGui: the compiled plan of the
// frame on screen as rows to draw. Per queue, the passes in submission order
// with their batch, barriers, cross-queue waits and GPU time; the resources
// each pass uses; the transient heaps with each placement and what shares
// its bytes (aliasing). Plan::toDot() writes the same plan as a Graphviz
// graph.

#include "glint/graph/executor.h"
#include "glint/graph/plan.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace glint::viewer {

struct PlanViewUse {
    std::string resource;
    std::string access;  // the access kinds, "+"-joined
    bool writes = false;
};

struct PlanViewWait {
    rg::Queue queue = rg::Queue::Graphics;  // the queue waited for
    uint32_t batch = 0;                     // its batch ordinal (kLastSignalled: whatever it signalled last)
    bool previousFrame = false;
};

struct PlanViewBarrier {
    std::string resource;
    VkPipelineStageFlags2 srcStages = 0, dstStages = 0;
    VkAccessFlags2 srcAccess = 0, dstAccess = 0;
    VkImageLayout oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, newLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    bool aliasing = false;  // its source accesses were made through another resource in the same bytes
};

struct PlanViewPass {
    std::string name;
    uint32_t batch = 0;                 // Plan::batches index
    bool batchStart = false;            // the first pass of its batch: the batch's waits go before it
    std::vector<PlanViewWait> waits;    // the batch's, on its first pass
    uint32_t barriers = 0;              // recorded before the pass
    std::vector<PlanViewBarrier> barrierList;  // the same, one by one
    std::optional<double> milliseconds;  // the newest timing of a pass of this name
    std::vector<PlanViewUse> uses;
};

struct PlanViewPlacement {
    std::string resource;
    uint64_t offset = 0;
    uint64_t size = 0;
    uint32_t firstPass = 0;  // planned-pass indices (submission order)
    uint32_t lastPass = 0;
    std::vector<std::string> aliases;  // transients sharing some of its bytes at other times
};

struct PlanViewHeap {
    rg::Queue queue = rg::Queue::Graphics;
    uint64_t size = 0;
    std::vector<PlanViewPlacement> placements;  // by offset
};

struct PlanView {
    std::vector<PlanViewPass> lanes[2];  // by rg::Queue: graphics, async compute
    std::vector<PlanViewHeap> heaps;
    uint64_t transientBytes = 0;  // every transient in its own memory
    uint64_t aliasedBytes = 0;    // the heaps
    uint32_t culled = 0;
};

// `timings`: the executor's newest per-pass times (matched by name).
PlanView planView(const rg::Plan& plan, std::span<const rg::PassTiming> timings = {});

} // namespace glint::viewer
