// ---- Barriers ---------------------------------------------------------------
// One walk over the schedule keeps, per subresource ("cell"), what a later
// use has to synchronise with:
//   - the last write (or layout transition): queue, stages, access, the
//     batch it ran in, and, stage by stage on each queue, the accesses it is
//     already visible to;
//   - the reads since that write, per queue.
// Each use then needs:
//   read-after-write   the write made visible to its stage and access;
//   write-after-read   an execution dependency on the reads;
//   write-after-write  the earlier write made available (when no read came
//                      between; a read in between already saw it);
//   a layout change    a transition, itself a write: ordered after every
//                      earlier use of the cell.
// Read after read needs nothing unless the layout changes. Same-queue needs
// become one barrier per (use, subresource range), all of a pass's in one
// dependency; other-queue needs become a timeline wait at the start of the
// pass's batch in the pass's own stages, or, when an earlier wait already
// reaches the producer, a barrier chained to that wait's stages.
//
// The frame repeats, so its start is the previous frame's end: transients
// begin with the last uses of their bytes (their own and their aliases')
// as prior accesses and discarded contents, history halves with what the
// other half ended in, imports with their declared initial state. Prior
// accesses on the other queue are waited for on the previous frame's last
// batch of that queue. After the last pass, imports move to their final
// state.
//
// A transient used on one queue starts from where this very walk leaves
// its bytes, so its priors are not known before the walk: its first use of
// each cell (always a write or a layout transition, after which nothing of
// the priors remains in the cell) gets a barrier without them, completed
// once the walk is over (resolveFirstUses). Those priors are on the use's
// own queue, so they add stages and accesses to that barrier, never a wait.
// Only history halves and transients on both queues have their end states
// worked out before the walk, from their own uses.
//
// This file holds the walk itself: each pass's hazards and the barriers and
// waits they become, and the barriers and waits that leave imports in their
// final states. Where each resource starts the frame is worked out in
// barrier_frame_start.cpp; the state the walk keeps is in barrier_walk.h.

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "glint/graph/barrier_walk.h"

