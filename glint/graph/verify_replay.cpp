// The verifier's replay of a Plan's frames (verify.cpp checks its shape
// first and says what the replay is for): per cell, the last write and the
// reads since, each with the stages it is ordered before and the accesses
// it is visible to on each queue; semaphores, barriers and uses update
// them, and each use and each import's final state is judged against them.

#include <algorithm>
#include <string>

#include "glint/graph/verify_replay.h"
#include "glint/graph/verify_rules.h"

namespace glint::rg::verify_replay {
namespace {

// ---- Flags, meta bits expanded ---------------------------------------------------

constexpr VkPipelineStageFlags2 kDeviceStages =
    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT |
    VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
    VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT |
    VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
    VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_BLIT_BIT | VK_PIPELINE_STAGE_2_RESOLVE_BIT |
    VK_PIPELINE_STAGE_2_CLEAR_BIT | VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR |
    VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR;

constexpr VkPipelineStageFlags2 kGraphicsStages =
    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT |
    VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
    VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT |
    VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;

VkPipelineStageFlags2 expandStages(VkPipelineStageFlags2 s) {
    if (s & (VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT |
             VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT))
        s |= kDeviceStages;
    if (s & VK_PIPELINE_STAGE_2_ALL_GRAPHICS_BIT) s |= kGraphicsStages;
    if (s & VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT)
        s |= VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_BLIT_BIT | VK_PIPELINE_STAGE_2_RESOLVE_BIT |
             VK_PIPELINE_STAGE_2_CLEAR_BIT;
    if (s & VK_PIPELINE_STAGE_2_VERTEX_INPUT_BIT)
        s |= VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT | VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT;
    if (s & VK_PIPELINE_STAGE_2_PRE_RASTERIZATION_SHADERS_BIT)
        s |= VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT |
             VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT | VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT;
    // HOST is no device stage (ALL_COMMANDS does not include it) but a final
    // state may name it: the host reads a result after waiting for the frame.
    // A semaphore or fence wait does not make device writes visible to the
    // host; only a barrier to HOST does, so the model keeps the bit.
    return s & (kDeviceStages | VK_PIPELINE_STAGE_2_HOST_BIT);
}

constexpr VkAccessFlags2 kReadBits =
    VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_INDEX_READ_BIT | VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT |
    VK_ACCESS_2_UNIFORM_READ_BIT | VK_ACCESS_2_INPUT_ATTACHMENT_READ_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT |
    VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_BINDING_TABLE_READ_BIT_KHR |
    VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
    VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_HOST_READ_BIT | VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR;
constexpr VkAccessFlags2 kWriteBits = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
                                      VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;

VkAccessFlags2 expandAccess(VkAccessFlags2 a) {
    if (a & VK_ACCESS_2_SHADER_READ_BIT)
        a |= VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
             VK_ACCESS_2_SHADER_BINDING_TABLE_READ_BIT_KHR;
    if (a & VK_ACCESS_2_SHADER_WRITE_BIT) a |= VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
    if (a & VK_ACCESS_2_MEMORY_READ_BIT) a |= kReadBits;
    if (a & VK_ACCESS_2_MEMORY_WRITE_BIT) a |= kWriteBits;
    return a & (kReadBits | kWriteBits);
}

bool within(VkFlags64 inner, VkFlags64 outer) { return (inner & ~outer) == 0; }

// Every stage bit of `stages` must see every access bit of `access`
// through some pair.
bool covers(const std::vector<Vis>& pairs, VkPipelineStageFlags2 stages, VkAccessFlags2 access) {
    for (VkPipelineStageFlags2 rest = stages; rest; rest &= rest - 1) {
        const VkPipelineStageFlags2 bit = rest & (~rest + 1);
        VkAccessFlags2 seen = 0;
        for (const Vis& p : pairs)
            if (p.stages & bit) seen |= p.access;
        if (!within(access, seen)) return false;
    }
    return true;
}

int64_t timelineKey(int64_t frame, uint32_t ordinal) { return (frame + 1) * (int64_t{1} << 32) + ordinal; }

} // namespace

// ---- Frames ---------------------------------------------------------------------------

// History halves swap images each frame; everything else is itself.
uint32_t Replay::physical(uint32_t resource, uint32_t frame) const {
    const ir::Resource& r = d_.resources[resource];
    if (r.partner == kNoIndex || frame % 2 == 0) return resource;
    return r.partner;
}

Queue Replay::boundaryQueue(Queue declared) const {
    Queue q =
        declared == Queue::AsyncCompute && plan_.caps.separateComputeFamily ? Queue::AsyncCompute : Queue::Graphics;
    if (lastOrdinal(q) == kNoIndex) {
        const Queue other = q == Queue::Graphics ? Queue::AsyncCompute : Queue::Graphics;
        bool otherRunsPasses = false;
        bool ownRunsPasses = false;
        for (const PlannedPass& p : plan_.passes) {
            otherRunsPasses = otherRunsPasses || p.queue == other;
            ownRunsPasses = ownRunsPasses || p.queue == q;
        }
        if (!ownRunsPasses && otherRunsPasses) q = other;
    }
    return q;
}

uint32_t Replay::lastOrdinal(Queue q) const {
    uint32_t last = kNoIndex;
    for (const Batch& b : plan_.batches)
        if (b.queue == q) last = b.ordinal;
    return last;
}

void Replay::startFrame(uint32_t f) {
    // The plan orders a frame after the previous one through that frame's
    // end (its last batches), never through its intermediate waits; for
    // judging redundancy, cross-queue order carried over from them is not
    // the resource's own.
    forEachEvent([&](Event& e, bool) {
        for (uint32_t q = 0; q < kQueueCount; ++q) {
            if (q == e.queue) continue;
            e.ownChain[q] = 0;
            e.ownVisible[q].clear();
        }
    });
    for (uint32_t r = 0; r < d_.resources.size(); ++r) {
        const ir::Resource& res = d_.resources[r];
        switch (res.origin) {
            case ir::Origin::Transient:
                break; // memory and state persist; contents are whatever the last user left
            case ir::Origin::HistoryPrevious:
            case ir::Origin::HistoryCurrent:
                if (f == 0) {
                    // The executor clears both images into their half's entry layout.
                    for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
                        cells_[c] = Cell{};
                        cells_[c].layout = plan_.resources[r].entryLayout;
                        cells_[c].contents = true;
                    }
                }
                break;
            case ir::Origin::Imported: {
                // The same object frame after frame when the plan hands its state
                // to itself; a state with no stages hands over nothing (the caller
                // orders the next frame's use, e.g. by waiting on the host).
                const bool persistent = res.hasInitial && res.hasFinal && res.initial == res.final &&
                                        boundaryScope(res.final, res.kind).stages != 0;
                if (f > 0 && persistent) break;
                if (!res.hasInitial) break;
                const SyncScope s = boundaryScope(res.initial, res.kind);
                const Queue q = boundaryQueue(res.initial.queue);
                const uint32_t last = lastOrdinal(q);
                for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
                    Cell& cell = cells_[c];
                    cell = Cell{};
                    cell.layout = s.layout;
                    cell.contents = res.contentsAtStart;
                    if (!s.stages) continue;
                    Event e;
                    e.queue = static_cast<uint8_t>(q);
                    e.frame = f;
                    e.stages = expandStages(s.stages);
                    e.access = expandAccess(s.access);
                    // Done by the previous frame's last batch on that queue.
                    e.signalled[static_cast<uint32_t>(q)] =
                        timelineKey(static_cast<int64_t>(f) - 1, last == kNoIndex ? 0 : last);
                    if (e.access & kWriteBits) {
                        e.access &= kWriteBits;
                        cell.hasWrite = true;
                        cell.write = e;
                        continue;
                    }
                    cell.reads.push_back(e);
                    if (!cell.contents) continue;
                    // A read state says the contents are visible to that read:
                    // their writer is ordered before its stages, and no further.
                    Event writer = e;
                    writer.stages = 0;
                    writer.access = 0;
                    writer.available = true;
                    writer.chain[static_cast<uint32_t>(q)] = writer.ownChain[static_cast<uint32_t>(q)] = e.stages;
                    writer.visible[static_cast<uint32_t>(q)].push_back({e.stages, e.access});
                    writer.ownVisible[static_cast<uint32_t>(q)].push_back({e.stages, e.access});
                    cell.hasWrite = true;
                    cell.write = writer;
                }
                break;
            }
        }
    }
}

