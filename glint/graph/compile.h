#pragma once

// compile(): declared graph + device description -> Plan. Pure: no Vulkan
// calls, and the same input gives the same Plan (each thread keeps the
// barrier walk's working memory between calls; nothing else persists).
//
// Phases, one file each:
//   cull.cpp      passes nothing needs go; usage is derived from survivors
//   schedule.cpp  a stable order (declaration order unless order() says
//                 otherwise), then queue assignment
//   lifetimes.cpp first/last use, queues and usage flags per resource
//   alias.cpp     transient placement in per-queue heaps
//   barriers.cpp  hazards -> sync2 barriers and cross-queue waits (where
//                 resources start the frame: barrier_frame_start.cpp)
//   batches.cpp   per-queue submission batches and semaphore placement

#include "glint/graph/memory.h"
#include "glint/graph/plan.h"
#include "glint/graph/types.h"

namespace glint::rg {

class Graph;

struct CompileOptions {
    // Sizes of transients; estimateMemoryRequirements when empty.
    MemoryRequirementsFn memoryRequirements;
    // Off: every transient gets its own bytes (for measuring the saving and
    // for bisecting aliasing bugs).
    bool aliasing = true;
};

// `recycled` lends its vectors' storage to the new Plan: a frame loop that
// writes `plan = compile(graph, caps, options, std::move(plan))` stops
// allocating (and first-touching) a Plan's worth of memory every frame.
// Its contents are discarded.
Plan compile(const Graph& graph, const QueueCaps& caps, const CompileOptions& options = {}, Plan&& recycled = {});

} // namespace glint::rg