namespace glint::rg::detail::barrier_walk {

// Built during static initialisation (from the constant-initialised access
// table), so the lookup needs no guard. Rebuilt entry by entry only by a
// test's detail::ScopeOverride.
UseInfoTable kUseInfo;

Scratch& scratch() {
    thread_local Scratch s;
    return s;
}

void Walk::run() {
    st_.plan.barriers.reserve(d_.uses.size() + d_.resources.size());
    initialiseCells();
    st_.barrierFirst.assign(st_.order.size(), 0);
    st_.barrierCount.assign(st_.order.size(), 0);
    needs_.reserve(64);
    for (uint32_t pos = 0; pos < st_.order.size(); ++pos) walkPass(pos);
    resolveFirstUses();
    finalStates();
    batches_.finish();
}

// ---- Hazards ----------------------------------------------------------------

// A dependency on a prior access on the other queue: reuse a placed wait
// that reaches it, else request one (merged per signalling queue) in the
// use's own stages. Returns the wait stages the use can chain from.
// The pass's own new wait, once it has one, serves every need it reaches
// in the pass's stages; an older wait in other stages serves by a chained
// barrier only when no new wait is placed (walkPass re-analyses a pass
// that creates one, so the order of its uses does not matter).
VkPipelineStageFlags2 Walk::crossQueue(uint32_t q, uint32_t from, TimelinePoint point, VkPipelineStageFlags2 stages) {
    const VkPipelineStageFlags2 wanted = stages ? stages : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    const VkPipelineStageFlags2 placed =
        batches_.reachingStages(static_cast<Queue>(q), static_cast<Queue>(from), point);
    if (placed && within(wanted, placed)) return placed;
    WaitRequest& req = pending_[from];
    if (req.active && reaches(req.point, point)) {
        req.stages |= wanted;
        return req.stages;
    }
    if (placed) return placed;
    if (!req.active) {
        req = {true, point, wanted};
    } else {
        req.point = point;
        req.stages |= wanted;
    }
    return req.stages;
}

// `n` arrives value-initialised (a fresh need, or one reset by the caller).
// Inline in the walk (it and update() run for every use; as calls they
// spent a tenth of the walk saving and restoring registers).
[[gnu::always_inline]] void Walk::analyse(Need& n, uint32_t c, uint32_t q, const UseInfo& use, bool writes,
                                          bool texture) {
    const Cell& cell = cells_[c];
    const SyncScope& s = use.scope;
    if (cell.priorLater) {
        // Nothing this frame came before it, and what the previous one
        // left comes later: a barrier either way (a texture transitions
        // from UNDEFINED; a buffer's last frame always left a use behind),
        // which resolveFirstUses() completes.
        n.cell = c;
        n.transition = texture && cell.layout != s.layout;
        n.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        n.barrier = true;
        n.firstUse = true;
        return;
    }
    n.cell = c;
    n.transition = texture && cell.layout != s.layout;
    n.oldLayout = n.transition && !cell.contents ? VK_IMAGE_LAYOUT_UNDEFINED : cell.layout;
    const bool writeOp = writes || n.transition;

    // Read after write.
    if (use.reads && cell.wQueue >= 0 && cell.wStages && !cell.vis.covers(q, use.readMask)) {
        if (cell.wQueue == static_cast<int8_t>(q)) {
            n.srcStages |= cell.wStages;
            n.srcAccess |= cell.wAccess;
            n.rawByBarrier = true;
        } else {
            viaOtherQueue(n, q, s, static_cast<uint32_t>(cell.wQueue), cell.wPoint, true);
        }
    }
    if (writeOp) {
        // Write after read.
        for (uint32_t rq = 0; rq < kQueueCount; ++rq) {
            if (!cell.rStages[rq]) continue;
            if (rq == q)
                n.srcStages |= cell.rStages[rq];
            else if (n.transition || !within(ownStages(s), cell.rOrdered[q]))
                viaOtherQueue(n, q, s, rq, cell.rPoint[rq], false);
        }
        // Write after write. A layout transition names the last write
        // in its first scope even when an earlier barrier already made
        // it available: the transition is a write of its own, and
        // synchronization validation (rightly strict about WAW) only
        // accepts a prior write the transition's barrier itself covers.
        if ((cell.wPending || n.transition) && cell.wQueue >= 0 && cell.wStages &&
            (n.transition || !cell.vis.covers(q, use.accessMask))) {
            if (cell.wQueue == static_cast<int8_t>(q)) {
                n.srcStages |= cell.wStages;
                n.srcAccess |= cell.wAccess;
            } else {
                viaOtherQueue(n, q, s, static_cast<uint32_t>(cell.wQueue), cell.wPoint, false);
            }
        }
    }
    n.barrier = n.transition || n.srcStages != 0;
}

// The stages a use's own work runs in (ALL_COMMANDS for a use of none).
VkPipelineStageFlags2 Walk::ownStages(const SyncScope& s) {
    return s.stages ? s.stages : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
}

// analyse()'s dependency on a prior access on the other queue, `from`,
// at `point`: through a wait, chained into a barrier when the wait's
// stages do not cover the use's. Out of line: most uses never get here.
[[gnu::noinline]] void Walk::viaOtherQueue(Need& n, uint32_t q, const SyncScope& s, uint32_t from, TimelinePoint point,
                                           bool makesVisible) {
    n.waits = true;
    const VkPipelineStageFlags2 waited = crossQueue(q, from, point, s.stages);
    if (n.transition || !within(ownStages(s), waited)) {
        n.srcStages |= waited; // chain through the wait
        n.rawByBarrier = n.rawByBarrier || makesVisible;
    } else if (makesVisible) {
        n.visibleByWait |= waited;
    }
}

// The frame's last word on an import: it ends in `s` on queue q, as if a
// use of that kind came next. Priors that `s` already describes (same
// queue, its stages, its write access) stay as they are: whoever comes
// next synchronises with them through `s`. Others are made to happen
// before `s`.
// `n` arrives value-initialised, as in analyse().
void Walk::analyseFinal(Need& n, uint32_t c, uint32_t q, const UseInfo& state, bool texture) {
    const Cell& cell = cells_[c];
    const SyncScope& s = state.scope;
    n.cell = c;
    n.transition = texture && s.layout != VK_IMAGE_LAYOUT_UNDEFINED && cell.layout != s.layout;
    n.oldLayout = n.transition && !cell.contents ? VK_IMAGE_LAYOUT_UNDEFINED : cell.layout;
    if (!n.transition && !s.stages) return; // handed over by a semaphore signal: nothing to order

    auto order = [&](uint32_t from, TimelinePoint point, VkPipelineStageFlags2 stages, VkAccessFlags2 access,
                     bool makesVisible) {
        if (from == q) {
            n.srcStages |= stages;
            n.srcAccess |= access;
            n.rawByBarrier = n.rawByBarrier || makesVisible;
            return;
        }
        n.waits = true;
        const VkPipelineStageFlags2 waited = crossQueue(q, from, point, s.stages);
        if (n.transition || !within(s.stages ? s.stages : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, waited))
            n.srcStages |= waited;
    };

    for (uint32_t rq = 0; rq < kQueueCount; ++rq) {
        if (!cell.rStages[rq]) continue;
        if (!n.transition && rq == q && within(cell.rStages[rq], s.stages)) continue;
        if (!n.transition && rq != q && within(s.stages, cell.rOrdered[q])) continue;
        order(rq, cell.rPoint[rq], cell.rStages[rq], 0, false);
    }
    if (cell.wQueue >= 0 && cell.wStages) {
        const bool described = cell.wQueue == static_cast<int8_t>(q) && within(cell.wStages, s.stages) &&
                               within(cell.wAccess, s.access);
        const bool unseen = state.reads && !cell.vis.covers(q, state.readMask);
        if ((n.transition && cell.wPending) || (!described && (cell.wPending || unseen)))
            order(static_cast<uint32_t>(cell.wQueue), cell.wPoint, cell.wStages, cell.wAccess, unseen);
    }
    n.barrier = n.transition || n.srcStages != 0;
}

// Inline in the walk, as analyse() is.
[[gnu::always_inline]] void Walk::update(const Need& n, uint32_t q, const UseInfo& use, bool writes,
                                         TimelinePoint now) {
    Cell& cell = cells_[n.cell];
    const SyncScope& s = use.scope;
    if (n.firstUse) [[unlikely]] {
        // What follows a write (or a layout transition) does not depend
        // on what came before it, so the walk can go on without the
        // priors. A transient's first use of a subresource writes it
        // (reads need contents), so this holds by construction.
        if (!writes && !n.transition)
            throw std::logic_error("rg barriers: the first use of a transient subresource in '" +
                                   std::string(d_.passes[st_.order[pos_]].name) + "' reads it");
        cell.priorLater = false;
    }
    if (writes) {
        // A write replaces all the cell knew but its layout: what a
        // transition, a barrier or a wait made visible or ordered came
        // before it.
        if (n.transition) cell.layout = s.layout;
        cell.wQueue = static_cast<int8_t>(q);
        cell.wPoint = now;
        cell.wStages = s.stages;
        cell.wAccess = use.writeAccess;
        cell.wPending = true;
        cell.rStages[0] = cell.rStages[1] = 0;
        cell.rOrdered[0] = cell.rOrdered[1] = 0;
        cell.clearVisible();
        cell.contents = true;
        return;
    }
    // A barrier chained from a wait orders every read of the other queue
    // that wait reached, not only the hazard it was placed for.
    const uint32_t other = queueIndex(otherQueue(static_cast<Queue>(q)));
    if (n.barrier && cell.rStages[other] &&
        (batches_.reachingStages(static_cast<Queue>(q), static_cast<Queue>(other), cell.rPoint[other]) &
         n.srcStages))
        cell.rOrdered[q] |= s.stages;
    if (n.transition) {
        cell.layout = s.layout;
        cell.wQueue = static_cast<int8_t>(q);
        cell.wPoint = now;
        cell.wStages = s.stages;
        cell.wAccess = 0;
        cell.wPending = true;
        cell.rStages[0] = cell.rStages[1] = 0;
        cell.rOrdered[0] = cell.rOrdered[1] = 0;
        cell.clearVisible();
        cell.vis.add(q, use.accessMask);
    } else if (n.rawByBarrier) {
        cell.vis.add(q, use.readMask);
    }
    if (n.visibleByWait) cell.addVisibleToAll(q, n.visibleByWait);
    cell.rStages[q] |= s.stages;
    cell.rPoint[q] = now;
    cell.rOrdered[other] = 0; // the new read is not ordered on the other queue yet
    cell.wPending = false;
}

// ---- Emission ---------------------------------------------------------------

// Turns needs_[first, last) -- one use's cells in mip-major order -- into
// barriers: runs of layers per mip, merged across mips when runs line up.
// The use is on queue q, with `info` (null for frame-end states).
void Walk::emit(uint32_t resource, bool texture, VkImageAspectFlags aspect, const Subresource& range,
                const SyncScope& s, size_t first, size_t last, uint32_t q, const UseInfo* info) {
    std::vector<Barrier>& out = st_.plan.barriers;
    const size_t firstBarrier = out.size();
    const uint32_t layers = texture ? range.layerCount : 1;
    size_t i = first;
    while (i < last) {
        const Need& n = needs_[i];
        if (!n.barrier) {
            ++i;
            continue;
        }
        const auto offset = static_cast<uint32_t>(i - first);
        const uint32_t mip = texture ? range.baseMip + offset / layers : 0;
        const uint32_t layer = texture ? range.baseLayer + offset % layers : 0;
        VkPipelineStageFlags2 srcStages = n.srcStages;
        VkAccessFlags2 srcAccess = n.srcAccess;
        uint32_t layerCount = 1;
        size_t j = i + 1;
        while (j < last && (j - first) / layers == offset / layers && needs_[j].barrier &&
               needs_[j].oldLayout == n.oldLayout) {
            srcStages |= needs_[j].srcStages;
            srcAccess |= needs_[j].srcAccess;
            ++layerCount;
            ++j;
        }
        const VkImageLayout oldLayout = texture ? n.oldLayout : VK_IMAGE_LAYOUT_UNDEFINED;
        // Barriers are built in place: assembling one on the stack and
        // copying it costs store-forwarding stalls on this hot path.
        if (out.size() > firstBarrier) {
            Barrier& prev = out.back();
            if (prev.oldLayout == oldLayout && prev.range.baseLayer == layer &&
                prev.range.layerCount == layerCount && prev.range.baseMip + prev.range.mipCount == mip) {
                ++prev.range.mipCount;
                prev.srcStages |= srcStages;
                prev.srcAccess |= srcAccess;
                noteFirstUses(out.size() - 1, resource, texture, q, info, i, j);
                i = j;
                continue;
            }
        }
        noteFirstUses(out.size(), resource, texture, q, info, i, j);
        out.emplace_back(Barrier{resource, Subresource{mip, 1, layer, layerCount}, aspect, srcStages, srcAccess,
                                 s.stages, s.access, oldLayout, texture ? s.layout : VK_IMAGE_LAYOUT_UNDEFINED,
                                 false});
        i = j;
    }
    if (st_.log) {
        const ir::Resource& r = d_.resources[resource];
        for (size_t k = firstBarrier; k < out.size(); ++k)
            if (!holdsFirstUse(k)) spdlog::debug("rg barriers: {}", describeBarrier(r.name, out[k], r.kind));
    }
}

// Records the first uses among needs_[first, last) of a use of
// `resource` on queue q, merged into barrier `barrier`.
void Walk::noteFirstUses(size_t barrier, uint32_t resource, bool texture, uint32_t q, const UseInfo* info, size_t first,
                         size_t last) {
    for (size_t k = first; k < last; ++k)
        if (needs_[k].firstUse) [[unlikely]]
            firstUses_.push_back({static_cast<uint32_t>(barrier), needs_[k].cell, resource, q, texture, info});
}

// Whether barrier k waits for resolveFirstUses() (debug logging only).
bool Walk::holdsFirstUse(size_t k) const {
    return std::any_of(firstUses_.begin(), firstUses_.end(), [&](const FirstUse& f) { return f.barrier == k; });
}

// emit() of a use of one cell (most uses): one barrier, nothing to merge.
void Walk::emitOne(uint32_t resource, const UseRef& ref, const Subresource& range, const SyncScope& s, const Need& n,
                   uint32_t q) {
    if (n.firstUse) [[unlikely]]
        firstUses_.push_back(
            {static_cast<uint32_t>(st_.plan.barriers.size()), n.cell, resource, q, ref.texture, ref.info});
    // Constructed from its fields (braces: clang 14 has no parenthesised
    // aggregate initialisation). The aspect is read only when a barrier
    // needs it; the aliasing flag is set by resolveFirstUses() where
    // bytes are shared.
    const Barrier& b = st_.plan.barriers.emplace_back(Barrier{
        resource, ref.texture ? Subresource{range.baseMip, 1, range.baseLayer, 1} : Subresource{0, 1, 0, 1},
        ref.texture ? st_.plan.resources[resource].aspect : 0, n.srcStages, n.srcAccess, s.stages, s.access,
        ref.texture ? n.oldLayout : VK_IMAGE_LAYOUT_UNDEFINED, ref.texture ? s.layout : VK_IMAGE_LAYOUT_UNDEFINED,
        false});
    if (st_.log && !n.firstUse) {
        const ir::Resource& r = d_.resources[resource];
        spdlog::debug("rg barriers: {}", describeBarrier(r.name, b, r.kind));
    }
}

void Walk::walkPass(uint32_t pos) {
    pos_ = pos;
    const uint32_t p = st_.order[pos];
    const ir::Pass& pass = d_.passes[p];
    const uint32_t q = queueIndex(st_.queueOf[p]);
    clearPending();
    needs_.clear();
    useNeed_.clear();
    refs_.clear();
    for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
        const UseRef& ref = refs_.emplace_back(useRefOf(pass, u));
        useNeed_.push_back(static_cast<uint32_t>(needs_.size()));
        // Most uses name one cell: analysed directly, not through forCells' callback.
        if (ref.single)
            analyse(needs_.emplace_back(), ref.cell, q, *ref.info, ref.writes, ref.texture);
        else
            forCells(d_.resources[d_.uses[u].resource], d_.uses[u].range,
                     [&](uint32_t c) { analyse(needs_.emplace_back(), c, q, *ref.info, ref.writes, ref.texture); });
    }
    useNeed_.push_back(static_cast<uint32_t>(needs_.size())); // use i's needs end where use i + 1's begin
    // A new wait changes only what uses that asked crossQueue() get;
    // whether a use asks depends on its cell alone, so those needs,
    // analysed again in the same order, replay the requests as a
    // second full pass would.
    if (pending_[0].active || pending_[1].active) {
        for (uint32_t i = 0; i < pass.useCount; ++i) {
            const UseRef& ref = refs_[i];
            for (size_t k = useNeed_[i]; k < useNeed_[i + 1]; ++k) {
                if (!needs_[k].waits) continue;
                const uint32_t cell = needs_[k].cell;
                needs_[k] = Need{};
                analyse(needs_[k], cell, q, *ref.info, ref.writes, ref.texture);
            }
        }
    }
    const uint32_t ordinal = batches_.placePass(static_cast<Queue>(q), pos, pending_);
    const TimelinePoint now{0, ordinal};

