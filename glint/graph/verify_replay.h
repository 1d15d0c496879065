#pragma once

// The verifier's replay, shared by verify.cpp (the replay's reporting, the
// plan's shape checked before it, and verify() itself) and
// verify_replay.cpp (frames replayed: semaphores, barriers and uses against
// the model of Vulkan's synchronisation rules, and the imports' final
// states). Internal to glint_graph: nothing else includes it.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "glint/graph/access.h"
#include "glint/graph/verify.h"

namespace glint::rg::verify_replay {

using Kind = Violation::Kind;

constexpr int64_t kNever = std::numeric_limits<int64_t>::max();

// ---- State ----------------------------------------------------------------------------

struct Vis {
    VkPipelineStageFlags2 stages;
    VkAccessFlags2 access;
};

struct Event {
    uint8_t queue = 0;
    uint32_t frame = 0;
    uint32_t pass = kNoIndex;    // planned pass, or kNoIndex for a boundary state / transition
    uint32_t barrier = kNoIndex; // the barrier of a transition
    VkPipelineStageFlags2 stages = 0;
    VkAccessFlags2 access = 0;
    bool available = false;
    VkPipelineStageFlags2 chain[kQueueCount] = {0, 0};    // stages on each queue ordered after this
    VkPipelineStageFlags2 ownChain[kQueueCount] = {0, 0}; // the same, through this resource's own barriers
    std::vector<Vis> visible[kQueueCount];
    std::vector<Vis> ownVisible[kQueueCount];
    int64_t signalled[kQueueCount] = {kNever, kNever}; // first signal on each queue that covers it
};

struct Cell {
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    bool layoutLost = false; // another resource took the memory: no layout can be assumed
    bool contents = false;
    bool hasWrite = false;
    Event write;
    std::vector<Event> reads;
};

class Replay {
public:
    Replay(const Plan& plan, const VerifyOptions& options, VerifyReport& report)
        : plan_(plan), d_(*plan.declaration), options_(options), report_(report) {}

    void run();

private:
    // ---- Reporting, the plan's shape (verify.cpp) ---------------------------------

    void fail(Kind kind, uint32_t frame, std::string message);
    std::string passName(uint32_t planned) const;
    std::string describe(const Event& e) const;
    std::string barrierWhere(uint32_t b) const;
    std::string cellName(uint32_t resource, uint32_t cell) const;
    bool checkStructure();
    void expectWriters();
    void buildSegments();

    // ---- Frames, semaphores, barriers, uses, frame end (verify_replay.cpp) --------

    uint32_t physical(uint32_t resource, uint32_t frame) const;
    Queue boundaryQueue(Queue declared) const;
    uint32_t lastOrdinal(Queue q) const;
    void startFrame(uint32_t f);
    void replayFrame(uint32_t f);
    void checkOrder(uint32_t planned, uint32_t u, uint32_t f);
    static std::vector<Event*> events(Cell& c);
    template <class F>
    void forEachEvent(F&& f);
    void signal(uint32_t q, uint32_t ordinal, uint32_t f);
    void wait(uint32_t q, const SemaphoreWait& w, uint32_t f);

    struct Scoped {
        VkPipelineStageFlags2 src, dst;
        VkAccessFlags2 srcAccess, dstAccess;
    };

    static bool inScope(const Event& e, uint32_t q, VkPipelineStageFlags2 src);
    template <class F>
    void forBarrierCells(const Barrier& b, uint32_t f, F&& fn);
    std::vector<uint32_t> previousOwners(uint32_t phys) const;
    void claim(uint32_t phys);
    void applyBarriers(uint32_t first, uint32_t count, uint32_t q, uint32_t f, bool frameEnd = false);
    void checkTransitionPriors(Cell& cell, uint32_t q, const Scoped& s, bool memoryReaches, uint32_t barrier,
                               uint32_t phys, uint32_t c, uint32_t f);
    void use(uint32_t planned, Pipeline pipeline, const ir::Use& u, uint32_t q, uint32_t f);
    void checkFinalStates(Queue queue, uint32_t f, bool hasBatch);

    template <class F>
    static void forCells(const ir::Resource& r, const Subresource& range, F&& fn) {
        if (r.kind != ResourceKind::Texture) {
            fn(r.cellBase);
            return;
        }
        for (uint32_t m = range.baseMip; m < range.baseMip + range.mipCount; ++m)
            for (uint32_t l = range.baseLayer; l < range.baseLayer + range.layerCount; ++l) fn(ir::cellOf(r, m, l));
    }

    const Plan& plan_;
    const ir::Declaration& d_;
    const VerifyOptions& options_;
    VerifyReport& report_;
    std::vector<Cell> cells_;
    std::vector<uint8_t> useful_;
    std::vector<std::vector<uint32_t>> expected_; // per use, per cell: the writing pass (declaration index)
    // Per use: a cell's declared writer is skipped (PlannedPass::skipped),
    // so the use may find older or discarded contents (Builder::skip).
    std::vector<uint8_t> staleAllowed_;
    std::vector<uint32_t> writer_;                // per cell: last writer in the replay of this frame
    std::vector<std::vector<uint32_t>> segmentsOf_;
    std::vector<uint32_t> owner_;
    int64_t signalled_[kQueueCount] = {-1, -1};
};

} // namespace glint::rg::verify_replay
