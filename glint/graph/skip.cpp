// Skipped passes' barriers carried on and merged (skip.h).

#include "glint/graph/skip.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace glint::rg {

namespace {

bool overlap(const Subresource& a, const Subresource& b) {
    return a.baseMip < b.baseMip + b.mipCount && b.baseMip < a.baseMip + a.mipCount &&
           a.baseLayer < b.baseLayer + b.layerCount && b.baseLayer < a.baseLayer + a.layerCount;
}

bool same(const Subresource& a, const Subresource& b) {
    return a.baseMip == b.baseMip && a.mipCount == b.mipCount && a.baseLayer == b.baseLayer &&
           a.layerCount == b.layerCount;
}

// Two transients placed on overlapping memory of one heap.
bool memoryOverlaps(const Plan& plan, uint32_t a, uint32_t b) {
    const PlannedResource& x = plan.resources[a];
    const PlannedResource& y = plan.resources[b];
    if (x.origin != ir::Origin::Transient || y.origin != ir::Origin::Transient) return false;
    if (x.heap == kNoIndex || x.heap != y.heap) return false;
    return x.offset < y.offset + y.size && y.offset < x.offset + x.size;
}

// One barrier per subresource (mip, layer) of `b`'s range.
void split(const Barrier& b, std::vector<Barrier>& out) {
    for (uint32_t m = b.range.baseMip; m < b.range.baseMip + b.range.mipCount; ++m)
        for (uint32_t l = b.range.baseLayer; l < b.range.baseLayer + b.range.layerCount; ++l) {
            Barrier unit = b;
            unit.range = {m, 1, l, 1};
            out.push_back(unit);
        }
}

// The barriers carried from skipped passes, until the pass that next
// touches their resource (or the batch's end) takes them.
class Carried {
public:
    explicit Carried(const Plan& plan) : plan_(plan) {}

    // `own`, one pass's barriers (or a batch's end barriers), with what is
    // carried on their resources merged in: a subresource's two barriers
    // become one, from the carried one's old layout to the pass's new one,
    // both scopes unions (the carried source names accesses that did
    // happen; the pass's source may name the skipped pass's, which did
    // not; passes after it may rely on the carried destination, a read
    // the compiler found already visible). A barrier that takes memory
    // another carried resource held (an alias) absorbs that one's source
    // scope instead: the old owner's layout no longer matters, its last
    // accesses must still come first.
    std::vector<Barrier> take(std::span<const Barrier> own) {
        std::vector<Barrier> out;
        for (const Barrier& b : own) {
            Barrier l = b;
            for (auto it = carried_.begin(); it != carried_.end();) {
                if (it->resource != l.resource && memoryOverlaps(plan_, it->resource, l.resource)) {
                    l.srcStages |= it->srcStages;
                    l.srcAccess |= it->srcAccess;
                    l.aliasing = true;
                    it = carried_.erase(it);
                } else {
                    ++it;
                }
            }
            mergeInto(l, out);
        }
        return out;
    }

    // The carried barriers on resources `uses` names (after take(): those
    // with no barrier of the pass's own) join `emitted`: a pass that runs
    // relies on them (a read the compiler found ordered and visible
    // already, through the barrier now carried).
    void takeUsed(std::span<const ir::Use> uses, std::vector<Barrier>& emitted) {
        for (auto it = carried_.begin(); it != carried_.end();) {
            const bool used = std::any_of(uses.begin(), uses.end(),
                                          [&](const ir::Use& u) { return u.resource == it->resource; });
            if (used) {
                emitted.push_back(*it);
                it = carried_.erase(it);
            } else {
                ++it;
            }
        }
    }

    // Barriers a pass that runs records, after take() and takeUsed(): a
    // resource whose memory another resource held (its barrier is an
    // alias's) is claimed by its first write. While only read -- the
    // skipped pass was the one that wrote it -- every barrier on it stays
    // an alias's, carrying the old owner's last accesses as its source, so
    // that the write that does claim the memory comes after them.
    void settleClaims(std::vector<Barrier>& emitted, std::span<const ir::Use> uses) {
        for (Barrier& b : emitted) {
            const auto claim = std::find_if(claims_.begin(), claims_.end(),
                                            [&](const Barrier& c) { return c.resource == b.resource; });
            if (claim != claims_.end()) {
                b.srcStages |= claim->srcStages;
                b.srcAccess |= claim->srcAccess;
                b.aliasing = true;
            }
            const bool writes = std::any_of(uses.begin(), uses.end(), [&](const ir::Use& u) {
                return u.resource == b.resource && u.writes;
            });
            if (writes) {
                if (claim != claims_.end()) claims_.erase(claim);
            } else if (b.aliasing && claim == claims_.end()) {
                claims_.push_back(b);
            } else if (claim != claims_.end()) {
                *claim = b;
            }
        }
    }

