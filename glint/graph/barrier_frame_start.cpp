// ---- The barrier walk's frame start ---------------------------------------
// Where each resource starts the frame (barriers.cpp's header comment says
// why it is the previous frame's end): imports from their initial states,
// history halves and transients on both queues from their own ends, worked
// out before the walk; transients on one queue (aliased or not) once the
// walk is over, completing the barriers of their first uses
// (resolveFirstUses).

#include <stdexcept>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>

#include "glint/graph/barrier_walk.h"
#include "glint/graph/error.h"

namespace glint::rg::detail::barrier_walk {
namespace {

constexpr TimelinePoint kPreviousFrame{-1, TimelinePoint::kLastBatch};

// Adds `e` as the previous frame's accesses to `c`.
void addPrior(Cell& c, const EndState& e) {
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        if (!e.rStages[q]) continue;
        c.rStages[q] |= e.rStages[q];
        c.rPoint[q] = kPreviousFrame;
    }
    if (e.wQueue >= 0 && e.wStages && (c.wQueue < 0 || c.wQueue == e.wQueue)) {
        c.wQueue = e.wQueue;
        c.wStages |= e.wStages;
        c.wAccess |= e.wAccess;
        c.wPoint = kPreviousFrame;
        c.wPending = c.wPending || e.wPending;
    }
}

} // namespace

void Walk::initialiseCells() {
    const uint32_t cellCount = d_.cellCount;
    cells_.assign(cellCount, Cell{});
    // A UseRef is made per use in the walk and once more for a use of a
    // resource that starts from its own end: at most two merged entries
    // per use, and the reserve keeps pointers into them valid.
    mergedInfo_.clear();
    mergedInfo_.reserve(2 * d_.uses.size());

    // Imports start from their declared state. Resources that start from
    // where they end, known before the walk: history halves (each starts
    // from the other's end, visibility included) and transients on both
    // queues (their priors may need a wait on the other queue, which
    // changes batches). Only their cells' ends_ and endSeen_ are used, so
    // only those are reset. Every other transient is priorLater, as its
    // cells already are.
    ends_.resize(cellCount);
    endSeen_.resize(cellCount);
    early_.assign(d_.resources.size(), 0);
    std::vector<uint32_t>& early = scratch_.earlyList;
    std::vector<uint32_t>& currents = scratch_.historyCurrents;
    early.clear();
    currents.clear();
    imports_.clear();
    for (const uint32_t r : st_.startKnown) {
        const ir::Resource& res = d_.resources[r];
        switch (res.origin) {
            case ir::Origin::Imported:
                imports_.push_back(r);
                startImport(r);
                continue;
            case ir::Origin::Transient: // on both queues
                break;
            case ir::Origin::HistoryCurrent:
                currents.push_back(r);
                break;
            case ir::Origin::HistoryPrevious:
                break;
        }
        early_[r] = 1;
        early.push_back(r);
        for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
            ends_[c] = EndState{};
            endSeen_[c] = Visibility{};
        }
    }
    if (early.empty()) return;

    // What the frame leaves behind in them, use by use. A `previous` half
    // starts from what its partner ended in, so it goes second.
    std::vector<uint32_t>& deferred = scratch_.deferred;
    deferred.clear();
    for (uint32_t pos = 0; pos < st_.order.size(); ++pos) {
        const uint32_t p = st_.order[pos];
        const ir::Pass& pass = d_.passes[p];
        for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
            const uint32_t r = d_.uses[u].resource;
            if (!early_[r]) continue;
            if (d_.resources[r].origin == ir::Origin::HistoryPrevious) {
                deferred.push_back(u);
                deferred.push_back(pos);
                continue;
            }
            applyEnd(pass, u, queueIndex(st_.queueOf[p]));
        }
    }
    for (const uint32_t r : currents) seedHistoryPrevious(r);
    for (size_t i = 0; i < deferred.size(); i += 2) {
        const uint32_t p = st_.order[deferred[i + 1]];
        applyEnd(d_.passes[p], deferred[i], queueIndex(st_.queueOf[p]));
    }

    for (const uint32_t r : early) {
        const ir::Resource& res = d_.resources[r];
        if (res.origin != ir::Origin::Transient) {
            startHistory(r);
            continue;
        }
        // Its bytes are its own (no aliasing across queues).
        for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
            cells_[c].priorLater = false;
            addPrior(cells_[c], ends_[c]);
        }
    }
}

