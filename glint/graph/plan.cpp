#include "glint/graph/plan.h"

#include "glint/graph/access.h"

namespace glint::rg {

std::span<const ir::Use> Plan::uses(const PlannedPass& p) const {
    const ir::Pass& pass = declaration->passes[p.pass];
    return {declaration->uses.data() + pass.firstUse, pass.useCount};
}

uint32_t Plan::batchCount(Queue q) const {
    uint32_t n = 0;
    for (const Batch& b : batches) n += b.queue == q;
    return n;
}

uint32_t Plan::barrierCallCount() const {
    uint32_t n = 0;
    for (const PlannedPass& p : passes) n += p.barrierCount > 0;
    for (const Batch& b : batches) n += b.endBarrierCount > 0;
    return n;
}

uint32_t Plan::family(Queue q) const {
    return q == Queue::AsyncCompute && caps.separateComputeFamily ? caps.computeFamily : caps.graphicsFamily;
}

uint64_t Plan::signalValue(uint64_t frame, const Batch& b) const { return frame * batchCount(b.queue) + b.ordinal + 1; }

std::optional<uint64_t> Plan::waitValue(uint64_t frame, const SemaphoreWait& w) const {
    if (w.frameOffset < 0 && frame < static_cast<uint64_t>(-w.frameOffset)) return std::nullopt;
    // A queue without batches signals nothing under these values.
    if (w.batch == SemaphoreWait::kLastSignalled) return std::nullopt;
    const uint64_t target = frame + static_cast<uint64_t>(static_cast<int64_t>(w.frameOffset));
    return target * batchCount(w.queue) + w.batch + 1;
}

Plan::WaitPoint Plan::firstUseOf(uint32_t resource) const {
    WaitPoint out;
    if (resource >= resources.size()) return out;
    const ResourceKind kind = resources[resource].kind;
    for (const PlannedPass& p : passes) {
        for (const ir::Use& use : uses(p))
            if (use.resource == resource) out.stages |= accessScope(use.kinds, kind, pipeline(p)).stages;
        if (out.stages) {
            out.batch = p.batch;
            break;
        }
    }
    const ir::Resource& r = declaration->resources[resource];
    if (r.origin == ir::Origin::Imported && r.hasInitial) out.stages |= boundaryScope(r.initial, kind).stages;
    return out;
}

uint32_t Plan::batchEnding(uint32_t resource) const {
    uint32_t end = kNoIndex, lastUse = kNoIndex;
    for (uint32_t b = 0; b < batches.size(); ++b) {
        for (const Barrier& barrier : barriersAfter(batches[b]))
            if (barrier.resource == resource) end = b;
        for (const PlannedPass& p : passesOf(batches[b]))
            for (const ir::Use& use : uses(p))
                if (use.resource == resource) lastUse = b;
    }
    return end != kNoIndex ? end : lastUse;
}

const PlannedPass* Plan::findPass(std::string_view name) const {
    for (const PlannedPass& p : passes)
        if (declaration->passes[p.pass].name == name) return &p;
    return nullptr;
}

uint32_t Plan::findResource(std::string_view name) const {
    for (uint32_t r = 0; r < declaration->resources.size(); ++r)
        if (declaration->resources[r].name == name) return r;
    return kNoIndex;
}

} // namespace glint::rg
