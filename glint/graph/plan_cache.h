#pragma once

// Reusing compiled plans: a frame whose declaration has the shape of an
// earlier one gets that frame's Plan back instead of a compile.
//
//   rg::PlanCache cache;
//   each frame:
//     rg::Graph graph(caps);  ... passes ...
//     const rg::Plan& plan = cache.compile(graph, options);  // cached or compiled
//     executor.run(plan, resources);
//
// The shape is everything compile() reads of a declaration except resource
// and pass names and the execute callbacks: every pass's queue, pipeline,
// side effects and uses; every use (resource, version read, producer,
// access kinds, write, subresource range); every resource's kind, origin,
// description, cells, history partner and imports' boundary states;
// outputs, orderings, which cells start written; the device's QueueCaps and
// the options' aliasing switch. A cached shape is compared with the new
// declaration field by field, whole, so a hit means compile() would produce
// the same plan: the cached one, with this frame's declaration (names,
// callbacks) put in its place.
//
// The options' memoryRequirements must answer the same for the same
// description (the executor's, which asks the driver, does): its answers
// are not part of the shape. A cache serves one such source.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "glint/graph/compile.h"
#include "glint/graph/plan.h"

namespace glint::rg {

class Graph;

class PlanCache {
public:
    // Plans of up to `capacity` shapes are kept, the least recently used
    // dropped first (a renderer alternates between a few: the first frame,
    // a capture frame, a debug view).
    explicit PlanCache(uint32_t capacity = 4);

    // The plan of `graph` with graph.caps(): a cached plan of the same
    // shape given this declaration, else a fresh compile (kept for later).
    // The reference, and the declaration the plan holds, stay valid until
    // the next call or clear(); the plan of an earlier call no longer holds
    // its declaration (a cache keeps no old frame's callbacks alive).
    // Throws what compile() throws.
    const Plan& compile(const Graph& graph, const CompileOptions& options = {});

    uint64_t hits() const { return hits_; }
    uint64_t misses() const { return misses_; }
    uint32_t size() const { return uint32_t(entries_.size()); }
    void clear() {
        entries_.clear();
        answered_ = kNone;
    }

private:
    // The shape of a declaration (see the top of this file), as copied from
    // the one a cached plan was compiled from.
    struct PassShape {
        Queue queue;
        Pipeline pipeline;
        bool sideEffects;
        AccessSet kinds;
        uint32_t firstUse, useCount;
    };
    struct ResourceShape {
        ResourceKind kind;
        ir::Origin origin;
        uint8_t declarableAs;
        bool hasInitial, hasFinal, contentsAtStart;
        uint32_t cellBase, cellCount, partner;
        TextureDesc texture;
        BufferDesc buffer;
        BoundaryState initial, final;
    };
    struct Entry {
        QueueCaps caps;
        bool aliasing = true;
        uint32_t cellCount = 0;
        std::vector<PassShape> passes;
        std::vector<ir::Use> uses;
        std::vector<ResourceShape> resources;
        std::vector<ir::Output> outputs;
        std::vector<ir::Ordering> orderings;
        std::vector<uint8_t> written;
        Plan plan;  // holds a declaration only while it is the last call's answer
        uint64_t lastUse = 0;

        void copyShape(const ir::Declaration& d, const QueueCaps& c, const CompileOptions& options);
        bool sameShape(const ir::Declaration& d, const QueueCaps& c, const CompileOptions& options) const;
    };
    uint32_t capacity_;
    std::vector<Entry> entries_;
    static constexpr size_t kNone = SIZE_MAX;
    size_t answered_ = kNone;  // the entry whose plan the last call returned
    uint64_t hits_ = 0;
    uint64_t misses_ = 0;
    uint64_t calls_ = 0;
};

} // namespace glint::rg