[[noreturn]] void Walk::priorsElsewhere(uint32_t r) const {
    throw std::logic_error("rg barriers: the frame-start priors of '" + std::string(d_.resources[r].name) +
                           "' are on the other queue");
}

// Completes the first-use barriers of the transients on one queue: now
// that the walk has seen the frame's last uses, each such use is
// analysed again from its true frame-start state (its own last uses, or
// those of every resource on its bytes), and what that adds is ORed into
// the barrier the walk placed. The priors are on the use's own queue (a
// one-queue resource; an aliasing heap holds one queue's resources), so
// they add stages and accesses, never a wait.
void Walk::resolveFirstUses() {
    if (firstUses_.empty()) return;
    aliasedPriors_.resize(d_.resources.size());
    startAliased();
    std::vector<Barrier>& barriers = st_.plan.barriers;
    for (const FirstUse& f : firstUses_) {
        const uint32_t r = f.resource;
        const LastUses prior = st_.aliased[r] ? aliasedPriors_[r] : lastUsesOf(f.cell, f.queue, r);
        const UseInfo& info = *f.info;
        const bool transition = f.texture; // from UNDEFINED
        VkPipelineStageFlags2 srcStages = 0;
        VkAccessFlags2 srcAccess = 0;
        // analyse() of a use after `prior` alone: nothing is visible yet,
        // the use writes (or transitions), every prior is on its queue.
        const bool write = prior.wStages != 0;
        // Read after write.
        if (info.reads && write && !Visibility{}.covers(f.queue, info.readMask)) {
            srcStages |= prior.wStages;
            srcAccess |= prior.wAccess;
        }
        // Write after read.
        srcStages |= prior.rStages;
        // Write after write.
        if ((prior.pending || transition) && write &&
            (transition || !Visibility{}.covers(f.queue, info.accessMask))) {
            srcStages |= prior.wStages;
            srcAccess |= prior.wAccess;
        }
        if (!transition && !srcStages) [[unlikely]]
            throw std::logic_error("rg barriers: '" + std::string(d_.resources[r].name) +
                                   "' starts the frame with no prior use");
        Barrier& b = barriers[f.barrier];
        b.srcStages |= srcStages;
        b.srcAccess |= srcAccess;
        b.aliasing = b.aliasing || st_.aliased[r];
    }
    if (st_.log) {
        for (size_t i = 0; i < firstUses_.size(); ++i) {
            const uint32_t k = firstUses_[i].barrier;
            if (i > 0 && firstUses_[i - 1].barrier == k) continue;
            const ir::Resource& r = d_.resources[barriers[k].resource];
            spdlog::debug("rg barriers: {} (first use)", describeBarrier(r.name, barriers[k], r.kind));
        }
    }
    firstUses_.clear();
}

void Walk::applyEnd(const ir::Pass& pass, uint32_t u, uint32_t q) {
    const ir::Use& use = d_.uses[u];
    const ir::Resource& r = d_.resources[use.resource];
    const UseRef ref = useRefOf(pass, u);
    // Visibility carries over only for history images (imports restart
    // from their declared state, transients from discarded contents).
    const bool history = r.partner != kNoIndex;
    forCells(ref, use, [&](uint32_t c) {
        ends_[c].apply(q, *ref.info, use.writes, ref.texture, history ? &endSeen_[c] : nullptr);
    });
}

// `previous` this frame is what `current` was at the end of the last one.
void Walk::seedHistoryPrevious(uint32_t current) {
    const ir::Resource& cur = d_.resources[current];
    const ir::Resource& prev = d_.resources[cur.partner];
    for (uint32_t i = 0; i < cur.cellCount; ++i) {
        const EndState& from = ends_[cur.cellBase + i];
        if (!from.touched) continue;
        ends_[prev.cellBase + i] = from;
        endSeen_[prev.cellBase + i] = endSeen_[cur.cellBase + i];
    }
}

