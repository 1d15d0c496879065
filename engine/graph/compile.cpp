#include "graph/compile.h"

#include <spdlog/spdlog.h>

#include "graph/compile_state.h"
#include "graph/graph.h"

namespace glint::rg {

Plan compile(const Graph& graph, const QueueCaps& caps, const CompileOptions& options, Plan&& recycled) {
    Plan plan = std::move(recycled);
    plan.declaration.reset();
    plan.passes.clear();
    plan.batches.clear();
    plan.barriers.clear();
    plan.waits.clear();
    plan.resources.clear();
    plan.heaps.clear();
    plan.culled.clear();
    plan.stats = {};
    plan.caps = caps;
    plan.declaration = graph.decl_;
    plan.stats.declaredPasses = static_cast<uint32_t>(graph.decl_->passes.size());

    detail::CompileState state{*graph.decl_, caps, options, plan};
    state.log = spdlog::should_log(spdlog::level::debug);

    detail::cull(state);
    detail::schedule(state);
    detail::assignQueues(state);
    detail::computeLifetimes(state);
    detail::aliasMemory(state);
    detail::placeBarriersAndBatches(state);

    // Lifetimes in planned-pass indices, now that the passes have them.
    for (uint32_t r = 0; r < plan.resources.size(); ++r) {
        const detail::Lifetime& life = state.lifetimes[r];
        if (!life.used()) continue;
        plan.resources[r].firstPass = state.plannedIndex[life.first];
        plan.resources[r].lastPass = state.plannedIndex[life.last];
    }
    plan.stats.culledPasses = static_cast<uint32_t>(plan.culled.size());

    if (state.log)
        spdlog::debug("rg compile: {} passes ({} culled), {} batches, {} barriers, {} waits, transients {} -> {} bytes",
                      plan.passes.size(), plan.culled.size(), plan.batches.size(), plan.barriers.size(),
                      plan.waits.size(), plan.stats.transientBytes, plan.stats.aliasedTransientBytes);
    return plan;
}

} // namespace glint::rg
