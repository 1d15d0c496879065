#pragma once

// Submission batches and semaphore placement, driven by the barrier walk.
// Internal to glint_graph.
//
// Each queue has one open batch at a time. A pass that must wait for the
// other queue starts a new batch whose waits sit at its start, so the wait
// delays nothing submitted before that pass; the batch holding what it
// waits for is closed so that its signal covers it. Every batch signals its
// queue's timeline when it completes.

#include <cstdint>
#include <limits>
#include <vector>

#include "glint/graph/compile_state.h"

namespace glint::rg::detail {

// A point on a queue's timeline: batch `ordinal` of this frame (frame 0) or
// of the previous one (frame -1; kLastBatch: the previous frame's last).
struct TimelinePoint {
    static constexpr uint32_t kLastBatch = std::numeric_limits<uint32_t>::max();
    int32_t frame = 0;
    uint32_t ordinal = 0;
};

// A timeline wait reaches everything its point's batch and earlier batches
// signalled, this frame's or the previous one's.
inline bool reaches(TimelinePoint have, TimelinePoint need) {
    return have.frame != need.frame ? have.frame > need.frame : have.ordinal >= need.ordinal;
}

struct WaitRequest {
    bool active = false;
    TimelinePoint point;
    VkPipelineStageFlags2 stages = 0;
};

class BatchBuilder {
public:
    explicit BatchBuilder(CompileState& state);

    // The stages of `waiter` that waits placed so far (in its open batch or
    // earlier) have ordered after `need` on `signaller`: the union over the
    // waits that reach it (each orders its own stages; together, theirs).
    // 0 when none reaches.
    VkPipelineStageFlags2 reachingStages(Queue waiter, Queue signaller, TimelinePoint need) const {
        const std::vector<Reach>& list = byPair_[queueIndex(waiter)][queueIndex(signaller)];
        // Most questions are about a point no wait reaches yet (the latest
        // wait is the furthest) or one every wait reaches.
        if (list.empty() || !reaches(list.back().point, need)) return 0;
        if (reaches(list.front().point, need)) return list.front().suffixStages;
        const std::vector<uint32_t>& first = firstReaching_[queueIndex(waiter)][queueIndex(signaller)];
        if (need.frame == 0 && need.ordinal < first.size()) return list[first[need.ordinal]].suffixStages;
        return reachingStagesSearch(list, need);
    }

    // Puts the pass at schedule position `pos` on `q`, opening a new batch
    // when it has waits to place (waits[i] is on queue i). Returns the
    // ordinal of its batch on `q`.
    uint32_t placePass(Queue q, uint32_t pos, const WaitRequest (&waits)[kQueueCount]);

    // The batch that records the frame's end barriers on `q` (after its last
    // pass; new when waits are needed or the queue has no batch). Returns its
    // ordinal; endBarriers() then assigns the barrier range.
    uint32_t placeEnd(Queue q, const WaitRequest (&waits)[kQueueCount]);
    void setEndBarriers(Queue q, uint32_t first, uint32_t count);

    // The batch ordinal the next pass on q would get without waits.
    uint32_t ordinalOfOpen(Queue q) const;

    // Resolves previous-frame points, orders batches for submission and
    // writes Plan::batches, Plan::passes and Plan::waits.
    void finish();

private:
    struct Build {
        Queue queue;
        uint32_t ordinal;
        uint32_t firstPosition; // schedule position of the first pass; kNoIndex: end barriers only
        uint32_t firstInQueue;  // index into positions_[queue]
        uint32_t passCount = 0;
        uint32_t firstWait = 0;
        uint32_t waitCount = 0;
        uint32_t firstEnd = 0;
        uint32_t endCount = 0;
    };
    struct PlacedWait {
        Queue waiter;
        Queue signaller;
        TimelinePoint point;
        VkPipelineStageFlags2 stages;
    };

    uint32_t open(Queue q, uint32_t firstPosition, const WaitRequest (&waits)[kQueueCount]);
    struct Reach;
    static VkPipelineStageFlags2 reachingStagesSearch(const std::vector<Reach>& list, TimelinePoint need);

    CompileState& st_;
    std::vector<Build> builds_;
    std::vector<PlacedWait> waits_;
    // Per (waiter, signaller), in placement order. A wait is only placed for
    // a point no earlier wait reaches, so points rise along each list: the
    // waits reaching a point are a suffix, found by binary search, whose
    // stages each entry keeps as a union.
    struct Reach {
        TimelinePoint point;
        VkPipelineStageFlags2 suffixStages;
    };
    std::vector<Reach> byPair_[kQueueCount][kQueueCount];
    // Per (waiter, signaller), for this frame's points: ordinal -> index of
    // the first entry of byPair_ that reaches it (the binary search was a
    // few percent of compile, called per hazard).
    std::vector<uint32_t> firstReaching_[kQueueCount][kQueueCount];
    std::vector<uint32_t> positions_[kQueueCount]; // schedule positions per queue, in order
    uint32_t open_[kQueueCount] = {kNoIndex, kNoIndex};
    uint32_t last_[kQueueCount] = {kNoIndex, kNoIndex};
    uint32_t count_[kQueueCount] = {0, 0};
};

} // namespace glint::rg::detail
