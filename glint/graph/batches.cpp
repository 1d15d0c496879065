// ---- Batches ----------------------------------------------------------------
// Per-queue submission lists and where semaphore waits go (see batches.h).
// Submission order is by each batch's first pass in the schedule: a batch
// only waits on batches closed before its first pass was placed, whose
// passes all come earlier, so every wait names a batch submitted before it.

#include "glint/graph/batches.h"

#include <algorithm>
#include <numeric>

#include <spdlog/spdlog.h>

namespace glint::rg::detail {

BatchBuilder::BatchBuilder(CompileState& state) : st_(state) {
    builds_.reserve(16);
    for (auto& p : positions_) p.reserve(state.order.size());
}

VkPipelineStageFlags2 BatchBuilder::reachingStagesSearch(const std::vector<Reach>& list, TimelinePoint need) {
    const auto first =
        std::partition_point(list.begin(), list.end(), [&](const Reach& r) { return !reaches(r.point, need); });
    return first == list.end() ? 0 : first->suffixStages;
}

uint32_t BatchBuilder::open(Queue q, uint32_t firstPosition, const WaitRequest (&waits)[kQueueCount]) {
    Build b;
    b.queue = q;
    b.ordinal = count_[queueIndex(q)]++;
    b.firstPosition = firstPosition;
    b.firstInQueue = static_cast<uint32_t>(positions_[queueIndex(q)].size());
    b.firstWait = static_cast<uint32_t>(waits_.size());
    for (uint32_t s = 0; s < kQueueCount; ++s) {
        const WaitRequest& w = waits[s];
        if (!w.active) continue;
        const auto signaller = static_cast<Queue>(s);
        std::vector<Reach>& reach = byPair_[queueIndex(q)][s];
        for (Reach& r : reach) r.suffixStages |= w.stages;
        std::vector<uint32_t>& first = firstReaching_[queueIndex(q)][s];
        if (w.point.frame == 0 && w.point.ordinal >= first.size())
            first.resize(size_t{w.point.ordinal} + 1, static_cast<uint32_t>(reach.size()));
        reach.push_back({w.point, w.stages});
        waits_.push_back({q, signaller, w.point, w.stages});
        ++b.waitCount;
        // The batch holding what we wait for signals when it completes: close
        // it so it does not grow past the producer.
        if (w.point.frame == 0 && open_[s] != kNoIndex && builds_[open_[s]].ordinal == w.point.ordinal)
            open_[s] = kNoIndex;
    }
    const auto id = static_cast<uint32_t>(builds_.size());
    builds_.push_back(b);
    open_[queueIndex(q)] = id;
    last_[queueIndex(q)] = id;
    return id;
}

uint32_t BatchBuilder::ordinalOfOpen(Queue q) const {
    const uint32_t id = open_[queueIndex(q)];
    return id != kNoIndex ? builds_[id].ordinal : count_[queueIndex(q)];
}

uint32_t BatchBuilder::placePass(Queue q, uint32_t pos, const WaitRequest (&waits)[kQueueCount]) {
    const bool needsWait = waits[0].active || waits[1].active;
    uint32_t id = open_[queueIndex(q)];
    if (id == kNoIndex || needsWait) {
        id = open(q, pos, waits);
        if (st_.log && needsWait) {
            for (uint32_t s = 0; s < kQueueCount; ++s)
                if (waits[s].active)
                    spdlog::debug(
                        "rg batches: '{}' starts {} batch {}, waiting {} {} batch {}",
                        st_.decl.passes[st_.order[pos]].name, toString(q), builds_[id].ordinal,
                        toString(static_cast<Queue>(s)), waits[s].point.frame < 0 ? "previous frame's" : "this frame's",
                        waits[s].point.ordinal == TimelinePoint::kLastBatch ? std::string("last")
                                                                            : std::to_string(waits[s].point.ordinal));
        }
    }
    positions_[queueIndex(q)].push_back(pos);
    ++builds_[id].passCount;
    return builds_[id].ordinal;
}

uint32_t BatchBuilder::placeEnd(Queue q, const WaitRequest (&waits)[kQueueCount]) {
    const bool needsWait = waits[0].active || waits[1].active;
    uint32_t id = last_[queueIndex(q)];
    // End barriers may join a closed batch: they only extend it before its
    // signal, and nothing they do waits on anything.
    if (id == kNoIndex || needsWait) id = open(q, kNoIndex, waits);
    return builds_[id].ordinal;
}

void BatchBuilder::setEndBarriers(Queue q, uint32_t first, uint32_t count) {
    Build& b = builds_[last_[queueIndex(q)]];
    b.firstEnd = first;
    b.endCount = count;
}

void BatchBuilder::finish() {
    Plan& plan = st_.plan;
    std::vector<uint32_t> submit(builds_.size());
    std::iota(submit.begin(), submit.end(), 0u);
    std::stable_sort(submit.begin(), submit.end(),
                     [&](uint32_t a, uint32_t b) { return builds_[a].firstPosition < builds_[b].firstPosition; });

    plan.batches.reserve(builds_.size());
    plan.passes.reserve(st_.order.size());
    plan.waits.reserve(waits_.size());
    st_.plannedIndex.assign(st_.order.size(), kNoIndex);
    for (uint32_t id : submit) {
        const Build& b = builds_[id];
        Batch out;
        out.queue = b.queue;
        out.ordinal = b.ordinal;
        out.firstPass = static_cast<uint32_t>(plan.passes.size());
        out.passCount = b.passCount;
        out.firstWait = static_cast<uint32_t>(plan.waits.size());
        out.waitCount = b.waitCount;
        out.firstEndBarrier = b.firstEnd;
        out.endBarrierCount = b.endCount;
        for (uint32_t w = b.firstWait; w < b.firstWait + b.waitCount; ++w) {
            const PlacedWait& placed = waits_[w];
            SemaphoreWait wait;
            wait.queue = placed.signaller;
            wait.frameOffset = placed.point.frame;
            if (placed.point.ordinal != TimelinePoint::kLastBatch) {
                wait.batch = placed.point.ordinal;
            } else {
                const uint32_t batches = count_[queueIndex(placed.signaller)];
                wait.batch = batches > 0 ? batches - 1 : SemaphoreWait::kLastSignalled;
            }
            wait.stages = placed.stages;
            plan.waits.push_back(wait);
        }
        const auto batchIndex = static_cast<uint32_t>(plan.batches.size());
        for (uint32_t i = 0; i < b.passCount; ++i) {
            const uint32_t pos = positions_[queueIndex(b.queue)][b.firstInQueue + i];
            PlannedPass p;
            p.pass = st_.order[pos];
            p.queue = b.queue;
            p.batch = batchIndex;
            p.firstBarrier = st_.barrierFirst[pos];
            p.barrierCount = st_.barrierCount[pos];
            p.timestampQuery = static_cast<uint32_t>(plan.passes.size()) * 2;
            st_.plannedIndex[pos] = static_cast<uint32_t>(plan.passes.size());
            plan.passes.push_back(p);
        }
        plan.batches.push_back(out);
    }
}

} // namespace glint::rg::detail
