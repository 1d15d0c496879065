#include "glint/graph/compile.h"

#include <spdlog/spdlog.h>

#include "glint/graph/compile_state.h"
#include "glint/graph/error.h"
#include "glint/graph/graph.h"

namespace glint::rg {
namespace {

// The phases' per-pass and per-resource vectors, kept from one compile to
// the next on this thread: a frame loop compiles every frame, and
// allocating them afresh each time cost more than most phases' work. Every
// phase sizes what it uses with assign()/clear(), so nothing stale leaks
// from the previous compile.
struct Scratch {
    std::vector<uint8_t> alive;
    std::vector<uint32_t> order;
    std::vector<uint32_t> position;
    std::vector<Queue> queueOf;
    std::vector<detail::Lifetime> lifetimes;
    std::vector<uint32_t> startKnown;
    std::vector<uint8_t> aliased;
    std::vector<uint32_t> barrierFirst;
    std::vector<uint32_t> barrierCount;
    std::vector<uint32_t> plannedIndex;
};

void swapVectors(Scratch& s, detail::CompileState& st) {
    s.alive.swap(st.alive);
    s.order.swap(st.order);
    s.position.swap(st.position);
    s.queueOf.swap(st.queueOf);
    s.lifetimes.swap(st.lifetimes);
    s.startKnown.swap(st.startKnown);
    s.aliased.swap(st.aliased);
    s.barrierFirst.swap(st.barrierFirst);
    s.barrierCount.swap(st.barrierCount);
    s.plannedIndex.swap(st.plannedIndex);
}

// Lends the scratch vectors to a CompileState for one compile and takes
// them back afterwards, also when a phase throws.
class LentScratch {
public:
    explicit LentScratch(detail::CompileState& st) : st_(st) { swapVectors(scratch(), st_); }
    ~LentScratch() { swapVectors(scratch(), st_); }
    LentScratch(const LentScratch&) = delete;
    LentScratch& operator=(const LentScratch&) = delete;

private:
    static Scratch& scratch() {
        thread_local Scratch s;
        return s;
    }
    detail::CompileState& st_;
};

} // namespace

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
    graph.mayBeShared_.store(true, std::memory_order_relaxed);
    plan.stats.declaredPasses = static_cast<uint32_t>(graph.decl_->passes.size());

    // An import the graph must leave in a final state has to start from a
    // known one, used or not: moving it from an unknown state races
    // whatever last touched it (the previous frame's own move, for one).
    for (const ir::Resource& r : graph.decl_->resources) {
        if (r.origin == ir::Origin::Imported && r.hasFinal && !r.hasInitial &&
            (r.final.isRaw || r.final.access != Access::None)) [[unlikely]] {
            throw GraphError(ErrorKind::ImportWithoutState, "(graph)", std::string(r.name),
                             "was imported with a final state but no initial state; the graph cannot move it from "
                             "an unknown state");
        }
    }

    detail::CompileState state{*graph.decl_, caps, options, plan};
    state.log = spdlog::should_log(spdlog::level::debug);
    const LentScratch lent(state);

    detail::cull(state);
    detail::schedule(state);
    detail::assignQueues(state);
    detail::computeLifetimes(state);
    detail::aliasMemory(state);
    detail::placeBarriersAndBatches(state);

    // Lifetimes in planned-pass indices, now that the passes have them.
    const detail::Lifetime* const lifetimes = state.lifetimes.data();
    const uint32_t* const plannedIndex = state.plannedIndex.data();
    const auto resourceCount = static_cast<uint32_t>(plan.resources.size());
    for (uint32_t r = 0; r < resourceCount; ++r) {
        const detail::Lifetime& life = lifetimes[r];
        if (!life.used()) continue;
        plan.resources[r].firstPass = plannedIndex[life.first];
        plan.resources[r].lastPass = plannedIndex[life.last];
    }
    plan.stats.culledPasses = static_cast<uint32_t>(plan.culled.size());

    if (state.log)
        spdlog::debug("rg compile: {} passes ({} culled), {} batches, {} barriers, {} waits, transients {} -> {} bytes",
                      plan.passes.size(), plan.culled.size(), plan.batches.size(), plan.barriers.size(),
                      plan.waits.size(), plan.stats.transientBytes, plan.stats.aliasedTransientBytes);
    return plan;
}

} // namespace glint::rg
