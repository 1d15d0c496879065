#include "plan_view.h"

#include "glint/graph/access.h"

#include <algorithm>

namespace glint::viewer {

namespace {

std::string accessNames(rg::AccessSet kinds) {
    std::string out;
    for (uint32_t k = 0; k < rg::kAccessCount; ++k) {
        if (!(kinds & (1u << k))) continue;
        if (!out.empty()) out += "+";
        out += rg::toString(static_cast<rg::Access>(k));
    }
    return out;
}

} // namespace

PlanView planView(const rg::Plan& plan, std::span<const rg::PassTiming> timings) {
    PlanView view;
    view.transientBytes = plan.stats.transientBytes;
    view.aliasedBytes = plan.stats.aliasedTransientBytes;
    view.culled = plan.stats.culledPasses;
    for (uint32_t b = 0; b < plan.batches.size(); ++b) {
        const rg::Batch& batch = plan.batches[b];
        bool first = true;
        for (const rg::PlannedPass& p : plan.passesOf(batch)) {
            PlanViewPass row;
            row.name = std::string(plan.passName(p));
            row.batch = b;
            row.batchStart = first;
            if (first) {
                for (const rg::SemaphoreWait& w : plan.waitsOf(batch)) {
                    row.waits.push_back({w.queue, w.batch, w.frameOffset < 0});
                }
            }
            first = false;
            row.barriers = p.barrierCount;
            for (const rg::Barrier& barrier : plan.barriersBefore(p)) {
                row.barrierList.push_back({std::string(plan.resourceName(barrier.resource)), barrier.srcStages,
                                           barrier.dstStages, barrier.srcAccess, barrier.dstAccess,
                                           barrier.oldLayout, barrier.newLayout, barrier.aliasing});
            }
            for (const rg::PassTiming& t : timings) {
                if (t.name == row.name) row.milliseconds = t.milliseconds;
            }
            for (const rg::ir::Use& u : plan.uses(p)) {
                row.uses.push_back({std::string(plan.resourceName(u.resource)), accessNames(u.kinds), u.writes});
            }
            view.lanes[p.queue == rg::Queue::AsyncCompute ? 1 : 0].push_back(std::move(row));
        }
    }
    for (const rg::MemoryHeap& h : plan.heaps) view.heaps.push_back({h.queue, h.size, {}});
    for (uint32_t r = 0; r < plan.resources.size(); ++r) {
        const rg::PlannedResource& res = plan.resources[r];
        if (res.origin != rg::ir::Origin::Transient || !res.used || res.heap >= view.heaps.size()) continue;
        view.heaps[res.heap].placements.push_back(
            {std::string(plan.resourceName(r)), res.offset, res.size, res.firstPass, res.lastPass, {}});
    }
    for (PlanViewHeap& heap : view.heaps) {
        std::sort(heap.placements.begin(), heap.placements.end(),
                  [](const PlanViewPlacement& a, const PlanViewPlacement& b) {
                      return a.offset != b.offset ? a.offset < b.offset : a.firstPass < b.firstPass;
                  });
        // Placements whose bytes overlap live at different times: aliases.
        for (PlanViewPlacement& a : heap.placements) {
            for (const PlanViewPlacement& b : heap.placements) {
                if (&a == &b) continue;
                if (a.offset < b.offset + b.size && b.offset < a.offset + a.size) a.aliases.push_back(b.resource);
            }
        }
    }
    return view;
}

} // namespace glint::viewer
