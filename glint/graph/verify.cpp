// The verifier: replays a Plan over several frames against a model of
// Vulkan's synchronisation rules (see verify.h). It shares nothing with
// barriers.cpp: what each use needs comes from its own rules
// (verify_rules.h), written apart from the compiler's access table; only
// the boundary states' concrete layouts and masks, a convention between the
// graph and its callers, are read from that table.

#include "glint/graph/verify.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

#include "glint/graph/access.h"
#include "glint/graph/verify_rules.h"

namespace glint::rg {
namespace {

using Kind = Violation::Kind;

constexpr int64_t kNever = std::numeric_limits<int64_t>::max();

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

// ---- State ----------------------------------------------------------------------------

struct Vis {
    VkPipelineStageFlags2 stages;
    VkAccessFlags2 access;
};

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

int64_t timelineKey(int64_t frame, uint32_t ordinal) { return (frame + 1) * (int64_t{1} << 32) + ordinal; }

class Replay {
public:
    Replay(const Plan& plan, const VerifyOptions& options, VerifyReport& report)
        : plan_(plan), d_(*plan.declaration), options_(options), report_(report) {}

    void run() {
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

private:
    // ---- Reporting ------------------------------------------------------------------

    void fail(Kind kind, uint32_t frame, std::string message) {
        // One line per distinct problem; the same hazard recurs every frame.
        for (const Violation& v : report_.violations)
            if (v.kind == kind && v.message == message) return;
        report_.violations.push_back({kind, frame, std::move(message)});
    }

    std::string passName(uint32_t planned) const { return "'" + std::string(plan_.passName(plan_.passes[planned])) + "'"; }

    std::string describe(const Event& e) const {
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

    std::string barrierWhere(uint32_t b) const {
        for (uint32_t p = 0; p < plan_.passes.size(); ++p) {
            const PlannedPass& pass = plan_.passes[p];
            if (b >= pass.firstBarrier && b < pass.firstBarrier + pass.barrierCount) return "before " + passName(p);
        }
        return "at the end of the frame";
    }

    std::string cellName(uint32_t resource, uint32_t cell) const {
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

    bool checkStructure() {
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
    // counting surviving passes only.
    void expectWriters() {
        std::vector<uint8_t> alive(d_.passes.size(), 0);
        for (const PlannedPass& p : plan_.passes) alive[p.pass] = 1;
        std::vector<uint32_t> last(d_.cellCount, kNoIndex);
        expected_.assign(d_.uses.size(), {});
        for (uint32_t p = 0; p < d_.passes.size(); ++p) {
            if (!alive[p]) continue;
            const ir::Pass& pass = d_.passes[p];
            for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
                const ir::Use& use = d_.uses[u];
                forCells(d_.resources[use.resource], use.range, [&](uint32_t c) { expected_[u].push_back(last[c]); });
            }
            for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
                const ir::Use& use = d_.uses[u];
                if (use.writes) forCells(d_.resources[use.resource], use.range, [&](uint32_t c) { last[c] = p; });
            }
        }
    }

    // Memory of each heap cut at every resource boundary; a segment's owner
    // is the resource that last wrote it.
    void buildSegments() {
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

    // ---- Frames ---------------------------------------------------------------------------

    // History halves swap images each frame; everything else is itself.
    uint32_t physical(uint32_t resource, uint32_t frame) const {
        const ir::Resource& r = d_.resources[resource];
        if (r.partner == kNoIndex || frame % 2 == 0) return resource;
        return r.partner;
    }

    Queue boundaryQueue(Queue declared) const {
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

    uint32_t lastOrdinal(Queue q) const {
        uint32_t last = kNoIndex;
        for (const Batch& b : plan_.batches)
            if (b.queue == q) last = b.ordinal;
        return last;
    }

    void startFrame(uint32_t f) {
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

    void replayFrame(uint32_t f) {
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

    void checkOrder(uint32_t planned, uint32_t u, uint32_t f) {
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

    static std::vector<Event*> events(Cell& c) {
        std::vector<Event*> out;
        if (c.hasWrite) out.push_back(&c.write);
        for (Event& r : c.reads) out.push_back(&r);
        return out;
    }

    template <class F>
    void forEachEvent(F&& f) {
        for (Cell& c : cells_) {
            if (c.hasWrite) f(c.write, true);
            for (Event& r : c.reads) f(r, false);
        }
    }

    // ---- Semaphores ------------------------------------------------------------------------

    void signal(uint32_t q, uint32_t ordinal, uint32_t f) {
        const int64_t key = timelineKey(f, ordinal);
        signalled_[q] = key;
        forEachEvent([&](Event& e, bool) {
            if ((e.queue == q || e.chain[q]) && e.signalled[q] == kNever) e.signalled[q] = key;
        });
    }

    void wait(uint32_t q, const SemaphoreWait& w, uint32_t f) {
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

    struct Scoped {
        VkPipelineStageFlags2 src, dst;
        VkAccessFlags2 srcAccess, dstAccess;
    };

    static bool inScope(const Event& e, uint32_t q, VkPipelineStageFlags2 src) {
        return (e.queue == q && (e.stages & src)) || (e.chain[q] & src);
    }

    template <class F>
    void forBarrierCells(const Barrier& b, uint32_t f, F&& fn) {
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
    std::vector<uint32_t> previousOwners(uint32_t phys) const {
        std::vector<uint32_t> owners;
        for (uint32_t s : segmentsOf_[phys])
            if (owner_[s] != kNoIndex && owner_[s] != phys &&
                std::find(owners.begin(), owners.end(), owner_[s]) == owners.end())
                owners.push_back(owner_[s]);
        return owners;
    }

    void claim(uint32_t phys) {
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
    void applyBarriers(uint32_t first, uint32_t count, uint32_t q, uint32_t f, bool frameEnd = false) {
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
    void checkTransitionPriors(Cell& cell, uint32_t q, const Scoped& s, bool memoryReaches, uint32_t barrier,
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

    void use(uint32_t planned, Pipeline pipeline, const ir::Use& u, uint32_t q, uint32_t f) {
        const uint32_t phys = physical(u.resource, f);
        const ir::Resource& r = d_.resources[phys];
        // The verifier's own rules (verify_rules.h), not the compiler's table.
        const verify_rules::Need need = verify_rules::need(u.kinds, r.kind, pipeline);
        const VkPipelineStageFlags2 stages = expandStages(need.stages);
        const VkAccessFlags2 access = expandAccess(need.reads | need.writes);
        const VkAccessFlags2 readBits = access & kReadBits, writeBits = access & kWriteBits;
        const bool needsContents = need.needsContents;
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

    template <class F>
    static void forCells(const ir::Resource& r, const Subresource& range, F&& fn) {
        if (r.kind != ResourceKind::Texture) {
            fn(r.cellBase);
            return;
        }
        for (uint32_t m = range.baseMip; m < range.baseMip + range.mipCount; ++m)
            for (uint32_t l = range.baseLayer; l < range.baseLayer + range.layerCount; ++l) fn(ir::cellOf(r, m, l));
    }

    // ---- Frame end ------------------------------------------------------------------------

    // Each import must end as its final state says: in its layout, with every
    // use either described by the state (its queue, within its stages and
    // write access) or ordered before it -- and, if it reads, visible to it.
    // A layout transition is no use a state can describe: it must be ordered
    // before the state's stages (for Present, the semaphore signal's: the
    // presentation engine must find the image in PRESENT_SRC).
    void checkFinalStates(Queue queue, uint32_t f, bool hasBatch) {
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

    const Plan& plan_;
    const ir::Declaration& d_;
    const VerifyOptions& options_;
    VerifyReport& report_;
    std::vector<Cell> cells_;
    std::vector<uint8_t> useful_;
    std::vector<std::vector<uint32_t>> expected_; // per use, per cell: the writing pass (declaration index)
    std::vector<uint32_t> writer_;                // per cell: last writer in the replay of this frame
    std::vector<std::vector<uint32_t>> segmentsOf_;
    std::vector<uint32_t> owner_;
    int64_t signalled_[kQueueCount] = {-1, -1};
};

} // namespace

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
    Replay(plan, options, report).run();
    return report;
}

} // namespace glint::rg