void Replay::replayFrame(uint32_t f) {
    startFrame(f);
    writer_.assign(d_.cellCount, kNoIndex);
    for (uint32_t b = 0; b < plan_.batches.size(); ++b) {
        const Batch& batch = plan_.batches[b];
        const auto q = static_cast<uint32_t>(batch.queue);
        for (const SemaphoreWait& w : plan_.waitsOf(batch)) wait(q, w, f);
        for (uint32_t i = 0; i < batch.passCount; ++i) {
            const uint32_t planned = batch.firstPass + i;
            const PlannedPass& p = plan_.passes[planned];
            applyBarriers(p.firstBarrier, p.barrierCount, q, f);
            // A skipped pass records nothing: no use of its own (its
            // barriers, carried on by skipPasses(), have none left here).
            if (p.skipped) continue;
            const ir::Pass& pass = d_.passes[p.pass];
            for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) checkOrder(planned, u, f);
            for (const ir::Use& u : plan_.uses(p)) use(planned, pass.pipeline, u, q, f);
            for (const ir::Use& u : plan_.uses(p))
                if (u.writes) forCells(d_.resources[u.resource], u.range, [&](uint32_t c) { writer_[c] = p.pass; });
        }
        applyBarriers(batch.firstEndBarrier, batch.endBarrierCount, q, f, true);
        if (batch.ordinal == lastOrdinal(batch.queue)) checkFinalStates(batch.queue, f, true);
        signal(q, batch.ordinal, f);
    }
    for (uint32_t q = 0; q < kQueueCount; ++q)
        if (lastOrdinal(static_cast<Queue>(q)) == kNoIndex) checkFinalStates(static_cast<Queue>(q), f, false);
}