void Walk::startImport(uint32_t r) {
    const ir::Resource& res = d_.resources[r];
    for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) cells_[c].priorLater = false;
    if (!res.hasInitial) return;
    // A state named by an access kind is a use of that kind: its masks
    // come from the table.
    UseInfo raw;
    if (res.initial.isRaw) raw = makeUseInfo(boundaryScope(res.initial, res.kind));
    const UseInfo& state =
        res.initial.isRaw ? raw : useInfoOf(res.initial.access, res.kind, res.initial.pipeline);
    const SyncScope& s = state.scope;
    const uint32_t q = queueIndex(st_.boundaryQueue(res.initial.queue));
    for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
        Cell& cell = cells_[c];
        cell.layout = s.layout;
        cell.contents = res.contentsAtStart;
        if (!s.stages) continue; // nothing in flight: ordered outside the plan
        cell.wQueue = static_cast<int8_t>(q);
        cell.wStages = s.stages;
        cell.wPoint = kPreviousFrame;
        if (state.writeAccess) {
            cell.wAccess = state.writeAccess;
            cell.wPending = true;
        } else {
            // A read state: whatever wrote the contents is visible to that
            // read, and only to it; other readers chain from its stages.
            cell.rStages[q] = s.stages;
            cell.rPoint[q] = kPreviousFrame;
            if (cell.contents)
                cell.vis.add(q, state.accessMask);
            else
                cell.wQueue = -1;
        }
    }
}

// A history half's image was its partner's last frame. `current` starts
// where `previous` ended (ends_ of `previous` already includes the
// partner's end it started from); `previous` starts where `current` ended,
// or, for a subresource `current` never touched, where it left it itself
// two frames ago.
void Walk::startHistory(uint32_t r) {
    const ir::Resource& res = d_.resources[r];
    const ir::Resource& partner = d_.resources[res.partner];
    VkImageLayout entry = VK_IMAGE_LAYOUT_UNDEFINED;
    bool first = true;
    for (uint32_t i = 0; i < res.cellCount; ++i) {
        const EndState& partnerEnd = ends_[partner.cellBase + i];
        const bool fromPartner = res.origin == ir::Origin::HistoryCurrent || partnerEnd.touched;
        const uint32_t fromCell = fromPartner ? partner.cellBase + i : res.cellBase + i;
        const EndState& from = ends_[fromCell];
        Cell& cell = cells_[res.cellBase + i];
        cell.priorLater = false;
        cell.contents = true;
        if (!from.touched) continue;
        cell.layout = from.layout;
        addPrior(cell, from);
        // The image keeps what last frame made visible; re-establishing it
        // would be a barrier that orders nothing.
        cell.vis = endSeen_[fromCell];
        if (res.kind != ResourceKind::Texture) continue;
        if (first) entry = from.layout;
        first = false;
        if (from.layout != entry)
            throw GraphError(ErrorKind::ConflictingAccess, lastUserName(res.partner), res.name,
                             "a history texture must end the frame with every subresource in one layout (the "
                             "executor prepares both images in one layout before the first frame)");
    }
    st_.plan.resources[r].entryLayout = entry;
}

std::string_view Walk::lastUserName(uint32_t r) const {
    const Lifetime& life = st_.lifetimes[r];
    return life.used() ? d_.passes[st_.order[life.last]].name : std::string_view("(none)");
}

