#pragma once

// State the compile phases hand to each other. Internal to glint_graph.

#include <bit>
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "glint/graph/compile.h"
#include "glint/graph/ir.h"
#include "glint/graph/plan.h"

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
    // Imports, history halves and transients used on both queues, in
    // declaration order: the resources whose state at the frame's start is
    // known before the barrier walk (every other one is a transient on one
    // queue, which starts where the walk leaves it).
    std::vector<uint32_t> startKnown;
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

// Stable LSD radix sort by an unsigned 64-bit key, 8 bits a pass and only
// as many passes as the keys' set bits span. The alias phase sorts each
// heap's distinct byte offsets, thousands in a frame that reuses little;
// comparison sorts spent most of their time on mispredicted branches there.
// One read counts every digit at once, and a digit all keys share (one
// bucket holds them all) orders nothing, so its scatter is skipped.
template <class T, class Key>
void radixSort(std::vector<T>& items, std::vector<T>& scratch, Key key) {
    constexpr uint32_t kBits = 8, kBuckets = 1u << kBits, kDigits = 64 / kBits;
    // Small graphs: clearing the buckets would cost more than the sort.
    if (items.size() < 4 * kBuckets) {
        std::stable_sort(items.begin(), items.end(), [&](const T& a, const T& b) { return key(a) < key(b); });
        return;
    }
    uint64_t largest = 0;
    for (const T& item : items) largest |= key(item);
    if (largest == 0) return;
    // Bits below the lowest one any key sets order nothing: byte offsets
    // are aligned, so this saves a pass or two.
    const auto low = static_cast<uint32_t>(std::countr_zero(largest));
    const uint32_t digits = std::min(kDigits, (static_cast<uint32_t>(std::bit_width(largest)) - low + kBits - 1) / kBits);
    uint32_t count[kDigits][kBuckets] = {};
    for (const T& item : items) {
        const uint64_t k = key(item) >> low;
        for (uint32_t d = 0; d < digits; ++d) ++count[d][(k >> (d * kBits)) & (kBuckets - 1)];
    }
    scratch.resize(items.size());
    const auto n = static_cast<uint32_t>(items.size());
    for (uint32_t d = 0; d < digits; ++d) {
        const uint32_t shift = low + d * kBits;
        uint32_t sum = 0;
        bool trivial = false;
        for (uint32_t& c : count[d]) {
            const uint32_t m = c;
            trivial = trivial || m == n;
            c = sum;
            sum += m;
        }
        if (trivial) continue;
        for (const T& item : items) scratch[count[d][(key(item) >> shift) & (kBuckets - 1)]++] = item;
        items.swap(scratch);
    }
}

inline uint32_t queueIndex(Queue q) { return static_cast<uint32_t>(q); }
inline Queue otherQueue(Queue q) { return q == Queue::Graphics ? Queue::AsyncCompute : Queue::Graphics; }

} // namespace glint::rg::detail
