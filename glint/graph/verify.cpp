// The verifier: replays a Plan over several frames against a model of
// Vulkan's synchronisation rules (see verify.h). It shares nothing with the
// compiler's barrier walk (barriers.cpp): what each use needs comes from its
// own rules (verify_rules.h), written apart from the compiler's access
// table; only the boundary states' concrete layouts and masks, a convention
// between the graph and its callers, are read from that table.
//
// This file checks the plan's shape before the replay, reports what the
// replay finds and holds verify(); the replay itself (frames, semaphores,
// barriers, uses, final states) is verify_replay.cpp.

#include "glint/graph/verify.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "glint/graph/verify_replay.h"

namespace glint::rg {
namespace verify_replay {

void Replay::run() {
    if (!checkStructure()) return;
    expectWriters();
    cells_.assign(d_.cellCount, Cell{});
    useful_.assign(plan_.barriers.size(), 0);
    buildSegments();
    for (uint32_t f = 0; f < options_.frames; ++f) replayFrame(f);
    // One plan serves every frame: a barrier is redundant only when it does
    // nothing in all of them (the first frame starts from fresh images, the
    // others from the frame before).
    if (options_.checkRedundancy)
        for (uint32_t b = 0; b < plan_.barriers.size(); ++b)
            if (!useful_[b])
                fail(Kind::RedundantBarrier, options_.frames - 1,
                     "barrier on '" + std::string(plan_.resourceName(plan_.barriers[b].resource)) + "' " + barrierWhere(b) +
                         " orders nothing its resource needs in any frame");
}

// ---- Reporting ------------------------------------------------------------------

void Replay::fail(Kind kind, uint32_t frame, std::string message) {
    // One line per distinct problem; the same hazard recurs every frame.
    for (const Violation& v : report_.violations)
        if (v.kind == kind && v.message == message) return;
    report_.violations.push_back({kind, frame, std::move(message)});
}

std::string Replay::passName(uint32_t planned) const {
    return "'" + std::string(plan_.passName(plan_.passes[planned])) + "'";
}

std::string Replay::describe(const Event& e) const {
    std::string who;
    if (e.pass != kNoIndex)
        who = "pass " + passName(e.pass);
    else if (e.barrier != kNoIndex)
        who = "the layout transition " + barrierWhere(e.barrier);
    else
        who = "the frame boundary state";
    return who + " (" + std::string(toString(static_cast<Queue>(e.queue))) + ", frame " + std::to_string(e.frame) +
           ")";
}

std::string Replay::barrierWhere(uint32_t b) const {
    for (uint32_t p = 0; p < plan_.passes.size(); ++p) {
        const PlannedPass& pass = plan_.passes[p];
        if (b >= pass.firstBarrier && b < pass.firstBarrier + pass.barrierCount) return "before " + passName(p);
    }
    return "at the end of the frame";
}

std::string Replay::cellName(uint32_t resource, uint32_t cell) const {
    const ir::Resource& r = d_.resources[resource];
    std::string s = "'" + std::string(r.name) + "'";
    if (r.kind == ResourceKind::Texture && r.cellCount > 1) {
        const uint32_t i = cell - r.cellBase;
        s += " (mip " + std::to_string(i / r.texture.layers) + ", layer " + std::to_string(i % r.texture.layers) +
             ")";
    }
    return s;
}

// ---- Shape ----------------------------------------------------------------------------

bool Replay::checkStructure() {
    bool ok = true;
    auto bad = [&](std::string message) {
        fail(Kind::Structure, 0, std::move(message));
        ok = false;
    };
    std::vector<uint32_t> seen(d_.passes.size(), 0);
    for (uint32_t p : plan_.culled) ++seen[p];
    uint32_t ordinals[kQueueCount] = {0, 0};
    std::vector<uint8_t> timestamps(plan_.timestampQueryCount(), 0);
    for (uint32_t b = 0; b < plan_.batches.size(); ++b) {
        const Batch& batch = plan_.batches[b];
        if (batch.ordinal != ordinals[static_cast<uint32_t>(batch.queue)]++)
            bad("batch " + std::to_string(b) + " is out of order on its queue");
        if (batch.firstPass + batch.passCount > plan_.passes.size() ||
            batch.firstWait + batch.waitCount > plan_.waits.size() ||
            batch.firstEndBarrier + batch.endBarrierCount > plan_.barriers.size()) {
            bad("batch " + std::to_string(b) + " indexes past the plan");
            return false;
        }
        for (uint32_t i = 0; i < batch.passCount; ++i) {
            const PlannedPass& p = plan_.passes[batch.firstPass + i];
            if (p.pass >= d_.passes.size()) {
                bad("planned pass names no declared pass");
                return false;
            }
            ++seen[p.pass];
            if (p.queue != batch.queue || p.batch != b)
                bad("pass " + passName(batch.firstPass + i) + " is not on its batch's queue");
            const Queue declared = d_.passes[p.pass].queue;
            const Queue expected = declared == Queue::AsyncCompute && plan_.caps.separateComputeFamily
                                       ? Queue::AsyncCompute
                                       : Queue::Graphics;
            if (p.queue != expected) bad("pass " + passName(batch.firstPass + i) + " runs on the wrong queue");
            if (p.firstBarrier + p.barrierCount > plan_.barriers.size()) {
                bad("pass barriers index past the plan");
                return false;
            }
            if (p.timestampQuery + 1 >= timestamps.size() || timestamps[p.timestampQuery] ||
                timestamps[p.timestampQuery + 1])
                bad("pass " + passName(batch.firstPass + i) + " shares timestamp queries");
            else
                timestamps[p.timestampQuery] = timestamps[p.timestampQuery + 1] = 1;
        }
        if (batch.firstPass != (b == 0 ? 0 : plan_.batches[b - 1].firstPass + plan_.batches[b - 1].passCount))
            bad("batches do not list the passes in submission order");
    }
    for (uint32_t p = 0; p < d_.passes.size(); ++p)
        if (seen[p] != 1)
            bad("declared pass '" + std::string(d_.passes[p].name) + "' appears " + std::to_string(seen[p]) +
                " times among planned and culled passes");

    // Waits: another queue, an existing batch, submitted before.
    std::vector<uint32_t> count(kQueueCount, 0);
    for (const Batch& batch : plan_.batches) ++count[static_cast<uint32_t>(batch.queue)];
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> submittedAt;
    for (uint32_t b = 0; b < plan_.batches.size(); ++b)
        submittedAt[{static_cast<uint32_t>(plan_.batches[b].queue), plan_.batches[b].ordinal}] = b;
    for (uint32_t b = 0; b < plan_.batches.size(); ++b) {
        const Batch& batch = plan_.batches[b];
        for (const SemaphoreWait& w : plan_.waitsOf(batch)) {
            const auto q = static_cast<uint32_t>(w.queue);
            if (w.queue == batch.queue) bad("batch " + std::to_string(b) + " waits on its own queue");
            if (w.frameOffset != 0 && w.frameOffset != -1) bad("wait frame offset must be 0 or -1");
            if (w.batch == SemaphoreWait::kLastSignalled) {
                // Only where the plan has no batch on that queue to name.
                if (w.frameOffset != -1 || count[q] != 0)
                    bad("batch " + std::to_string(b) + " waits on the last signal of a queue with batches");
                if (!w.stages) bad("batch " + std::to_string(b) + " waits in no stage");
                continue;
            }
            if (w.batch >= count[q]) {
                bad("batch " + std::to_string(b) + " waits on a batch that does not exist");
                continue;
            }
            if (!w.stages) bad("batch " + std::to_string(b) + " waits in no stage");
            if (w.frameOffset == 0 && submittedAt[{q, w.batch}] >= b)
                fail(Kind::Deadlock, 0,
                     "batch " + std::to_string(b) + " waits on " + std::string(toString(w.queue)) + " batch " +
                         std::to_string(w.batch) + ", which is submitted after it");
        }
    }

    // Barriers stay inside their resources; one pass never has two on one subresource.
    for (const Barrier& b : plan_.barriers) {
        if (b.resource >= d_.resources.size()) {
            bad("barrier names no resource");
            return false;
        }
        const ir::Resource& r = d_.resources[b.resource];
        if (r.kind == ResourceKind::Texture && (b.range.mipCount == 0 || b.range.layerCount == 0 ||
                                                b.range.baseMip + b.range.mipCount > r.texture.mips ||
                                                b.range.baseLayer + b.range.layerCount > r.texture.layers)) {
            bad("barrier on '" + std::string(r.name) + "' is outside its subresources");
            return false;
        }
    }
    auto checkMerged = [&](uint32_t first, uint32_t n, const std::string& where) {
        for (uint32_t i = first; i < first + n; ++i)
            for (uint32_t j = i + 1; j < first + n; ++j) {
                const Barrier& a = plan_.barriers[i];
                const Barrier& c = plan_.barriers[j];
                if (a.resource != c.resource) continue;
                const bool overlap = a.range.baseMip < c.range.baseMip + c.range.mipCount &&
                                     c.range.baseMip < a.range.baseMip + a.range.mipCount &&
                                     a.range.baseLayer < c.range.baseLayer + c.range.layerCount &&
                                     c.range.baseLayer < a.range.baseLayer + a.range.layerCount;
                if (overlap)
                    fail(Kind::UnmergedBarriers, 0,
                         "two barriers on one subresource of '" + std::string(plan_.resourceName(a.resource)) + "' " + where);
            }
    };
    for (uint32_t p = 0; p < plan_.passes.size(); ++p)
        checkMerged(plan_.passes[p].firstBarrier, plan_.passes[p].barrierCount, "before " + passName(p));
    for (const Batch& batch : plan_.batches)
        checkMerged(batch.firstEndBarrier, batch.endBarrierCount, "at the end of the frame");

    // Sharing and heaps.
    std::vector<uint8_t> queues(d_.resources.size(), 0);
    for (const PlannedPass& p : plan_.passes)
        for (const ir::Use& u : plan_.uses(p))
            queues[u.resource] |= static_cast<uint8_t>(1u << static_cast<uint32_t>(p.queue));
    for (uint32_t r = 0; r < d_.resources.size(); ++r) {
        const uint8_t both = static_cast<uint8_t>(
            queues[r] | (d_.resources[r].partner != kNoIndex ? queues[d_.resources[r].partner] : 0));
        const PlannedResource& res = plan_.resources[r];
        if (both == 3 && !res.crossQueue)
            bad("'" + std::string(d_.resources[r].name) + "' is used on both queues without concurrent sharing");
        if (d_.resources[r].origin != ir::Origin::Transient || !queues[r]) continue;
        if (res.heap >= plan_.heaps.size()) {
            bad("transient '" + std::string(d_.resources[r].name) + "' has no memory");
            return false;
        }
        const MemoryHeap& heap = plan_.heaps[res.heap];
        if (res.offset + res.size > heap.size || res.offset % res.alignment != 0)
            bad("transient '" + std::string(d_.resources[r].name) + "' does not fit its heap");
        if (heap.crossQueue ? queues[r] != 3 : queues[r] != (1u << static_cast<uint32_t>(heap.queue)))
            bad("transient '" + std::string(d_.resources[r].name) + "' is in a heap of another queue");
    }
    return ok;
}

// Which pass's data each use must find in each subresource: the last
// writer before it in declaration order (versions follow declarations),
// counting the passes that run only. A skipped pass writes nothing, so its
// readers find the writer before it -- or discarded contents, which they
// are allowed (Builder::skip: what they read is the caller's concern).
void Replay::expectWriters() {
    enum : uint8_t { Culled, Runs, Skipped };
    std::vector<uint8_t> state(d_.passes.size(), Culled);
    for (const PlannedPass& p : plan_.passes) state[p.pass] = p.skipped ? Skipped : Runs;
    std::vector<uint32_t> last(d_.cellCount, kNoIndex);
    std::vector<uint8_t> lastSkipped(d_.cellCount, 0);
    expected_.assign(d_.uses.size(), {});
    staleAllowed_.assign(d_.uses.size(), 0);
    for (uint32_t p = 0; p < d_.passes.size(); ++p) {
        if (state[p] == Culled) continue;
        const ir::Pass& pass = d_.passes[p];
        for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
            const ir::Use& use = d_.uses[u];
            forCells(d_.resources[use.resource], use.range, [&](uint32_t c) {
                expected_[u].push_back(last[c]);
                if (lastSkipped[c]) staleAllowed_[u] = 1;
            });
        }
        for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
            const ir::Use& use = d_.uses[u];
            if (!use.writes) continue;
            forCells(d_.resources[use.resource], use.range, [&](uint32_t c) {
                if (state[p] == Runs) last[c] = p;
                lastSkipped[c] = state[p] == Skipped;
            });
        }
    }
}