    st_.barrierFirst[pos] = static_cast<uint32_t>(st_.plan.barriers.size());
    for (uint32_t i = 0; i < pass.useCount; ++i) {
        const UseRef& ref = refs_[i];
        const UseInfo& info = *ref.info;
        const SyncScope& s = info.scope;
        const size_t first = useNeed_[i];
        const size_t last = useNeed_[i + 1];
        if (ref.single) {
            const Need& n = needs_[first];
            if (n.barrier)
                emitOne(d_.uses[pass.firstUse + i].resource, ref, d_.uses[pass.firstUse + i].range, s, n, q);
            update(n, q, info, ref.writes, now);
            continue;
        }
        // Most uses need no barrier; emit() is not worth a call for them.
        size_t firstBarrier = first;
        while (firstBarrier < last && !needs_[firstBarrier].barrier) ++firstBarrier;
        if (firstBarrier < last) {
            const ir::Use& use = d_.uses[pass.firstUse + i];
            emit(use.resource, ref.texture, ref.texture ? st_.plan.resources[use.resource].aspect : 0, use.range, s,
                 first, last, q, ref.info);
        }
        for (size_t k = first; k < last; ++k) update(needs_[k], q, info, ref.writes, now);
    }
    st_.barrierCount[pos] = static_cast<uint32_t>(st_.plan.barriers.size()) - st_.barrierFirst[pos];
}

