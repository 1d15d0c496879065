#pragma once

// Reusing compiled plans: a frame whose declaration has the shape of an
// earlier one gets that frame's Plan back instead of a compile.
//
//   rg::PlanCache cache;
//   each frame:
//     rg::Graph graph(caps);  ... passes ...
//     const rg::Plan plan = cache.compile(graph, options);  // a copy of a cached plan, or compiled
//     executor.run(plan, resources);
//
// The key (structuralKey) is everything compile() reads of a declaration
// except resource and pass names and the execute callbacks: every pass's
// queue, pipeline and side effects; every use (resource, version read,
// producer, access kinds, write, subresource range); every resource's
// kind, origin, description, cells, history partner and imports' boundary
// states; outputs, orderings; the device's QueueCaps and the options'
// aliasing switch. Keys are compared whole, not by hash alone, so a hit
// means compile() would produce the same plan: a reused plan is the cached
// one with this frame's declaration (names, callbacks) put in its place.
//
// The options' memoryRequirements must answer the same for the same
// description (the executor's, which asks the driver, does): its answers
// are not part of the key. A cache serves one such source.

#include <cstdint>
#include <vector>

#include "glint/graph/compile.h"
#include "glint/graph/plan.h"

namespace glint::rg {

class Graph;

// The words compared; see the top of this file.
void structuralKey(const ir::Declaration& declaration, const QueueCaps& caps, const CompileOptions& options,
                   std::vector<uint64_t>& key);

class PlanCache {
public:
    // Plans of up to `capacity` shapes are kept, the least recently used
    // dropped first (a renderer alternates between a few: the first frame,
    // a capture frame, a debug view).
    explicit PlanCache(uint32_t capacity = 4);

    // The plan of `graph` with graph.caps(): a cached plan of the same key
    // rebound to this declaration, else a fresh compile (kept for later).
    // Throws what compile() throws.
    Plan compile(const Graph& graph, const CompileOptions& options = {});

    uint64_t hits() const { return hits_; }
    uint64_t misses() const { return misses_; }
    uint32_t size() const { return uint32_t(entries_.size()); }
    void clear() { entries_.clear(); }

private:
    struct Entry {
        std::vector<uint64_t> key;
        uint64_t hash = 0;
        Plan plan;  // without a declaration: a cached plan keeps no frame's callbacks alive
        uint64_t lastUse = 0;
    };
    uint32_t capacity_;
    std::vector<Entry> entries_;
    std::vector<uint64_t> key_;  // this call's, kept to reuse its storage
    uint64_t hits_ = 0;
    uint64_t misses_ = 0;
    uint64_t calls_ = 0;
};

} // namespace glint::rg