// A transient sharing bytes starts after the last uses of every resource
// on any of its bytes, itself included (one queue per heap, so stages
// are all that matter). Per heap: cut the bytes at every placement
// boundary, OR each resource's last uses into the pieces it covers, then
// OR back over each resource's pieces: piece by piece when members span
// a few pieces each (the usual packing), else through a segment tree
// over the pieces (bottom-up, 2 x pieces nodes: OR is commutative, so
// any size works), O(n log n) however many placements overlap.
void Walk::startAliased() {
    std::vector<std::vector<uint32_t>>& members = scratch_.heapMembers;
    members.resize(st_.plan.heaps.size());
    for (auto& list : members) list.clear();
    for (uint32_t r = 0; r < d_.resources.size(); ++r)
        if (st_.aliased[r]) members[st_.plan.resources[r].heap].push_back(r);
    std::vector<LastUses>& tree = scratch_.tree;
    std::vector<std::pair<uint32_t, uint32_t>>& pieces = scratch_.pieces;
    for (const std::vector<uint32_t>& list : members) {
        if (list.empty()) continue;
        // The distinct offsets where members begin or end, in order; a
        // piece lies between two neighbours. Placement reuses a few
        // offsets for many members, so the distinct ones are gathered
        // through a hash table first and only they are sorted.
        OffsetIndex& index = scratch_.offsetIndex;
        index.reset();
        for (const uint32_t r : list) {
            const PlannedResource& placed = st_.plan.resources[r];
            index.insert(placed.offset);
            index.insert(placed.offset + placed.size);
        }
        index.number();
        pieces.resize(list.size());
        for (uint32_t i = 0; i < list.size(); ++i) {
            const PlannedResource& placed = st_.plan.resources[list[i]];
            pieces[i] = {index.find(placed.offset), index.find(placed.offset + placed.size)};
        }
        const size_t width = index.count() - 1;
        // Placement packs a heap so that a member usually spans a few
        // pieces: then OR-ing into and out of each piece directly is far
        // cheaper than the tree. The tree bounds the worst case.
        size_t spanned = 0;
        for (const auto& [first, last] : pieces) spanned += last - first;
        if (spanned <= 8 * pieces.size()) {
            tree.assign(width, LastUses{});
            for (size_t i = 0; i < list.size(); ++i) {
                const LastUses last = summary(list[i]);
                for (uint32_t k = pieces[i].first; k < pieces[i].second; ++k) tree[k].merge(last);
            }
            for (size_t i = 0; i < list.size(); ++i) {
                LastUses priors;
                for (uint32_t k = pieces[i].first; k < pieces[i].second; ++k) priors.merge(tree[k]);
                addAliasedPriors(list[i], priors);
            }
            continue;
        }
        // Range-OR updates, pushed down to the pieces.
        tree.assign(2 * width, LastUses{});
        for (size_t i = 0; i < list.size(); ++i) {
            const LastUses last = summary(list[i]);
            for (size_t l = pieces[i].first + width, h = pieces[i].second + width; l < h; l /= 2, h /= 2) {
                if (l & 1) tree[l++].merge(last);
                if (h & 1) tree[--h].merge(last);
            }
        }
        for (size_t n = 1; n < width; ++n) {
            tree[2 * n].merge(tree[n]);
            tree[2 * n + 1].merge(tree[n]);
        }
        // Range-OR queries over the pieces.
        for (size_t n = width - 1; n >= 1; --n) {
            tree[n] = tree[2 * n];
            tree[n].merge(tree[2 * n + 1]);
        }
        for (size_t i = 0; i < list.size(); ++i) {
            LastUses priors;
            for (size_t l = pieces[i].first + width, h = pieces[i].second + width; l < h; l /= 2, h /= 2) {
                if (l & 1) priors.merge(tree[l++]);
                if (h & 1) priors.merge(tree[--h]);
            }
            addAliasedPriors(list[i], priors);
        }
    }
}

// Keeps an aliased transient's priors for resolveFirstUses().
void Walk::addAliasedPriors(uint32_t r, const LastUses& priors) { aliasedPriors_[r] = priors; }

// The last uses of any subresource of `r`: where the walk left its cells.
LastUses Walk::summary(uint32_t r) const {
    const ir::Resource& res = d_.resources[r];
    const uint32_t q = queueIndex(st_.plan.resources[r].queue);
    LastUses out;
    for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) out.merge(lastUsesOf(c, q, r));
    return out;
}

// Where the walk left cell c of transient r, used on queue q only.
LastUses Walk::lastUsesOf(uint32_t c, uint32_t q, uint32_t r) const {
    const Cell& cell = cells_[c];
    const bool written = cell.wQueue >= 0 && cell.wStages;
    if (cell.rStages[q ^ 1] || (written && cell.wQueue != static_cast<int8_t>(q))) [[unlikely]]
        priorsElsewhere(r);
    LastUses out;
    out.rStages = cell.rStages[q];
    if (written) {
        out.wStages = cell.wStages;
        out.wAccess = cell.wAccess;
        out.pending = cell.wPending;
    }
    return out;
}

} // namespace glint::rg::detail::barrier_walk