void Replay::checkOrder(uint32_t planned, uint32_t u, uint32_t f) {
    const ir::Use& use = d_.uses[u];
    uint32_t i = 0;
    forCells(d_.resources[use.resource], use.range, [&](uint32_t c) {
        const uint32_t want = expected_[u][i++];
        if (writer_[c] == want) return;
        auto name = [&](uint32_t p) {
            return p == kNoIndex ? std::string("the frame's start") : "'" + std::string(d_.passes[p].name) + "'";
        };
        fail(Kind::Order, f,
             "pass " + passName(planned) + " finds " + cellName(use.resource, c) + " last written by " +
                 name(writer_[c]) + " where its declaration expects " + name(want));
    });
}

std::vector<Event*> Replay::events(Cell& c) {
    std::vector<Event*> out;
    if (c.hasWrite) out.push_back(&c.write);
    for (Event& r : c.reads) out.push_back(&r);
    return out;
}

template <class F>
void Replay::forEachEvent(F&& f) {
    for (Cell& c : cells_) {
        if (c.hasWrite) f(c.write, true);
        for (Event& r : c.reads) f(r, false);
    }
}

// ---- Semaphores ------------------------------------------------------------------------

void Replay::signal(uint32_t q, uint32_t ordinal, uint32_t f) {
    const int64_t key = timelineKey(f, ordinal);
    signalled_[q] = key;
    forEachEvent([&](Event& e, bool) {
        if ((e.queue == q || e.chain[q]) && e.signalled[q] == kNever) e.signalled[q] = key;
    });
}

void Replay::wait(uint32_t q, const SemaphoreWait& w, uint32_t f) {
    const int64_t frame = static_cast<int64_t>(f) + w.frameOffset;
    // The last signal of a queue without batches: what an import's
    // initial state on it was done by (see the frame start).
    const bool lastSignalled = w.batch == SemaphoreWait::kLastSignalled;
    const int64_t key = timelineKey(frame, lastSignalled ? 0 : w.batch);
    const auto from = static_cast<uint32_t>(w.queue);
    if (!lastSignalled && frame >= 0 && signalled_[from] < key) {
        fail(Kind::Deadlock, f,
             "a " + std::string(toString(static_cast<Queue>(q))) + " batch waits on " +
                 std::string(toString(w.queue)) + " batch " + std::to_string(w.batch) + " before it is submitted");
        return;
    }
    const VkPipelineStageFlags2 stages = expandStages(w.stages);
    forEachEvent([&](Event& e, bool isWrite) {
        if (e.signalled[from] > key) return;
        e.chain[q] |= stages;
        if (isWrite) {
            e.available = true;
            e.visible[q].push_back({stages, kReadBits | kWriteBits});
        }
        // Redundancy is judged per resource: order on one queue is its own
        // barriers' job, even when a semaphore round trip through the other
        // queue happens to provide it too.
        if (e.queue == q) return;
        e.ownChain[q] |= stages;
        if (isWrite) e.ownVisible[q].push_back({stages, kReadBits | kWriteBits});
    });
}

