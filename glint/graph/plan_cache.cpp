#include "glint/graph/plan_cache.h"

#include <algorithm>

#include "glint/graph/graph.h"

namespace glint::rg {

void PlanCache::Entry::copyShape(const ir::Declaration& d, const QueueCaps& c, const CompileOptions& options) {
    caps = c;
    aliasing = options.aliasing;
    cellCount = d.cellCount;
    passes.clear();
    passes.reserve(d.passes.size());
    for (const ir::Pass& p : d.passes) {
        passes.push_back({p.queue, p.pipeline, p.sideEffects, p.kinds, p.firstUse, p.useCount});
    }
    uses = d.uses;
    resources.clear();
    resources.reserve(d.resources.size());
    for (const ir::Resource& r : d.resources) {
        resources.push_back({r.kind, r.origin, r.declarableAs, r.hasInitial, r.hasFinal, r.contentsAtStart, r.cellBase,
                             r.cellCount, r.partner, r.texture, r.buffer, r.initial, r.final});
    }
    outputs = d.outputs;
    orderings = d.orderings;
    written = d.written;
}

bool PlanCache::Entry::sameShape(const ir::Declaration& d, const QueueCaps& c, const CompileOptions& options) const {
    // Sizes first: a different frame usually differs there.
    if (d.passes.size() != passes.size() || d.uses.size() != uses.size() || d.resources.size() != resources.size() ||
        d.outputs.size() != outputs.size() || d.orderings.size() != orderings.size() ||
        d.written.size() != written.size() || d.cellCount != cellCount) {
        return false;
    }
    if (c.separateComputeFamily != caps.separateComputeFamily || c.graphicsFamily != caps.graphicsFamily ||
        c.computeFamily != caps.computeFamily || c.rayQuery != caps.rayQuery ||
        c.rayTracingPipeline != caps.rayTracingPipeline || c.bufferImageGranularity != caps.bufferImageGranularity ||
        options.aliasing != aliasing) {
        return false;
    }
    for (size_t i = 0; i < passes.size(); ++i) {
        const ir::Pass& p = d.passes[i];
        const PassShape& s = passes[i];
        if (p.queue != s.queue || p.pipeline != s.pipeline || p.sideEffects != s.sideEffects || p.kinds != s.kinds ||
            p.firstUse != s.firstUse || p.useCount != s.useCount) {
            return false;
        }
    }
    for (size_t i = 0; i < uses.size(); ++i) {
        const ir::Use& u = d.uses[i];
        const ir::Use& s = uses[i];
        if (u.resource != s.resource || u.version != s.version || u.producer != s.producer || u.kinds != s.kinds ||
            u.writes != s.writes || !(u.range == s.range)) {
            return false;
        }
    }
    for (size_t i = 0; i < resources.size(); ++i) {
        const ir::Resource& r = d.resources[i];
        const ResourceShape& s = resources[i];
        if (r.kind != s.kind || r.origin != s.origin || r.declarableAs != s.declarableAs ||
            r.hasInitial != s.hasInitial || r.hasFinal != s.hasFinal || r.contentsAtStart != s.contentsAtStart ||
            r.cellBase != s.cellBase || r.cellCount != s.cellCount || r.partner != s.partner ||
            !(r.texture == s.texture) || !(r.buffer == s.buffer)) {
            return false;
        }
        if (r.origin == ir::Origin::Imported && (!(r.initial == s.initial) || !(r.final == s.final))) return false;
    }
    for (size_t i = 0; i < outputs.size(); ++i) {
        const ir::Output& o = d.outputs[i];
        if (o.resource != outputs[i].resource || o.version != outputs[i].version ||
            o.producer != outputs[i].producer) {
            return false;
        }
    }
    for (size_t i = 0; i < orderings.size(); ++i) {
        if (d.orderings[i].before != orderings[i].before || d.orderings[i].after != orderings[i].after) return false;
    }
    return d.written == written;
}

PlanCache::PlanCache(uint32_t capacity) : capacity_(std::max(capacity, 1u)) {}

const Plan& PlanCache::compile(const Graph& graph, const CompileOptions& options) {
    ++calls_;
    // The last answer lets go of its frame's declaration.
    if (answered_ != kNone) entries_[answered_].plan.declaration.reset();
    answered_ = kNone;
    const ir::Declaration& d = graph.declaration();
    for (size_t i = 0; i < entries_.size(); ++i) {
        Entry& e = entries_[i];
        if (!e.sameShape(d, graph.caps(), options)) continue;
        ++hits_;
        e.lastUse = calls_;
        graph.shareDeclaration(e.plan);
        answered_ = i;
        return e.plan;
    }
    ++misses_;
    Plan plan = graph.compile(options);  // first: a throwing compile leaves the cache as it was
    if (entries_.size() >= capacity_) {
        const auto oldest = std::min_element(entries_.begin(), entries_.end(),
                                             [](const Entry& a, const Entry& b) { return a.lastUse < b.lastUse; });
        entries_.erase(oldest);
    }
    Entry& e = entries_.emplace_back();
    e.copyShape(d, graph.caps(), options);
    e.plan = std::move(plan);
    e.lastUse = calls_;
    answered_ = entries_.size() - 1;
    return e.plan;
}

} // namespace glint::rg
