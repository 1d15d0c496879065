#pragma once

// State the compile phases hand to each other. Internal to glint_graph.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "graph/compile.h"
#include "graph/ir.h"
#include "graph/plan.h"

namespace glint::rg::detail {

struct Lifetime {
    uint32_t first = kNoIndex; // schedule positions of the first and last use
    uint32_t last = 0;
    uint8_t queues = 0;  // bit per assigned queue that uses it
    AccessSet kinds = 0; // every access kind it is used with
    bool used() const { return first != kNoIndex; }
    bool crossQueue() const { return queues == 3; }
};

struct CompileState {
    CompileState(const ir::Declaration& d, const QueueCaps& c, const CompileOptions& o, Plan& p)
        : decl(d), caps(c), options(o), plan(p) {}

    const ir::Declaration& decl;
    const QueueCaps& caps;
    const CompileOptions& options;
    Plan& plan;
    bool log = false; // spdlog at debug level: explain decisions

    // cull
    std::vector<uint8_t> alive; // per declared pass
    // schedule
    std::vector<uint32_t> order;    // declared pass indices in execution order
    std::vector<uint32_t> position; // per declared pass: index into order, kNoIndex when culled
    std::vector<Queue> queueOf;     // per declared pass: assigned queue
    bool queueActive[kQueueCount] = {false, false};
    // lifetimes
    std::vector<Lifetime> lifetimes; // per resource
    // alias: transients whose bytes some other transient also uses
    std::vector<uint8_t> aliased; // per resource
    // barriers -> batches
    std::vector<uint32_t> barrierFirst; // per schedule position
    std::vector<uint32_t> barrierCount;
    std::vector<uint32_t> plannedIndex; // per schedule position: index into plan.passes

    // Which queue a boundary state's work is on: its declared queue as
    // assigned, or the other queue when the assigned one runs nothing in this
    // plan (an idle queue holds no work of ours to synchronise with).
    Queue boundaryQueue(Queue declared) const {
        Queue q = declared == Queue::AsyncCompute && caps.separateComputeFamily ? Queue::AsyncCompute : Queue::Graphics;
        const Queue other = q == Queue::Graphics ? Queue::AsyncCompute : Queue::Graphics;
        if (!queueActive[static_cast<uint32_t>(q)] && queueActive[static_cast<uint32_t>(other)]) q = other;
        return q;
    }
};

// A barrier in words, for logs and Plan::toText().
std::string describeBarrier(std::string_view resource, const Barrier& barrier, ResourceKind kind);

void cull(CompileState& state);
void schedule(CompileState& state);
void assignQueues(CompileState& state);
void computeLifetimes(CompileState& state);
void aliasMemory(CompileState& state);
void placeBarriersAndBatches(CompileState& state);

inline uint32_t queueIndex(Queue q) { return static_cast<uint32_t>(q); }
inline Queue otherQueue(Queue q) { return q == Queue::Graphics ? Queue::AsyncCompute : Queue::Graphics; }

} // namespace glint::rg::detail