// Memory of each heap cut at every resource boundary; a segment's owner
// is the resource that last wrote it.
void Replay::buildSegments() {
    segmentsOf_.assign(d_.resources.size(), {});
    std::vector<std::vector<uint32_t>> members(plan_.heaps.size());
    for (uint32_t r = 0; r < d_.resources.size(); ++r) {
        const PlannedResource& res = plan_.resources[r];
        if (d_.resources[r].origin == ir::Origin::Transient && res.used && res.heap < plan_.heaps.size())
            members[res.heap].push_back(r);
    }
    for (const auto& list : members) {
        std::vector<uint64_t> cuts;
        for (uint32_t r : list) {
            cuts.push_back(plan_.resources[r].offset);
            cuts.push_back(plan_.resources[r].offset + plan_.resources[r].size);
        }
        std::sort(cuts.begin(), cuts.end());
        cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
        const auto base = static_cast<uint32_t>(owner_.size());
        for (size_t i = 0; i + 1 < cuts.size(); ++i) owner_.push_back(kNoIndex);
        for (uint32_t r : list) {
            const uint64_t begin = plan_.resources[r].offset, end = begin + plan_.resources[r].size;
            for (size_t i = 0; i + 1 < cuts.size(); ++i)
                if (cuts[i] >= begin && cuts[i + 1] <= end)
                    segmentsOf_[r].push_back(base + static_cast<uint32_t>(i));
        }
    }
}

} // namespace verify_replay