// ---- Barriers --------------------------------------------------------------------------

bool Replay::inScope(const Event& e, uint32_t q, VkPipelineStageFlags2 src) {
    return (e.queue == q && (e.stages & src)) || (e.chain[q] & src);
}

template <class F>
void Replay::forBarrierCells(const Barrier& b, uint32_t f, F&& fn) {
    const uint32_t phys = physical(b.resource, f);
    const ir::Resource& r = d_.resources[phys];
    if (r.kind != ResourceKind::Texture) {
        fn(phys, r.cellBase);
        return;
    }
    for (uint32_t m = b.range.baseMip; m < b.range.baseMip + b.range.mipCount; ++m)
        for (uint32_t l = b.range.baseLayer; l < b.range.baseLayer + b.range.layerCount; ++l)
            fn(phys, ir::cellOf(r, m, l));
}

// Cells of the resources that own some of `phys`'s memory now.
std::vector<uint32_t> Replay::previousOwners(uint32_t phys) const {
    std::vector<uint32_t> owners;
    for (uint32_t s : segmentsOf_[phys])
        if (owner_[s] != kNoIndex && owner_[s] != phys &&
            std::find(owners.begin(), owners.end(), owner_[s]) == owners.end())
            owners.push_back(owner_[s]);
    return owners;
}

void Replay::claim(uint32_t phys) {
    for (uint32_t owner : previousOwners(phys)) {
        const ir::Resource& r = d_.resources[owner];
        for (uint32_t c = r.cellBase; c < r.cellBase + r.cellCount; ++c) {
            cells_[c].contents = false;
            cells_[c].layoutLost = true;
        }
    }
    for (uint32_t s : segmentsOf_[phys]) owner_[s] = phys;
}