    void carry(std::vector<Barrier> barriers) {
        carried_.insert(carried_.end(), barriers.begin(), barriers.end());
    }

    std::vector<Barrier> takeAll() { return std::exchange(carried_, {}); }

private:
    // `l` into `out`, merged with what is carried on its subresources
    // (both split into single subresources where their ranges differ).
    void mergeInto(const Barrier& l, std::vector<Barrier>& out) {
        const auto differs = [&](const Barrier& e) {
            return e.resource == l.resource && overlap(e.range, l.range) && !same(e.range, l.range);
        };
        std::vector<Barrier> pieces;
        if (std::any_of(carried_.begin(), carried_.end(), differs)) {
            split(l, pieces);
            std::vector<Barrier> units;
            for (const Barrier& e : carried_) {
                if (e.resource == l.resource && overlap(e.range, l.range))
                    split(e, units);
                else
                    units.push_back(e);
            }
            carried_ = std::move(units);
        } else {
            pieces.push_back(l);
        }
        for (Barrier& piece : pieces) {
            const auto it = std::find_if(carried_.begin(), carried_.end(), [&](const Barrier& e) {
                return e.resource == piece.resource && same(e.range, piece.range);
            });
            if (it != carried_.end()) {
                Barrier merged = *it;
                merged.srcStages |= piece.srcStages;
                merged.srcAccess |= piece.srcAccess;
                merged.dstStages |= piece.dstStages;
                merged.dstAccess |= piece.dstAccess;
                // The pass's barrier discards the contents: the merged one may too.
                if (piece.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED) merged.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
                merged.newLayout = piece.newLayout;
                merged.aliasing = merged.aliasing || piece.aliasing;
                carried_.erase(it);
                out.push_back(merged);
            } else {
                out.push_back(piece);
            }
        }
    }

    const Plan& plan_;
    std::vector<Barrier> carried_;
    std::vector<Barrier> claims_; // per resource: the alias's source scope not yet claimed by a write
};

} // namespace

bool hasSkippedPasses(const Plan& plan) {
    if (!plan.declaration) return false;
    const auto& passes = plan.declaration->passes;
    return std::any_of(plan.passes.begin(), plan.passes.end(),
                       [&](const PlannedPass& p) { return passes[p.pass].skipped; });
}

Plan skipPasses(const Plan& plan) {
    if (!hasSkippedPasses(plan)) return plan;
    const auto& declared = plan.declaration->passes;
    Plan out = plan;
    std::vector<std::vector<Barrier>> before(plan.passes.size());
    std::vector<std::vector<Barrier>> end(plan.batches.size());
    // Barriers are carried within a batch; the claims of aliased memory
    // across the frame (heaps never mix queues: a claim stays on its queue).
    Carried carried(plan);
    for (uint32_t b = 0; b < plan.batches.size(); ++b) {
        const Batch& batch = plan.batches[b];
        for (uint32_t planned = batch.firstPass; planned < batch.firstPass + batch.passCount; ++planned) {
            const PlannedPass& p = plan.passes[planned];
            std::vector<Barrier> own = carried.take(plan.barriersBefore(p));
            if (declared[p.pass].skipped) {
                out.passes[planned].skipped = true;
                carried.carry(std::move(own));
            } else {
                carried.takeUsed(plan.uses(p), own);
                carried.settleClaims(own, plan.uses(p));
                before[planned] = std::move(own);
            }
        }
        end[b] = carried.take(plan.barriersAfter(batch));
        const std::vector<Barrier> rest = carried.takeAll();
        end[b].insert(end[b].end(), rest.begin(), rest.end());
        carried.settleClaims(end[b], {});
    }

    out.barriers.clear();
    for (uint32_t b = 0; b < plan.batches.size(); ++b) {
        Batch& batch = out.batches[b];
        for (uint32_t planned = batch.firstPass; planned < batch.firstPass + batch.passCount; ++planned) {
            out.passes[planned].firstBarrier = static_cast<uint32_t>(out.barriers.size());
            out.passes[planned].barrierCount = static_cast<uint32_t>(before[planned].size());
            out.barriers.insert(out.barriers.end(), before[planned].begin(), before[planned].end());
        }
        batch.firstEndBarrier = static_cast<uint32_t>(out.barriers.size());
        batch.endBarrierCount = static_cast<uint32_t>(end[b].size());
        out.barriers.insert(out.barriers.end(), end[b].begin(), end[b].end());
    }
    return out;
}

} // namespace glint::rg