using verify_replay::Kind;

std::string_view toString(Violation::Kind kind) {
    switch (kind) {
        case Kind::Structure:
            return "structure";
        case Kind::Order:
            return "order";
        case Kind::Deadlock:
            return "deadlock";
        case Kind::Layout:
            return "layout";
        case Kind::Contents:
            return "contents";
        case Kind::ReadAfterWrite:
            return "read-after-write";
        case Kind::WriteAfterRead:
            return "write-after-read";
        case Kind::WriteAfterWrite:
            return "write-after-write";
        case Kind::TransitionRace:
            return "transition race";
        case Kind::FinalState:
            return "final state";
        case Kind::RedundantBarrier:
            return "redundant barrier";
        case Kind::UnmergedBarriers:
            return "unmerged barriers";
    }
    return "?";
}

bool VerifyReport::has(Violation::Kind kind) const {
    return std::any_of(violations.begin(), violations.end(), [&](const Violation& v) { return v.kind == kind; });
}

std::string VerifyReport::text() const {
    std::string out;
    for (const Violation& v : violations)
        out += std::string(toString(v.kind)) + " (frame " + std::to_string(v.frame) + "): " + v.message + "\n";
    return out;
}

VerifyReport verify(const Plan& plan, const VerifyOptions& options) {
    VerifyReport report;
    verify_replay::Replay(plan, options, report).run();
    return report;
}

} // namespace glint::rg
