// ---- Schedule ---------------------------------------------------------------
// Order: declaration order already respects every data edge (a handle can
// only name a version declared earlier), so it is the schedule unless an
// explicit order() points backwards. Then a topological sort that always
// takes the lowest-declared ready pass keeps independent passes in
// declaration order; passes it cannot place are on a cycle, reported with
// the resources that close it.
//
// Queues: async compute passes go to the compute family when it is
// separate; otherwise to the graphics queue, nothing else changing.

#include <algorithm>
#include <functional>
#include <queue>
#include <string>

#include <spdlog/spdlog.h>

#include "glint/graph/compile_state.h"
#include "glint/graph/error.h"

namespace glint::rg::detail {
namespace {

struct Edge {
    uint32_t from;
    uint32_t to;
    uint32_t resource; // kNoIndex: an explicit order()
};

[[noreturn]] void reportCycle(const CompileState& st, const std::vector<Edge>& edges,
                              const std::vector<uint32_t>& indegree) {
    const ir::Declaration& d = st.decl;
    const auto n = static_cast<uint32_t>(d.passes.size());
    // Walk backwards along edges between unplaced passes until a pass repeats:
    // every unplaced pass has an unplaced predecessor, so this finds a cycle.
    std::vector<std::vector<const Edge*>> incoming(n);
    for (const Edge& e : edges)
        if (indegree[e.from] > 0 && indegree[e.to] > 0) incoming[e.to].push_back(&e);
    uint32_t start = 0;
    while (start < n && (!st.alive[start] || indegree[start] == 0)) ++start;
    std::vector<uint32_t> seenAt(n, kNoIndex);
    std::vector<const Edge*> path;
    uint32_t p = start;
    while (seenAt[p] == kNoIndex) {
        seenAt[p] = static_cast<uint32_t>(path.size());
        const Edge* e = incoming[p].front();
        path.push_back(e);
        p = e->from;
    }
    // path[seenAt[p]..] is the cycle, walked backwards.
    std::vector<const Edge*> cycle(path.begin() + seenAt[p], path.end());
    std::reverse(cycle.begin(), cycle.end());
    std::string detail = "passes wait on each other: '" + std::string(d.passes[cycle.front()->from].name) + "'";
    std::string resource;
    for (const Edge* e : cycle) {
        detail += e->resource == kNoIndex ? " -> (order) -> " : " -> (" + std::string(d.resources[e->resource].name) + ") -> ";
        detail += "'" + std::string(d.passes[e->to].name) + "'";
        if (resource.empty() && e->resource != kNoIndex) resource = d.resources[e->resource].name;
    }
    throw GraphError(ErrorKind::Cycle, d.passes[cycle.front()->from].name, resource, detail);
}

} // namespace

void schedule(CompileState& st) {
    const ir::Declaration& d = st.decl;
    const auto n = static_cast<uint32_t>(d.passes.size());
    bool backwards = false;
    for (const ir::Ordering& o : d.orderings)
        if (st.alive[o.before] && st.alive[o.after] && o.before >= o.after) backwards = true;

    if (!backwards) {
        // Declaration order: one pass writes both the order and the
        // positions, without a branch per pass (culling is data-dependent).
        st.order.resize(n);
        st.position.resize(n);
        uint32_t count = 0;
        for (uint32_t p = 0; p < n; ++p) {
            st.order[count] = p;
            st.position[p] = st.alive[p] ? count : kNoIndex;
            count += st.alive[p];
        }
        st.order.resize(count);
        return;
    }
    st.order.clear();
    st.order.reserve(n);
    st.position.assign(n, kNoIndex);
    std::vector<Edge> edges;
    // Readers of each resource's current version, for write-after-read edges.
    std::vector<std::vector<uint32_t>> readers(d.resources.size());
    for (uint32_t p = 0; p < n; ++p) {
        if (!st.alive[p]) continue;
        const ir::Pass& pass = d.passes[p];
        for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
            const ir::Use& use = d.uses[u];
            if (use.producer != kNoIndex) edges.push_back({use.producer, p, use.resource});
            if (use.writes) {
                for (uint32_t reader : readers[use.resource])
                    if (reader != p) edges.push_back({reader, p, use.resource});
            }
        }
        // Readers are recorded after the pass's own writes so a pass that
        // reads one mip and writes another is not its own predecessor.
        for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
            const ir::Use& use = d.uses[u];
            if (use.writes)
                readers[use.resource].clear();
            else
                readers[use.resource].push_back(p);
        }
    }
    for (const ir::Ordering& o : d.orderings)
        if (st.alive[o.before] && st.alive[o.after]) edges.push_back({o.before, o.after, kNoIndex});

    std::vector<uint32_t> indegree(n, 0);
    std::vector<std::vector<uint32_t>> successors(n);
    for (const Edge& e : edges) {
        ++indegree[e.to];
        successors[e.from].push_back(e.to);
    }
    std::priority_queue<uint32_t, std::vector<uint32_t>, std::greater<>> ready;
    for (uint32_t p = 0; p < n; ++p)
        if (st.alive[p] && indegree[p] == 0) ready.push(p);
    while (!ready.empty()) {
        const uint32_t p = ready.top();
        ready.pop();
        st.order.push_back(p);
        for (uint32_t s : successors[p])
            if (--indegree[s] == 0) ready.push(s);
    }
    uint32_t aliveCount = 0;
    for (uint32_t p = 0; p < n; ++p) aliveCount += st.alive[p];
    if (st.order.size() != aliveCount) reportCycle(st, edges, indegree);
    if (st.log) spdlog::debug("rg schedule: explicit orderings moved passes out of declaration order");
    for (uint32_t i = 0; i < st.order.size(); ++i) st.position[st.order[i]] = i;
}

void assignQueues(CompileState& st) {
    const ir::Declaration& d = st.decl;
    const auto n = static_cast<uint32_t>(d.passes.size());
    st.queueOf.resize(n);
    // Local pointers and flags: the byte-sized stores would otherwise make
    // the compiler reload every vector after each one.
    Queue* const queueOf = st.queueOf.data();
    const uint8_t* const alive = st.alive.data();
    const bool separate = st.caps.separateComputeFamily;
    bool active[kQueueCount] = {false, false};
    for (uint32_t p = 0; p < n; ++p) {
        const Queue q = d.passes[p].queue == Queue::AsyncCompute && separate ? Queue::AsyncCompute : Queue::Graphics;
        queueOf[p] = q;
        active[queueIndex(q)] = active[queueIndex(q)] || alive[p];
    }
    for (uint32_t q = 0; q < kQueueCount; ++q) st.queueActive[q] = st.queueActive[q] || active[q];
    if (!st.log) return;
    for (uint32_t p = 0; p < n; ++p)
        if (alive[p] && d.passes[p].queue != queueOf[p])
            spdlog::debug("rg queues: '{}' runs on graphics (no separate compute family)", d.passes[p].name);
}

} // namespace glint::rg::detail