// One vkCmdPipelineBarrier2: every barrier's first scope is taken before
// any of them takes effect.
// `frameEnd`: the barriers that leave imports in their final states,
// which promise an order to whoever comes next, reader or writer.
void Replay::applyBarriers(uint32_t first, uint32_t count, uint32_t q, uint32_t f, bool frameEnd) {
    if (!count) return;
    struct Transition {
        uint32_t barrier, phys, cell;
    };
    std::vector<Transition> transitions;
    std::vector<Scoped> scoped(count);
    for (uint32_t i = 0; i < count; ++i) {
        const Barrier& b = plan_.barriers[first + i];
        scoped[i] = {expandStages(b.srcStages), expandStages(b.dstStages), expandAccess(b.srcAccess),
                     expandAccess(b.dstAccess)};
    }

    // Decide, against the state before the barriers.
    struct Effect {
        Event* event;
        bool isWrite;
        VkPipelineStageFlags2 chain, ownChain;
        bool makeAvailable;
        std::vector<Vis> visible, ownVisible;
    };
    std::vector<Effect> effects;
    for (uint32_t i = 0; i < count; ++i) {
        const uint32_t bi = first + i;
        const Barrier& b = plan_.barriers[bi];
        const Scoped& s = scoped[i];
        const uint32_t phys = physical(b.resource, f);
        const ir::Resource& res = d_.resources[phys];
        const bool globalMemory = b.aliasing || res.kind == ResourceKind::AccelStruct;
        // Ordering a read matters only before a write: the barrier's own
        // accesses, its layout transition, or the next frame's.
        const bool movesLayout = res.kind == ResourceKind::Texture &&
                                 (b.oldLayout != b.newLayout || b.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
        const bool beforeWrite = (s.dstAccess & kWriteBits) != 0 || movesLayout || frameEnd;
        // 1: the barrier's own subresources; 2: those of the resources it
        // takes memory from (it must order their last uses, but their own
        // synchronisation is theirs).
        std::vector<uint8_t> ownCell(d_.cellCount, 0);
        forBarrierCells(b, f, [&](uint32_t, uint32_t c) { ownCell[c] = 1; });
        if (b.aliasing)
            for (uint32_t owner : previousOwners(phys))
                for (uint32_t c = d_.resources[owner].cellBase;
                     c < d_.resources[owner].cellBase + d_.resources[owner].cellCount; ++c)
                    ownCell[c] = 2;
        bool useful = false;

        for (uint32_t c = 0; c < d_.cellCount; ++c) {
            Cell& cell = cells_[c];
            const bool memory = globalMemory || ownCell[c];
            auto consider = [&](Event& e, bool isWrite) {
                Effect eff{&e, isWrite, 0, 0, false, {}, {}};
                if (inScope(e, q, s.src)) {
                    eff.chain = s.dst;
                    if (isWrite && memory) {
                        const bool available = e.available || within(e.access, s.srcAccess);
                        eff.makeAvailable = available && !e.available;
                        if (available) eff.visible.push_back({s.dst, s.dstAccess});
                    }
                }
                // Useful: it orders an event of its own resource further than
                // that resource's own synchronisation had (same-queue order from
                // its barriers, cross-queue order from semaphores).
                if (ownCell[c] && inScope(e, q, s.src)) {
                    const bool ordersMore = (isWrite || beforeWrite) && !within(s.dst, e.ownChain[q]);
                    bool showsMore = false;
                    const bool reachesMemory = e.available || within(e.access, s.srcAccess);
                    if (isWrite && reachesMemory) showsMore = !covers(e.ownVisible[q], s.dst, s.dstAccess);
                    if (ordersMore || showsMore) useful = true;
                    if (ownCell[c] == 1) {
                        eff.ownChain = s.dst;
                        if (isWrite && reachesMemory) eff.ownVisible.push_back({s.dst, s.dstAccess});
                    }
                }
                if (eff.chain || eff.ownChain || eff.makeAvailable) effects.push_back(std::move(eff));
            };
            if (cell.hasWrite) consider(cell.write, true);
            for (Event& r : cell.reads) consider(r, false);
        }

        if (res.kind == ResourceKind::Texture &&
            (b.oldLayout != b.newLayout || b.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED)) {
            forBarrierCells(b, f, [&](uint32_t p, uint32_t c) {
                Cell& cell = cells_[c];
                if (cell.layout != b.newLayout || cell.layoutLost) useful = true;
                if (b.oldLayout != VK_IMAGE_LAYOUT_UNDEFINED && (cell.layoutLost || cell.layout != b.oldLayout))
                    fail(Kind::Layout, f,
                         "barrier " + barrierWhere(bi) + " moves " + cellName(p, c) + " from " +
                             std::to_string(static_cast<int>(b.oldLayout)) + " but it is in " +
                             (cell.layoutLost ? std::string("no known layout (its memory was aliased)")
                                              : std::to_string(static_cast<int>(cell.layout))));
                checkTransitionPriors(cell, q, s, true, bi, p, c, f);
                if (d_.resources[p].origin == ir::Origin::Transient)
                    for (uint32_t owner : previousOwners(p)) {
                        const ir::Resource& o = d_.resources[owner];
                        for (uint32_t oc = o.cellBase; oc < o.cellBase + o.cellCount; ++oc)
                            checkTransitionPriors(cells_[oc], q, s, b.aliasing, bi, owner, oc, f);
                    }
                transitions.push_back({bi, p, c});
            });
        }
        if (useful) useful_[bi] = 1;
    }

    // Apply.
    for (Effect& eff : effects) {
        Event& e = *eff.event;
        e.chain[q] |= eff.chain;
        e.ownChain[q] |= eff.ownChain;
        if (eff.makeAvailable) e.available = true;
        for (const Vis& v : eff.visible) e.visible[q].push_back(v);
        for (const Vis& v : eff.ownVisible) e.ownVisible[q].push_back(v);
    }
    for (const Transition& t : transitions) {
        const Barrier& b = plan_.barriers[t.barrier];
        const Scoped s{expandStages(b.srcStages), expandStages(b.dstStages), expandAccess(b.srcAccess),
                       expandAccess(b.dstAccess)};
        Cell& cell = cells_[t.cell];
        if (b.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED) cell.contents = false;
        if (d_.resources[t.phys].origin == ir::Origin::Transient) claim(t.phys);
        cell.layout = b.newLayout;
        cell.layoutLost = false;
        Event e;
        e.queue = static_cast<uint8_t>(q);
        e.frame = f;
        e.barrier = t.barrier;
        e.available = true;
        e.chain[q] = e.ownChain[q] = s.dst;
        e.visible[q].push_back({s.dst, s.dstAccess});
        e.ownVisible[q].push_back({s.dst, s.dstAccess});
        cell.hasWrite = true;
        cell.write = std::move(e);
        cell.reads.clear();
    }
}

// A transition writes the cell: earlier reads must be in the barrier's
// first scope, or else the earlier write (in scope and made available).
void Replay::checkTransitionPriors(Cell& cell, uint32_t q, const Scoped& s, bool memoryReaches, uint32_t barrier,
                                   uint32_t phys, uint32_t c, uint32_t f) {
    if (!cell.reads.empty()) {
        for (const Event& r : cell.reads)
            if (!inScope(r, q, s.src))
                fail(Kind::TransitionRace, f,
                     "the layout transition " + barrierWhere(barrier) + " of " + cellName(phys, c) +
                         " is not ordered after the read by " + describe(r));
        return;
    }
    if (!cell.hasWrite) return;
    const Event& w = cell.write;
    const bool available = w.available || (memoryReaches && within(w.access, s.srcAccess));
    if (!inScope(w, q, s.src) || !available)
        fail(Kind::TransitionRace, f,
             "the layout transition " + barrierWhere(barrier) + " of " + cellName(phys, c) +
                 (inScope(w, q, s.src) ? " does not make available the write by "
                                       : " is not ordered after the write by ") +
                 describe(w));
}

// ---- Uses ------------------------------------------------------------------------------

void Replay::use(uint32_t planned, Pipeline pipeline, const ir::Use& u, uint32_t q, uint32_t f) {
    const uint32_t phys = physical(u.resource, f);
    const ir::Resource& r = d_.resources[phys];
    // The verifier's own rules (verify_rules.h), not the compiler's table.
    const verify_rules::Need need = verify_rules::need(u.kinds, r.kind, pipeline);
    const VkPipelineStageFlags2 stages = expandStages(need.stages);
    const VkAccessFlags2 access = expandAccess(need.reads | need.writes);
    const VkAccessFlags2 readBits = access & kReadBits, writeBits = access & kWriteBits;
    // A reader of what a skipped pass would have written may find it gone.
    const bool needsContents = need.needsContents && !staleAllowed_[static_cast<size_t>(&u - d_.uses.data())];
    const std::string who = "pass " + passName(planned);

    auto checkAgainst = [&](Cell& cell, uint32_t cellPhys, uint32_t c) {
        const std::string what = cellName(cellPhys, c);
        if (readBits && cell.hasWrite && cellPhys == phys) {
            const Event& w = cell.write;
            if (!within(stages, w.chain[q]) || !covers(w.visible[q], stages, readBits))
                fail(Kind::ReadAfterWrite, f,
                     who + " reads " + what + " before the write by " + describe(w) + " is " +
                         (within(stages, w.chain[q]) ? "visible to it" : "ordered before it"));
        }
        if (!writeBits) return;
        if (!cell.reads.empty()) {
            for (const Event& rd : cell.reads)
                if (!within(stages, rd.chain[q]))
                    fail(Kind::WriteAfterRead, f,
                         who + " writes " + what + " before the read by " + describe(rd) + " is ordered before it");
        } else if (cell.hasWrite) {
            const Event& w = cell.write;
            if (!within(stages, w.chain[q]) || !covers(w.visible[q], stages, writeBits))
                fail(Kind::WriteAfterWrite, f,
                     who + " writes " + what + " before the write by " + describe(w) + " is " +
                         (within(stages, w.chain[q]) ? "made available to it" : "ordered before it"));
        }
    };

    forCells(r, u.range, [&](uint32_t c) {
        Cell& cell = cells_[c];
        if (r.kind == ResourceKind::Texture && (cell.layoutLost || !need.allows(cell.layout)))
            fail(Kind::Layout, f,
                 who + " uses " + cellName(phys, c) + " in a layout its access does not accept: " +
                     (cell.layoutLost ? std::string("no known layout")
                                      : std::to_string(static_cast<int>(cell.layout))));
        if (needsContents && !cell.contents)
            fail(
                Kind::Contents, f,
                who + " reads " + cellName(phys, c) + ", whose contents were discarded or overwritten by an alias");
        checkAgainst(cell, phys, c);
        if (writeBits && r.origin == ir::Origin::Transient) {
            for (uint32_t owner : previousOwners(phys)) {
                const ir::Resource& o = d_.resources[owner];
                for (uint32_t oc = o.cellBase; oc < o.cellBase + o.cellCount; ++oc)
                    checkAgainst(cells_[oc], owner, oc);
            }
            claim(phys);
        }
        Event e;
        e.queue = static_cast<uint8_t>(q);
        e.frame = f;
        e.pass = planned;
        e.stages = stages;
        if (writeBits) {
            e.access = writeBits;
            cell.hasWrite = true;
            cell.write = std::move(e);
            cell.reads.clear();
            cell.contents = true;
        } else {
            e.access = readBits;
            cell.reads.push_back(std::move(e));
        }
    });
}

// ---- Frame end ------------------------------------------------------------------------

// Each import must end as its final state says: in its layout, with every
// use either described by the state (its queue, within its stages and
// write access) or ordered before it -- and, if it reads, visible to it.
// A layout transition is no use a state can describe: it must be ordered
// before the state's stages (for Present, the semaphore signal's: the
// presentation engine must find the image in PRESENT_SRC).
void Replay::checkFinalStates(Queue queue, uint32_t f, bool hasBatch) {
    const auto q = static_cast<uint32_t>(queue);
    for (uint32_t r = 0; r < d_.resources.size(); ++r) {
        const ir::Resource& res = d_.resources[r];
        if (res.origin != ir::Origin::Imported || !res.hasFinal) continue;
        if (!res.final.isRaw && res.final.access == Access::None) continue;
        if (boundaryQueue(res.final.queue) != queue) continue;
        const SyncScope s = boundaryScope(res.final, res.kind);
        const VkPipelineStageFlags2 stages = expandStages(s.stages);
        const VkAccessFlags2 access = expandAccess(s.access);
        const std::string where = "at the end of frame " + std::to_string(f);
        for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
            Cell& cell = cells_[c];
            if (res.kind == ResourceKind::Texture && s.layout != VK_IMAGE_LAYOUT_UNDEFINED &&
                cell.layout != s.layout)
                fail(Kind::FinalState, f, cellName(r, c) + " is not in its final layout " + where);
            if (!hasBatch || !stages) continue;
            for (const Event& rd : cell.reads) {
                const bool described = rd.queue == q && within(rd.stages, stages);
                if (!described && !within(stages, rd.chain[q]))
                    fail(Kind::FinalState, f,
                         "the read of " + cellName(r, c) + " by " + describe(rd) +
                             " is not ordered before its final state");
            }
            if (!cell.hasWrite) continue;
            const Event& w = cell.write;
            if (w.barrier != kNoIndex) {
                if (!within(stages, w.chain[q]))
                    fail(Kind::FinalState, f,
                         "the layout transition of " + cellName(r, c) + " by barrier " + barrierWhere(w.barrier) +
                             " is not ordered before its final state");
                continue;
            }
            const bool described = w.queue == q && within(w.stages, stages) && within(w.access, access);
            if (described) continue;
            const bool ordered = within(stages, w.chain[q]);
            const bool seen = covers(w.visible[q], stages, access & kReadBits);
            if ((access & kReadBits) && (!ordered || !seen))
                fail(
                    Kind::FinalState, f,
                    "the write of " + cellName(r, c) + " by " + describe(w) + " is not visible to its final state");
            else if (cell.reads.empty() && !ordered)
                fail(Kind::FinalState, f,
                     "the write of " + cellName(r, c) + " by " + describe(w) +
                         " is not ordered before its final state");
        }
    }
}

} // namespace glint::rg::verify_replay