// ---- Frame end --------------------------------------------------------------

void Walk::finalStates() {
    // The imports that end in a state someone cares about, by the queue
    // of that state, with its scope looked up once.
    std::vector<FinalImport>* targets = scratch_.finalImports;
    std::vector<UseInfo>& rawFinals = scratch_.rawFinals;
    targets[0].clear();
    targets[1].clear();
    rawFinals.clear();
    rawFinals.reserve(imports_.size()); // keeps pointers into it valid
    for (uint32_t r : imports_) {
        const ir::Resource& res = d_.resources[r];
        if (!res.hasFinal) continue;
        if (!res.final.isRaw && res.final.access == Access::None) continue; // the caller does not care
        if (!st_.lifetimes[r].used() && res.hasInitial && res.initial == res.final) continue;
        FinalImport& target = targets[queueIndex(st_.boundaryQueue(res.final.queue))].emplace_back();
        target.resource = r;
        target.cellBase = res.cellBase;
        target.cellCount = res.cellCount;
        target.texture = res.kind == ResourceKind::Texture;
        // A state named by an access kind is a use of that kind: the table has its masks.
        target.state = res.final.isRaw ? &rawFinals.emplace_back(makeUseInfo(boundaryScope(res.final, res.kind)))
                                       : &useInfoOf(res.final.access, res.kind, res.final.pipeline);
    }
    for (uint32_t qi = 0; qi < kQueueCount; ++qi) {
        const auto q = static_cast<Queue>(qi);
        clearPending();
        finals_.clear();
        needs_.clear();
        for (const FinalImport& target : targets[qi]) {
            // Every cell, mip-major, is the run of cells from cellBase.
            const auto first = static_cast<uint32_t>(needs_.size());
            bool matters = false;
            for (uint32_t c = target.cellBase; c < target.cellBase + target.cellCount; ++c) {
                Need& n = needs_.emplace_back();
                analyseFinal(n, c, qi, *target.state, target.texture);
                matters = matters || n.barrier || n.waits;
            }
            // Most imports end as the frame left them: nothing to keep.
            if (matters)
                finals_.push_back({&target, first, static_cast<uint32_t>(needs_.size())});
            else
                needs_.resize(first);
        }
        // As in walkPass(): a new wait changes only the needs that asked
        // for one, and analysing those again in order replays the requests.
        if (pending_[0].active || pending_[1].active) {
            for (const Final& f : finals_) {
                for (uint32_t k = f.firstNeed; k < f.endNeed; ++k) {
                    if (!needs_[k].waits) continue;
                    const uint32_t cell = needs_[k].cell;
                    needs_[k] = Need{};
                    analyseFinal(needs_[k], cell, qi, *f.target->state, f.target->texture);
                }
            }
        }
        std::erase_if(finals_, [&](const Final& f) {
            return std::none_of(needs_.begin() + f.firstNeed, needs_.begin() + f.endNeed,
                                [](const Need& n) { return n.barrier; });
        });
        // A final state can need only a wait: the import must be visible on
        // its final queue after the other queue's last use.
        if (finals_.empty() && !pending_[0].active && !pending_[1].active) continue;
        batches_.placeEnd(q, pending_);
        const auto firstBarrier = static_cast<uint32_t>(st_.plan.barriers.size());
        for (const Final& f : finals_) {
            const uint32_t r = f.target->resource;
            const bool texture = f.target->texture;
            emit(r, texture, texture ? st_.plan.resources[r].aspect : 0, wholeOf(d_.resources[r]),
                 f.target->state->scope, f.firstNeed, f.endNeed, qi, nullptr);
        }
        batches_.setEndBarriers(q, firstBarrier, static_cast<uint32_t>(st_.plan.barriers.size()) - firstBarrier);
    }
}

Subresource Walk::wholeOf(const ir::Resource& r) {
    return r.kind == ResourceKind::Texture ? Subresource{0, r.texture.mips, 0, r.texture.layers}
                                           : Subresource{0, 1, 0, 1};
}

} // namespace glint::rg::detail::barrier_walk

namespace glint::rg::detail {

void placeBarriersAndBatches(CompileState& st) { barrier_walk::Walk(st).run(); }

void refreshUseInfo(Access a, ResourceKind k, Pipeline p) {
    barrier_walk::kUseInfo.info[static_cast<uint32_t>(a)][static_cast<uint32_t>(k)][static_cast<uint32_t>(p)] =
        barrier_walk::makeUseInfo(scopeOf(a, k, p));
}

} // namespace glint::rg::detail
