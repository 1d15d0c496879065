#include "glint/graph/plan_cache.h"

#include <algorithm>

#include "glint/graph/graph.h"

namespace glint::rg {
namespace {

// Two 32-bit fields in one word.
constexpr uint64_t pair(uint64_t a, uint64_t b) { return a << 32 | (b & 0xFFFFFFFFu); }

void boundary(std::vector<uint64_t>& k, const BoundaryState& s) {
    k.push_back(pair(uint64_t(s.access) | uint64_t(s.queue) << 8 | uint64_t(s.pipeline) << 16 | uint64_t(s.isRaw) << 24,
                     uint64_t(s.rawScope.layout)));
    k.push_back(s.rawScope.stages);
    k.push_back(s.rawScope.access);
}

// FNV-1a over the words: a first filter before the whole keys are compared.
uint64_t hashOf(const std::vector<uint64_t>& key) {
    uint64_t h = 1469598103934665603ull;
    for (const uint64_t w : key) {
        h ^= w;
        h *= 1099511628211ull;
    }
    return h;
}

} // namespace

void structuralKey(const ir::Declaration& d, const QueueCaps& caps, const CompileOptions& options,
                   std::vector<uint64_t>& k) {
    k.clear();
    k.reserve(8 + d.passes.size() * 2 + d.uses.size() * 4 + d.resources.size() * 8 + d.outputs.size() * 2 +
              d.orderings.size() + d.written.size() / 8 + 1);
    k.push_back(pair(uint64_t(caps.separateComputeFamily) | uint64_t(caps.rayQuery) << 1 |
                         uint64_t(caps.rayTracingPipeline) << 2 | uint64_t(options.aliasing) << 3,
                     caps.graphicsFamily));
    k.push_back(pair(caps.computeFamily, d.cellCount));
    k.push_back(caps.bufferImageGranularity);
    // Counts first: vectors of different lengths never compare equal by
    // accident of concatenation.
    k.push_back(pair(d.passes.size(), d.uses.size()));
    k.push_back(pair(d.resources.size(), d.outputs.size()));
    k.push_back(pair(d.orderings.size(), d.written.size()));
    for (const ir::Pass& p : d.passes) {
        k.push_back(pair(uint64_t(p.queue) | uint64_t(p.pipeline) << 8 | uint64_t(p.sideEffects) << 16, p.firstUse));
        k.push_back(pair(p.useCount, p.kinds));
    }
    for (const ir::Use& u : d.uses) {
        k.push_back(pair(u.resource, u.version));
        k.push_back(pair(u.producer, uint64_t(u.kinds) | uint64_t(u.writes) << 16));
        k.push_back(pair(u.range.baseMip, u.range.mipCount));
        k.push_back(pair(u.range.baseLayer, u.range.layerCount));
    }
    for (const ir::Resource& r : d.resources) {
        k.push_back(pair(uint64_t(r.kind) | uint64_t(r.origin) << 8 | uint64_t(r.hasInitial) << 16 |
                             uint64_t(r.hasFinal) << 17 | uint64_t(r.contentsAtStart) << 18 |
                             uint64_t(r.declarableAs) << 24,
                         r.partner));
        k.push_back(pair(r.cellBase, r.cellCount));
        k.push_back(pair(r.texture.width, r.texture.height));
        k.push_back(pair(r.texture.depth, r.texture.layers));
        k.push_back(pair(r.texture.mips, uint64_t(r.texture.format)));
        k.push_back(r.buffer.size);
        if (r.origin == ir::Origin::Imported) {
            boundary(k, r.initial);
            boundary(k, r.final);
        }
    }
    for (const ir::Output& o : d.outputs) {
        k.push_back(pair(o.resource, o.version));
        k.push_back(o.producer);
    }
    for (const ir::Ordering& o : d.orderings) k.push_back(pair(o.before, o.after));
    // One bit per cell, 64 to a word.
    uint64_t word = 0;
    for (size_t c = 0; c < d.written.size(); ++c) {
        word |= uint64_t(d.written[c] != 0) << (c & 63);
        if ((c & 63) == 63) {
            k.push_back(word);
            word = 0;
        }
    }
    k.push_back(word);
}

PlanCache::PlanCache(uint32_t capacity) : capacity_(std::max(capacity, 1u)) {}

Plan PlanCache::compile(const Graph& graph, const CompileOptions& options) {
    ++calls_;
    structuralKey(graph.declaration(), graph.caps(), options, key_);
    const uint64_t hash = hashOf(key_);
    for (Entry& e : entries_) {
        if (e.hash != hash || e.key != key_) continue;
        ++hits_;
        e.lastUse = calls_;
        Plan plan = e.plan;
        graph.shareDeclaration(plan);
        return plan;
    }
    ++misses_;
    Plan plan = graph.compile(options);
    if (entries_.size() >= capacity_) {
        const auto oldest = std::min_element(entries_.begin(), entries_.end(),
                                             [](const Entry& a, const Entry& b) { return a.lastUse < b.lastUse; });
        entries_.erase(oldest);
    }
    Entry e;
    e.key = key_;
    e.hash = hash;
    e.plan = plan;
    e.plan.declaration.reset();
    e.lastUse = calls_;
    entries_.push_back(std::move(e));
    return plan;
}

} // namespace glint::rg
