// ---- Barriers ---------------------------------------------------------------
// One walk over the schedule keeps, per subresource ("cell"), what a later
// use has to synchronise with:
//   - the last write (or layout transition): queue, stages, access, the
//     batch it ran in, and, stage by stage on each queue, the accesses it is
//     already visible to;
//   - the reads since that write, per queue.
// Each use then needs:
//   read-after-write   the write made visible to its stage and access;
//   write-after-read   an execution dependency on the reads;
//   write-after-write  the earlier write made available (when no read came
//                      between; a read in between already saw it);
//   a layout change    a transition, itself a write: ordered after every
//                      earlier use of the cell.
// Read after read needs nothing unless the layout changes. Same-queue needs
// become one barrier per (use, subresource range), all of a pass's in one
// dependency; other-queue needs become a timeline wait at the start of the
// pass's batch in the pass's own stages, or, when an earlier wait already
// reaches the producer, a barrier chained to that wait's stages.
//
// The frame repeats, so its start is the previous frame's end: transients
// begin with the last uses of their bytes (their own and their aliases')
// as prior accesses and discarded contents, history halves with what the
// other half ended in, imports with their declared initial state. Prior
// accesses on the other queue are waited for on the previous frame's last
// batch of that queue. After the last pass, imports move to their final
// state.
//
// A transient used on one queue starts from where this very walk leaves
// its bytes, so its priors are not known before the walk: its first use of
// each cell (always a write or a layout transition, after which nothing of
// the priors remains in the cell) gets a barrier without them, completed
// once the walk is over (resolveFirstUses). Those priors are on the use's
// own queue, so they add stages and accesses to that barrier, never a wait.
// Only history halves and transients on both queues have their end states
// worked out before the walk, from their own uses.

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "glint/graph/batches.h"
#include "glint/graph/compile_state.h"
#include "glint/graph/error.h"

namespace glint::rg::detail {
namespace {

constexpr TimelinePoint kPreviousFrame{-1, TimelinePoint::kLastBatch};

bool within(VkFlags64 inner, VkFlags64 outer) { return (inner & ~outer) == 0; }

// Visibility is tracked per stage: the stages uses can name (the access
// table's, transfers as one) each keep the access bits made visible there,
// packed into 16 bits (the access bits the table uses; any other bit is
// the last one, which only a semaphore wait makes visible).
constexpr VkPipelineStageFlags2 kTrackedStages[] = {
    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
    VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT,
    VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
    VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
    VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
    VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR,
};
constexpr uint32_t kStageSlots = std::size(kTrackedStages);

constexpr VkAccessFlags2 kPackedAccess[] = {
    VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT,
    VK_ACCESS_2_UNIFORM_READ_BIT,
    VK_ACCESS_2_SHADER_READ_BIT,
    VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT,
    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
    VK_ACCESS_2_TRANSFER_READ_BIT,
    VK_ACCESS_2_TRANSFER_WRITE_BIT,
    VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
    VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
    VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
};
constexpr uint16_t kOtherAccess = 1u << 15;
constexpr uint16_t kAnyPacked = 0xFFFF;

struct PackTable {
    uint16_t bit[64] = {};
    constexpr PackTable() {
        for (uint32_t b = 0; b < 64; ++b) bit[b] = kOtherAccess;
        for (uint32_t i = 0; i < std::size(kPackedAccess); ++i)
            bit[std::countr_zero(kPackedAccess[i])] = uint16_t(1u << i);
    }
};
constexpr PackTable kPack;

uint16_t pack(VkAccessFlags2 a) {
    uint16_t out = 0;
    for (VkAccessFlags2 rest = a; rest; rest &= rest - 1) out |= kPack.bit[std::countr_zero(rest)];
    return out;
}

// The tracked-stage slots of a stage mask, and whether it has stages
// outside them.
struct Slots {
    uint16_t mask = 0;
    bool untracked = false;
};

// Stage bit -> slot (kStageSlots: untracked), so a mask's slots cost one
// step per set bit rather than one per tracked stage.
struct SlotTable {
    VkPipelineStageFlags2 tracked = 0;
    uint8_t slot[64] = {};
    constexpr SlotTable() {
        for (uint32_t b = 0; b < 64; ++b) slot[b] = kStageSlots;
        for (uint32_t i = 0; i < kStageSlots; ++i) {
            tracked |= kTrackedStages[i];
            slot[std::countr_zero(kTrackedStages[i])] = static_cast<uint8_t>(i);
        }
    }
};
constexpr SlotTable kSlots;

Slots slotsOf(VkPipelineStageFlags2 s) {
    if (s & VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT) return {uint16_t((1u << kStageSlots) - 1), true};
    Slots out;
    out.untracked = (s & ~kSlots.tracked) != 0;
    for (VkPipelineStageFlags2 rest = s & kSlots.tracked; rest; rest &= rest - 1)
        out.mask |= uint16_t(1u << kSlots.slot[std::countr_zero(rest)]);
    return out;
}

// A set of (tracked stage slot, packed access bit) pairs: slot i's 16
// access bits are bits [16i, 16i + 16) of a 160-bit row, so testing or
// adding visibility is a few word operations whatever the stages.
struct VisMask {
    uint64_t word[3] = {0, 0, 0};
    bool untracked = false; // names stages outside the tracked set
};
static_assert(kStageSlots <= 12, "a VisMask row holds 12 slots of 16 access bits");

VisMask maskOf(Slots s, uint16_t a) {
    VisMask m;
    m.untracked = s.untracked;
    for (uint32_t rest = s.mask; rest; rest &= rest - 1) {
        const auto slot = static_cast<uint32_t>(std::countr_zero(rest));
        m.word[slot / 4] |= uint64_t{a} << (16 * (slot % 4));
    }
    return m;
}

VisMask maskOf(VkPipelineStageFlags2 stages, uint16_t a) { return maskOf(slotsOf(stages), a); }

// One declared use, looked up in the access table once per compile.
struct UseInfo {
    SyncScope scope;
    VkAccessFlags2 reads = 0;       // the read bits of scope.access
    VkAccessFlags2 writeAccess = 0; // and its write bits
    VisMask accessMask;             // its stages x its accesses
    VisMask readMask;               // its stages x its reads
};

UseInfo makeUseInfo(const SyncScope& scope) {
    UseInfo info;
    info.scope = scope;
    info.writeAccess = writeAccessBits(scope.access);
    info.reads = scope.access & ~info.writeAccess;
    const Slots slots = slotsOf(scope.stages);
    info.accessMask = maskOf(slots, pack(scope.access));
    info.readMask = maskOf(slots, pack(info.reads));
    return info;
}

// makeUseInfo() of every single access kind, once per process.
struct UseInfoTable {
    UseInfo info[kAccessCount][3][3];
    UseInfoTable() {
        for (uint32_t a = 0; a < kAccessCount; ++a)
            for (uint32_t k = 0; k < 3; ++k)
                for (uint32_t p = 0; p < 3; ++p)
                    info[a][k][p] = makeUseInfo(
                        scopeOf(static_cast<Access>(a), static_cast<ResourceKind>(k), static_cast<Pipeline>(p)));
    }
};

// Built during static initialisation (from the constant-initialised access
// table), so the lookup needs no guard. Rebuilt entry by entry only by a
// test's detail::ScopeOverride.
UseInfoTable kUseInfo;

const UseInfo& useInfoOf(Access a, ResourceKind k, Pipeline p) {
    return kUseInfo.info[static_cast<uint32_t>(a)][static_cast<uint32_t>(k)][static_cast<uint32_t>(p)];
}

// Per queue, the (stage, access) pairs a write is visible to.
struct Visibility {
    uint64_t word[kQueueCount][3] = {};

    // Stages outside the tracked set (raw boundary states) never count as
    // visible: a barrier too many, never one too few. ALL_COMMANDS adds to
    // every slot (slotsOf()).
    bool covers(uint32_t q, const VisMask& m) const {
        const uint64_t* have = word[q];
        return !m.untracked &&
               ((m.word[0] & ~have[0]) | (m.word[1] & ~have[1]) | (m.word[2] & ~have[2])) == 0;
    }
    void add(uint32_t q, const VisMask& m) {
        word[q][0] |= m.word[0];
        word[q][1] |= m.word[1];
        word[q][2] |= m.word[2];
    }
    void clear() { *this = Visibility{}; }
};

struct Cell {
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    bool contents = false;
    // Not used yet this frame, and its prior accesses (the previous frame's
    // last uses of its bytes) are not known until the walk has seen those:
    // the first use's barrier is placed with the priors (and the aliasing
    // flag) left out and completed by resolveFirstUses(). A transient on
    // one queue, the default: the frame start sets every other cell.
    bool priorLater = true;
    bool wPending = false; // a later write must still be ordered after the write (no read came between)
    int8_t wQueue = -1;    // -1: no write to synchronise with
    TimelinePoint wPoint;
    VkPipelineStageFlags2 wStages = 0;
    VkAccessFlags2 wAccess = 0;
    Visibility vis; // what the write is visible to, stage by stage
    VkPipelineStageFlags2 rStages[kQueueCount] = {0, 0};
    TimelinePoint rPoint[kQueueCount];
    // Stages of each queue that the other queue's reads are already ordered
    // before (a barrier on that queue chained from a wait that reached them).
    VkPipelineStageFlags2 rOrdered[kQueueCount] = {0, 0};

    void addVisibleToAll(uint32_t q, VkPipelineStageFlags2 s) { vis.add(q, maskOf(s, kAnyPacked)); }
    void clearVisible() { vis.clear(); }
};

// What one frame leaves in a cell: enough to start the next one. It
// follows the walk's bookkeeping without placing anything: after a use,
// the last write is visible to that use whatever synchronised it.
struct EndState {
    bool touched = false;
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    int8_t wQueue = -1;
    bool wPending = false;
    VkPipelineStageFlags2 wStages = 0;
    VkAccessFlags2 wAccess = 0;
    VkPipelineStageFlags2 rStages[kQueueCount] = {0, 0};

    // `seen` (may be null) follows what the last write is visible to.
    void apply(uint32_t q, const UseInfo& use, bool writes, bool texture, Visibility* seen) {
        const SyncScope& s = use.scope;
        if (texture && (!touched || layout != s.layout) && s.layout != VK_IMAGE_LAYOUT_UNDEFINED) {
            // Transition: a write of no data at the use's stages.
            wQueue = static_cast<int8_t>(q);
            wPending = true;
            wStages = s.stages;
            wAccess = 0;
            rStages[0] = rStages[1] = 0;
            layout = s.layout;
            if (seen) {
                seen->clear();
                seen->add(q, use.accessMask);
            }
        }
        touched = true;
        if (writes) {
            wQueue = static_cast<int8_t>(q);
            wPending = true;
            wStages = s.stages;
            wAccess = use.writeAccess;
            rStages[0] = rStages[1] = 0;
            if (seen) seen->clear();
        } else {
            rStages[q] |= s.stages;
            wPending = false;
            if (seen) seen->add(q, use.accessMask);
        }
    }
};

// Adds `e` as the previous frame's accesses to `c`.
void addPrior(Cell& c, const EndState& e) {
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        if (!e.rStages[q]) continue;
        c.rStages[q] |= e.rStages[q];
        c.rPoint[q] = kPreviousFrame;
    }
    if (e.wQueue >= 0 && e.wStages && (c.wQueue < 0 || c.wQueue == e.wQueue)) {
        c.wQueue = e.wQueue;
        c.wStages |= e.wStages;
        c.wAccess |= e.wAccess;
        c.wPoint = kPreviousFrame;
        c.wPending = c.wPending || e.wPending;
    }
}

// The last uses of a transient on one queue, or of some bytes of a heap
// merged over the resources on them: what its first uses in the next frame
// synchronise with. One queue per heap, and reads and the write on it, so
// three masks and a flag, merged by OR. Writes already made available still
// matter to the next layout transition on these bytes (see analyse(): write
// after write), so they are carried too; only pending ones set `pending`.
struct LastUses {
    VkPipelineStageFlags2 rStages = 0;
    VkPipelineStageFlags2 wStages = 0; // 0: no write
    VkAccessFlags2 wAccess = 0;
    bool pending = false;

    void merge(const LastUses& o) {
        rStages |= o.rStages;
        wStages |= o.wStages;
        wAccess |= o.wAccess;
        pending = pending || o.pending;
    }
};

// What one use of one cell needs.
struct Need {
    uint32_t cell;
    VkPipelineStageFlags2 srcStages;
    VkAccessFlags2 srcAccess;
    VkImageLayout oldLayout;
    VkPipelineStageFlags2 visibleByWait; // a new or placed wait already makes the write visible here
    bool transition;
    bool barrier;
    bool rawByBarrier;
    bool waits;    // asked crossQueue(): the only part of analyse() that reads pending_
    bool firstUse; // of a priorLater cell: the barrier's priors come later
};

// A barrier that holds a priorLater cell's first use: resolveFirstUses()
// analyses that use again against the frame-start priors and ORs what they
// add into it. What that needs is kept here, not looked up again: resolving
// reads these long after the walk had them at hand.
struct FirstUse {
    uint32_t barrier; // index into Plan::barriers
    uint32_t cell;
    uint32_t resource;
    uint32_t queue;
    bool texture;
    const UseInfo* info;
};

struct FinalImport;

// An import whose final state needs barriers: its needs_[firstNeed, endNeed).
struct Final {
    const FinalImport* target;
    uint32_t firstNeed;
    uint32_t endNeed;
};

struct FinalImport {
    uint32_t resource;
    uint32_t cellBase; // its cells, all of them: [cellBase, +cellCount)
    uint32_t cellCount;
    bool texture;
    const UseInfo* state; // the final state as a use: in the table, or in rawFinals
};

// A declared use as the walk reads it, resolved once per pass: the walk
// then touches neither the (large) declared resource nor the planned one
// for the common use of one subresource.
struct UseRef {
    const UseInfo* info = nullptr;
    uint32_t cell = 0;              // first cell of the use's range
    bool texture = false;
    bool single = false; // the range is one cell
    bool writes = false;
};

// Byte offsets -> their rank among the distinct offsets inserted: an
// open-addressing hash set, then the distinct values sorted and numbered.
// Placement reuses a few offsets for many resources, so the table is sized
// by the distinct ones (it grows when they fill half of it), and a stamp per
// slot tells this compile's entries from older ones: nothing is cleared.
class OffsetIndex {
public:
    void reset() {
        distinct_.clear();
        if (slots_.empty()) rehash(64);
        if (++stamp_ == 0) { // wrapped: forget every stamp
            for (Slot& slot : slots_) slot.stamp = 0;
            stamp_ = 1;
        }
    }
    void insert(uint64_t offset) {
        size_t i = home(offset);
        while (slots_[i].stamp == stamp_) {
            if (slots_[i].key == offset) return;
            i = (i + 1) & mask_;
        }
        slots_[i] = {offset, stamp_, 0};
        distinct_.push_back(offset);
        if (2 * distinct_.size() > slots_.size()) rehash(2 * slots_.size());
    }
    void number() {
        std::sort(distinct_.begin(), distinct_.end());
        for (uint32_t i = 0; i < distinct_.size(); ++i) slots_[slotOf(distinct_[i])].rank = i;
    }
    // An inserted offset's rank.
    uint32_t find(uint64_t offset) const { return slots_[slotOf(offset)].rank; }
    size_t count() const { return distinct_.size(); }

private:
    struct Slot {
        uint64_t key = 0;
        uint32_t stamp = 0; // holds this compile's offset when it equals stamp_
        uint32_t rank = 0;
    };

    void rehash(size_t size) {
        slots_.assign(size, Slot{});
        mask_ = size - 1;
        shift_ = 64 - static_cast<uint32_t>(std::countr_zero(size));
        stamp_ = std::max(stamp_, 1u);
        for (const uint64_t offset : distinct_) {
            size_t i = home(offset);
            while (slots_[i].stamp == stamp_) i = (i + 1) & mask_;
            slots_[i] = {offset, stamp_, 0};
        }
    }
    size_t home(uint64_t offset) const { return static_cast<size_t>((offset * 0x9E3779B97F4A7C15ull) >> shift_); }
    size_t slotOf(uint64_t offset) const {
        size_t i = home(offset);
        while (slots_[i].key != offset || slots_[i].stamp != stamp_) i = (i + 1) & mask_;
        return i;
    }

    std::vector<Slot> slots_;
    size_t mask_ = 0;
    uint32_t shift_ = 64;
    uint32_t stamp_ = 0;
    std::vector<uint64_t> distinct_;
};

// compile() runs every frame: the walk keeps its working memory per thread
// so a frame's compile reuses last frame's allocations instead of asking
// the allocator (and the kernel, for fresh pages) again.
struct Scratch {
    std::vector<Cell> cells;
    std::vector<EndState> ends;
    std::vector<Visibility> endSeen;
    std::vector<UseInfo> mergedInfo;
    std::vector<Need> needs;
    std::vector<uint32_t> useNeed;
    std::vector<Final> finals;
    std::vector<FinalImport> finalImports[kQueueCount]; // by the final state's queue
    std::vector<UseInfo> rawFinals; // final states given as raw masks
    std::vector<uint32_t> deferred;
    std::vector<uint32_t> historyCurrents;
    std::vector<uint32_t> earlyList; // the resources early marks
    std::vector<uint8_t> early; // per resource: starts from its own end, known before the walk
    std::vector<UseRef> passRefs; // the walked pass's uses
    std::vector<uint32_t> imports;
    std::vector<FirstUse> firstUses;
    OffsetIndex offsetIndex;
    std::vector<LastUses> tree;
    std::vector<LastUses> aliasedPriors; // per resource; aliased transients' entries are set
    std::vector<std::pair<uint32_t, uint32_t>> pieces; // per aliased member: its pieces [first, second)
    std::vector<std::vector<uint32_t>> heapMembers;
};

Scratch& scratch() {
    thread_local Scratch s;
    return s;
}

class Walk {
public:
    explicit Walk(CompileState& st) : st_(st), d_(st.decl), batches_(st), scratch_(scratch()) {}

    void run() {
        st_.plan.barriers.reserve(d_.uses.size() + d_.resources.size());
        initialiseCells();
        st_.barrierFirst.assign(st_.order.size(), 0);
        st_.barrierCount.assign(st_.order.size(), 0);
        needs_.reserve(64);
        for (uint32_t pos = 0; pos < st_.order.size(); ++pos) walkPass(pos);
        resolveFirstUses();
        finalStates();
        batches_.finish();
    }

private:
    // ---- Frame start ----------------------------------------------------------

    // A declared use as the walk reads it (merged read kinds get an entry
    // of their own in mergedInfo_).
    UseRef useRefOf(const ir::Pass& pass, uint32_t u) {
        const ir::Use& use = d_.uses[u];
        const ir::Resource& r = d_.resources[use.resource];
        UseRef ref;
        if ((use.kinds & (use.kinds - 1)) == 0) {
            ref.info = &useInfoOf(static_cast<Access>(std::countr_zero(use.kinds)), r.kind, pass.pipeline);
        } else {
            mergedInfo_.push_back(makeUseInfo(accessScope(use.kinds, r.kind, pass.pipeline)));
            ref.info = &mergedInfo_.back();
        }
        ref.texture = r.kind == ResourceKind::Texture;
        ref.cell = ref.texture ? ir::cellOf(r, use.range.baseMip, use.range.baseLayer) : r.cellBase;
        ref.single = !ref.texture || (use.range.mipCount == 1 && use.range.layerCount == 1);
        ref.writes = use.writes;
        return ref;
    }

    void initialiseCells() {
        const uint32_t cellCount = d_.cellCount;
        cells_.assign(cellCount, Cell{});
        // A UseRef is made per use in the walk and once more for a use of a
        // resource that starts from its own end: at most two merged entries
        // per use, and the reserve keeps pointers into them valid.
        mergedInfo_.clear();
        mergedInfo_.reserve(2 * d_.uses.size());

        // Imports start from their declared state. Resources that start from
        // where they end, known before the walk: history halves (each starts
        // from the other's end, visibility included) and transients on both
        // queues (their priors may need a wait on the other queue, which
        // changes batches). Only their cells' ends_ and endSeen_ are used, so
        // only those are reset. Every other transient is priorLater, as its
        // cells already are.
        ends_.resize(cellCount);
        endSeen_.resize(cellCount);
        early_.assign(d_.resources.size(), 0);
        std::vector<uint32_t>& early = scratch_.earlyList;
        std::vector<uint32_t>& currents = scratch_.historyCurrents;
        early.clear();
        currents.clear();
        imports_.clear();
        for (const uint32_t r : st_.startKnown) {
            const ir::Resource& res = d_.resources[r];
            switch (res.origin) {
                case ir::Origin::Imported:
                    imports_.push_back(r);
                    startImport(r);
                    continue;
                case ir::Origin::Transient: // on both queues
                    break;
                case ir::Origin::HistoryCurrent:
                    currents.push_back(r);
                    break;
                case ir::Origin::HistoryPrevious:
                    break;
            }
            early_[r] = 1;
            early.push_back(r);
            for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
                ends_[c] = EndState{};
                endSeen_[c] = Visibility{};
            }
        }
        if (early.empty()) return;

        // What the frame leaves behind in them, use by use. A `previous` half
        // starts from what its partner ended in, so it goes second.
        std::vector<uint32_t>& deferred = scratch_.deferred;
        deferred.clear();
        for (uint32_t pos = 0; pos < st_.order.size(); ++pos) {
            const uint32_t p = st_.order[pos];
            const ir::Pass& pass = d_.passes[p];
            for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
                const uint32_t r = d_.uses[u].resource;
                if (!early_[r]) continue;
                if (d_.resources[r].origin == ir::Origin::HistoryPrevious) {
                    deferred.push_back(u);
                    deferred.push_back(pos);
                    continue;
                }
                applyEnd(pass, u, queueIndex(st_.queueOf[p]));
            }
        }
        for (const uint32_t r : currents) seedHistoryPrevious(r);
        for (size_t i = 0; i < deferred.size(); i += 2) {
            const uint32_t p = st_.order[deferred[i + 1]];
            applyEnd(d_.passes[p], deferred[i], queueIndex(st_.queueOf[p]));
        }

        for (const uint32_t r : early) {
            const ir::Resource& res = d_.resources[r];
            if (res.origin != ir::Origin::Transient) {
                startHistory(r);
                continue;
            }
            // Its bytes are its own (no aliasing across queues).
            for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
                cells_[c].priorLater = false;
                addPrior(cells_[c], ends_[c]);
            }
        }
    }

    [[noreturn]] void priorsElsewhere(uint32_t r) const {
        throw std::logic_error("rg barriers: the frame-start priors of '" + std::string(d_.resources[r].name) +
                               "' are on the other queue");
    }

    // Completes the first-use barriers of the transients on one queue: now
    // that the walk has seen the frame's last uses, each such use is
    // analysed again from its true frame-start state (its own last uses, or
    // those of every resource on its bytes), and what that adds is ORed into
    // the barrier the walk placed. The priors are on the use's own queue (a
    // one-queue resource; an aliasing heap holds one queue's resources), so
    // they add stages and accesses, never a wait.
    void resolveFirstUses() {
        if (firstUses_.empty()) return;
        aliasedPriors_.resize(d_.resources.size());
        startAliased();
        std::vector<Barrier>& barriers = st_.plan.barriers;
        for (const FirstUse& f : firstUses_) {
            const uint32_t r = f.resource;
            const LastUses prior = st_.aliased[r] ? aliasedPriors_[r] : lastUsesOf(f.cell, f.queue, r);
            const UseInfo& info = *f.info;
            const bool transition = f.texture; // from UNDEFINED
            VkPipelineStageFlags2 srcStages = 0;
            VkAccessFlags2 srcAccess = 0;
            // analyse() of a use after `prior` alone: nothing is visible yet,
            // the use writes (or transitions), every prior is on its queue.
            const bool write = prior.wStages != 0;
            // Read after write.
            if (info.reads && write && !Visibility{}.covers(f.queue, info.readMask)) {
                srcStages |= prior.wStages;
                srcAccess |= prior.wAccess;
            }
            // Write after read.
            srcStages |= prior.rStages;
            // Write after write.
            if ((prior.pending || transition) && write &&
                (transition || !Visibility{}.covers(f.queue, info.accessMask))) {
                srcStages |= prior.wStages;
                srcAccess |= prior.wAccess;
            }
            if (!transition && !srcStages) [[unlikely]]
                throw std::logic_error("rg barriers: '" + std::string(d_.resources[r].name) +
                                       "' starts the frame with no prior use");
            Barrier& b = barriers[f.barrier];
            b.srcStages |= srcStages;
            b.srcAccess |= srcAccess;
            b.aliasing = b.aliasing || st_.aliased[r];
        }
        if (st_.log) {
            for (size_t i = 0; i < firstUses_.size(); ++i) {
                const uint32_t k = firstUses_[i].barrier;
                if (i > 0 && firstUses_[i - 1].barrier == k) continue;
                const ir::Resource& r = d_.resources[barriers[k].resource];
                spdlog::debug("rg barriers: {} (first use)", describeBarrier(r.name, barriers[k], r.kind));
            }
        }
        firstUses_.clear();
    }

    void applyEnd(const ir::Pass& pass, uint32_t u, uint32_t q) {
        const ir::Use& use = d_.uses[u];
        const ir::Resource& r = d_.resources[use.resource];
        const UseRef ref = useRefOf(pass, u);
        // Visibility carries over only for history images (imports restart
        // from their declared state, transients from discarded contents).
        const bool history = r.partner != kNoIndex;
        forCells(ref, use, [&](uint32_t c) {
            ends_[c].apply(q, *ref.info, use.writes, ref.texture, history ? &endSeen_[c] : nullptr);
        });
    }

    // `previous` this frame is what `current` was at the end of the last one.
    void seedHistoryPrevious(uint32_t current) {
        const ir::Resource& cur = d_.resources[current];
        const ir::Resource& prev = d_.resources[cur.partner];
        for (uint32_t i = 0; i < cur.cellCount; ++i) {
            const EndState& from = ends_[cur.cellBase + i];
            if (!from.touched) continue;
            ends_[prev.cellBase + i] = from;
            endSeen_[prev.cellBase + i] = endSeen_[cur.cellBase + i];
        }
    }

    void startImport(uint32_t r) {
        const ir::Resource& res = d_.resources[r];
        for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) cells_[c].priorLater = false;
        if (!res.hasInitial) return;
        // A state named by an access kind is a use of that kind: its masks
        // come from the table.
        UseInfo raw;
        if (res.initial.isRaw) raw = makeUseInfo(boundaryScope(res.initial, res.kind));
        const UseInfo& state =
            res.initial.isRaw ? raw : useInfoOf(res.initial.access, res.kind, res.initial.pipeline);
        const SyncScope& s = state.scope;
        const uint32_t q = queueIndex(st_.boundaryQueue(res.initial.queue));
        for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) {
            Cell& cell = cells_[c];
            cell.layout = s.layout;
            cell.contents = res.contentsAtStart;
            if (!s.stages) continue; // nothing in flight: ordered outside the plan
            cell.wQueue = static_cast<int8_t>(q);
            cell.wStages = s.stages;
            cell.wPoint = kPreviousFrame;
            if (state.writeAccess) {
                cell.wAccess = state.writeAccess;
                cell.wPending = true;
            } else {
                // A read state: whatever wrote the contents is visible to that
                // read, and only to it; other readers chain from its stages.
                cell.rStages[q] = s.stages;
                cell.rPoint[q] = kPreviousFrame;
                if (cell.contents)
                    cell.vis.add(q, state.accessMask);
                else
                    cell.wQueue = -1;
            }
        }
    }

    // A history half's image was its partner's last frame. `current` starts
    // where `previous` ended (ends_ of `previous` already includes the
    // partner's end it started from); `previous` starts where `current` ended,
    // or, for a subresource `current` never touched, where it left it itself
    // two frames ago.
    void startHistory(uint32_t r) {
        const ir::Resource& res = d_.resources[r];
        const ir::Resource& partner = d_.resources[res.partner];
        VkImageLayout entry = VK_IMAGE_LAYOUT_UNDEFINED;
        bool first = true;
        for (uint32_t i = 0; i < res.cellCount; ++i) {
            const EndState& partnerEnd = ends_[partner.cellBase + i];
            const bool fromPartner = res.origin == ir::Origin::HistoryCurrent || partnerEnd.touched;
            const uint32_t fromCell = fromPartner ? partner.cellBase + i : res.cellBase + i;
            const EndState& from = ends_[fromCell];
            Cell& cell = cells_[res.cellBase + i];
            cell.priorLater = false;
            cell.contents = true;
            if (!from.touched) continue;
            cell.layout = from.layout;
            addPrior(cell, from);
            // The image keeps what last frame made visible; re-establishing it
            // would be a barrier that orders nothing.
            cell.vis = endSeen_[fromCell];
            if (res.kind != ResourceKind::Texture) continue;
            if (first) entry = from.layout;
            first = false;
            if (from.layout != entry)
                throw GraphError(ErrorKind::ConflictingAccess, lastUserName(res.partner), res.name,
                                 "a history texture must end the frame with every subresource in one layout (the "
                                 "executor prepares both images in one layout before the first frame)");
        }
        st_.plan.resources[r].entryLayout = entry;
    }

    std::string_view lastUserName(uint32_t r) const {
        const Lifetime& life = st_.lifetimes[r];
        return life.used() ? d_.passes[st_.order[life.last]].name : std::string_view("(none)");
    }

    // A transient sharing bytes starts after the last uses of every resource
    // on any of its bytes, itself included (one queue per heap, so stages
    // are all that matter). Per heap: cut the bytes at every placement
    // boundary, OR each resource's last uses into the pieces it covers, then
    // OR back over each resource's pieces: piece by piece when members span
    // a few pieces each (the usual packing), else through a segment tree
    // over the pieces (bottom-up, 2 x pieces nodes: OR is commutative, so
    // any size works), O(n log n) however many placements overlap.
    void startAliased() {
        std::vector<std::vector<uint32_t>>& members = scratch_.heapMembers;
        members.resize(st_.plan.heaps.size());
        for (auto& list : members) list.clear();
        for (uint32_t r = 0; r < d_.resources.size(); ++r)
            if (st_.aliased[r]) members[st_.plan.resources[r].heap].push_back(r);
        std::vector<LastUses>& tree = scratch_.tree;
        std::vector<std::pair<uint32_t, uint32_t>>& pieces = scratch_.pieces;
        for (const std::vector<uint32_t>& list : members) {
            if (list.empty()) continue;
            // The distinct offsets where members begin or end, in order; a
            // piece lies between two neighbours. Placement reuses a few
            // offsets for many members, so the distinct ones are gathered
            // through a hash table first and only they are sorted.
            OffsetIndex& index = scratch_.offsetIndex;
            index.reset();
            for (const uint32_t r : list) {
                const PlannedResource& placed = st_.plan.resources[r];
                index.insert(placed.offset);
                index.insert(placed.offset + placed.size);
            }
            index.number();
            pieces.resize(list.size());
            for (uint32_t i = 0; i < list.size(); ++i) {
                const PlannedResource& placed = st_.plan.resources[list[i]];
                pieces[i] = {index.find(placed.offset), index.find(placed.offset + placed.size)};
            }
            const size_t width = index.count() - 1;
            // Placement packs a heap so that a member usually spans a few
            // pieces: then OR-ing into and out of each piece directly is far
            // cheaper than the tree. The tree bounds the worst case.
            size_t spanned = 0;
            for (const auto& [first, last] : pieces) spanned += last - first;
            if (spanned <= 8 * pieces.size()) {
                tree.assign(width, LastUses{});
                for (size_t i = 0; i < list.size(); ++i) {
                    const LastUses last = summary(list[i]);
                    for (uint32_t k = pieces[i].first; k < pieces[i].second; ++k) tree[k].merge(last);
                }
                for (size_t i = 0; i < list.size(); ++i) {
                    LastUses priors;
                    for (uint32_t k = pieces[i].first; k < pieces[i].second; ++k) priors.merge(tree[k]);
                    addAliasedPriors(list[i], priors);
                }
                continue;
            }
            // Range-OR updates, pushed down to the pieces.
            tree.assign(2 * width, LastUses{});
            for (size_t i = 0; i < list.size(); ++i) {
                const LastUses last = summary(list[i]);
                for (size_t l = pieces[i].first + width, h = pieces[i].second + width; l < h; l /= 2, h /= 2) {
                    if (l & 1) tree[l++].merge(last);
                    if (h & 1) tree[--h].merge(last);
                }
            }
            for (size_t n = 1; n < width; ++n) {
                tree[2 * n].merge(tree[n]);
                tree[2 * n + 1].merge(tree[n]);
            }
            // Range-OR queries over the pieces.
            for (size_t n = width - 1; n >= 1; --n) {
                tree[n] = tree[2 * n];
                tree[n].merge(tree[2 * n + 1]);
            }
            for (size_t i = 0; i < list.size(); ++i) {
                LastUses priors;
                for (size_t l = pieces[i].first + width, h = pieces[i].second + width; l < h; l /= 2, h /= 2) {
                    if (l & 1) priors.merge(tree[l++]);
                    if (h & 1) priors.merge(tree[--h]);
                }
                addAliasedPriors(list[i], priors);
            }
        }
    }

    // Keeps an aliased transient's priors for resolveFirstUses().
    void addAliasedPriors(uint32_t r, const LastUses& priors) { aliasedPriors_[r] = priors; }

    // The last uses of any subresource of `r`: where the walk left its cells.
    LastUses summary(uint32_t r) const {
        const ir::Resource& res = d_.resources[r];
        const uint32_t q = queueIndex(st_.plan.resources[r].queue);
        LastUses out;
        for (uint32_t c = res.cellBase; c < res.cellBase + res.cellCount; ++c) out.merge(lastUsesOf(c, q, r));
        return out;
    }

    // Where the walk left cell c of transient r, used on queue q only.
    LastUses lastUsesOf(uint32_t c, uint32_t q, uint32_t r) const {
        const Cell& cell = cells_[c];
        const bool written = cell.wQueue >= 0 && cell.wStages;
        if (cell.rStages[q ^ 1] || (written && cell.wQueue != static_cast<int8_t>(q))) [[unlikely]]
            priorsElsewhere(r);
        LastUses out;
        out.rStages = cell.rStages[q];
        if (written) {
            out.wStages = cell.wStages;
            out.wAccess = cell.wAccess;
            out.pending = cell.wPending;
        }
        return out;
    }

    // A use's cells, mip-major.
    template <class F>
    void forCells(const UseRef& ref, const ir::Use& use, F&& f) const {
        if (ref.single) {
            f(ref.cell);
            return;
        }
        forCells(d_.resources[use.resource], use.range, std::forward<F>(f));
    }

    template <class F>
    static void forCells(const ir::Resource& r, const Subresource& range, F&& f) {
        if (r.kind != ResourceKind::Texture) {
            f(r.cellBase);
            return;
        }
        for (uint32_t m = range.baseMip; m < range.baseMip + range.mipCount; ++m)
            for (uint32_t l = range.baseLayer; l < range.baseLayer + range.layerCount; ++l) f(ir::cellOf(r, m, l));
    }

    // ---- Hazards --------------------------------------------------------------

    // A dependency on a prior access on the other queue: reuse a placed wait
    // that reaches it, else request one (merged per signalling queue) in the
    // use's own stages. Returns the wait stages the use can chain from.
    // The pass's own new wait, once it has one, serves every need it reaches
    // in the pass's stages; an older wait in other stages serves by a chained
    // barrier only when no new wait is placed (walkPass re-analyses a pass
    // that creates one, so the order of its uses does not matter).
    VkPipelineStageFlags2 crossQueue(uint32_t q, uint32_t from, TimelinePoint point, VkPipelineStageFlags2 stages) {
        const VkPipelineStageFlags2 wanted = stages ? stages : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        const VkPipelineStageFlags2 placed =
            batches_.reachingStages(static_cast<Queue>(q), static_cast<Queue>(from), point);
        if (placed && within(wanted, placed)) return placed;
        WaitRequest& req = pending_[from];
        if (req.active && reaches(req.point, point)) {
            req.stages |= wanted;
            return req.stages;
        }
        if (placed) return placed;
        if (!req.active) {
            req = {true, point, wanted};
        } else {
            req.point = point;
            req.stages |= wanted;
        }
        return req.stages;
    }

    // `n` arrives value-initialised (a fresh need, or one reset by the caller).
    // Inline in the walk (it and update() run for every use; as calls they
    // spent a tenth of the walk saving and restoring registers).
    [[gnu::always_inline]] void analyse(Need& n, uint32_t c, uint32_t q, const UseInfo& use, bool writes,
                                        bool texture) {
        const Cell& cell = cells_[c];
        const SyncScope& s = use.scope;
        if (cell.priorLater) {
            // Nothing this frame came before it, and what the previous one
            // left comes later: a barrier either way (a texture transitions
            // from UNDEFINED; a buffer's last frame always left a use behind),
            // which resolveFirstUses() completes.
            n.cell = c;
            n.transition = texture && cell.layout != s.layout;
            n.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            n.barrier = true;
            n.firstUse = true;
            return;
        }
        n.cell = c;
        n.transition = texture && cell.layout != s.layout;
        n.oldLayout = n.transition && !cell.contents ? VK_IMAGE_LAYOUT_UNDEFINED : cell.layout;
        const bool writeOp = writes || n.transition;

        // Read after write.
        if (use.reads && cell.wQueue >= 0 && cell.wStages && !cell.vis.covers(q, use.readMask)) {
            if (cell.wQueue == static_cast<int8_t>(q)) {
                n.srcStages |= cell.wStages;
                n.srcAccess |= cell.wAccess;
                n.rawByBarrier = true;
            } else {
                viaOtherQueue(n, q, s, static_cast<uint32_t>(cell.wQueue), cell.wPoint, true);
            }
        }
        if (writeOp) {
            // Write after read.
            for (uint32_t rq = 0; rq < kQueueCount; ++rq) {
                if (!cell.rStages[rq]) continue;
                if (rq == q)
                    n.srcStages |= cell.rStages[rq];
                else if (n.transition || !within(ownStages(s), cell.rOrdered[q]))
                    viaOtherQueue(n, q, s, rq, cell.rPoint[rq], false);
            }
            // Write after write. A layout transition names the last write
            // in its first scope even when an earlier barrier already made
            // it available: the transition is a write of its own, and
            // synchronization validation (rightly strict about WAW) only
            // accepts a prior write the transition's barrier itself covers.
            if ((cell.wPending || n.transition) && cell.wQueue >= 0 && cell.wStages &&
                (n.transition || !cell.vis.covers(q, use.accessMask))) {
                if (cell.wQueue == static_cast<int8_t>(q)) {
                    n.srcStages |= cell.wStages;
                    n.srcAccess |= cell.wAccess;
                } else {
                    viaOtherQueue(n, q, s, static_cast<uint32_t>(cell.wQueue), cell.wPoint, false);
                }
            }
        }
        n.barrier = n.transition || n.srcStages != 0;
    }

    // The stages a use's own work runs in (ALL_COMMANDS for a use of none).
    static VkPipelineStageFlags2 ownStages(const SyncScope& s) {
        return s.stages ? s.stages : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    }

    // analyse()'s dependency on a prior access on the other queue, `from`,
    // at `point`: through a wait, chained into a barrier when the wait's
    // stages do not cover the use's. Out of line: most uses never get here.
    [[gnu::noinline]] void viaOtherQueue(Need& n, uint32_t q, const SyncScope& s, uint32_t from, TimelinePoint point,
                                         bool makesVisible) {
        n.waits = true;
        const VkPipelineStageFlags2 waited = crossQueue(q, from, point, s.stages);
        if (n.transition || !within(ownStages(s), waited)) {
            n.srcStages |= waited; // chain through the wait
            n.rawByBarrier = n.rawByBarrier || makesVisible;
        } else if (makesVisible) {
            n.visibleByWait |= waited;
        }
    }

    // The frame's last word on an import: it ends in `s` on queue q, as if a
    // use of that kind came next. Priors that `s` already describes (same
    // queue, its stages, its write access) stay as they are: whoever comes
    // next synchronises with them through `s`. Others are made to happen
    // before `s`.
    // `n` arrives value-initialised, as in analyse().
    void analyseFinal(Need& n, uint32_t c, uint32_t q, const UseInfo& state, bool texture) {
        const Cell& cell = cells_[c];
        const SyncScope& s = state.scope;
        n.cell = c;
        n.transition = texture && s.layout != VK_IMAGE_LAYOUT_UNDEFINED && cell.layout != s.layout;
        n.oldLayout = n.transition && !cell.contents ? VK_IMAGE_LAYOUT_UNDEFINED : cell.layout;
        if (!n.transition && !s.stages) return; // handed over by a semaphore signal: nothing to order

        auto order = [&](uint32_t from, TimelinePoint point, VkPipelineStageFlags2 stages, VkAccessFlags2 access,
                         bool makesVisible) {
            if (from == q) {
                n.srcStages |= stages;
                n.srcAccess |= access;
                n.rawByBarrier = n.rawByBarrier || makesVisible;
                return;
            }
            n.waits = true;
            const VkPipelineStageFlags2 waited = crossQueue(q, from, point, s.stages);
            if (n.transition || !within(s.stages ? s.stages : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, waited))
                n.srcStages |= waited;
        };

        for (uint32_t rq = 0; rq < kQueueCount; ++rq) {
            if (!cell.rStages[rq]) continue;
            if (!n.transition && rq == q && within(cell.rStages[rq], s.stages)) continue;
            if (!n.transition && rq != q && within(s.stages, cell.rOrdered[q])) continue;
            order(rq, cell.rPoint[rq], cell.rStages[rq], 0, false);
        }
        if (cell.wQueue >= 0 && cell.wStages) {
            const bool described = cell.wQueue == static_cast<int8_t>(q) && within(cell.wStages, s.stages) &&
                                   within(cell.wAccess, s.access);
            const bool unseen = state.reads && !cell.vis.covers(q, state.readMask);
            if ((n.transition && cell.wPending) || (!described && (cell.wPending || unseen)))
                order(static_cast<uint32_t>(cell.wQueue), cell.wPoint, cell.wStages, cell.wAccess, unseen);
        }
        n.barrier = n.transition || n.srcStages != 0;
    }

    // Inline in the walk, as analyse() is.
    [[gnu::always_inline]] void update(const Need& n, uint32_t q, const UseInfo& use, bool writes, TimelinePoint now) {
        Cell& cell = cells_[n.cell];
        const SyncScope& s = use.scope;
        if (n.firstUse) [[unlikely]] {
            // What follows a write (or a layout transition) does not depend
            // on what came before it, so the walk can go on without the
            // priors. A transient's first use of a subresource writes it
            // (reads need contents), so this holds by construction.
            if (!writes && !n.transition)
                throw std::logic_error("rg barriers: the first use of a transient subresource in '" +
                                       std::string(d_.passes[st_.order[pos_]].name) + "' reads it");
            cell.priorLater = false;
        }
        if (writes) {
            // A write replaces all the cell knew but its layout: what a
            // transition, a barrier or a wait made visible or ordered came
            // before it.
            if (n.transition) cell.layout = s.layout;
            cell.wQueue = static_cast<int8_t>(q);
            cell.wPoint = now;
            cell.wStages = s.stages;
            cell.wAccess = use.writeAccess;
            cell.wPending = true;
            cell.rStages[0] = cell.rStages[1] = 0;
            cell.rOrdered[0] = cell.rOrdered[1] = 0;
            cell.clearVisible();
            cell.contents = true;
            return;
        }
        // A barrier chained from a wait orders every read of the other queue
        // that wait reached, not only the hazard it was placed for.
        const uint32_t other = queueIndex(otherQueue(static_cast<Queue>(q)));
        if (n.barrier && cell.rStages[other] &&
            (batches_.reachingStages(static_cast<Queue>(q), static_cast<Queue>(other), cell.rPoint[other]) &
             n.srcStages))
            cell.rOrdered[q] |= s.stages;
        if (n.transition) {
            cell.layout = s.layout;
            cell.wQueue = static_cast<int8_t>(q);
            cell.wPoint = now;
            cell.wStages = s.stages;
            cell.wAccess = 0;
            cell.wPending = true;
            cell.rStages[0] = cell.rStages[1] = 0;
            cell.rOrdered[0] = cell.rOrdered[1] = 0;
            cell.clearVisible();
            cell.vis.add(q, use.accessMask);
        } else if (n.rawByBarrier) {
            cell.vis.add(q, use.readMask);
        }
        if (n.visibleByWait) cell.addVisibleToAll(q, n.visibleByWait);
        cell.rStages[q] |= s.stages;
        cell.rPoint[q] = now;
        cell.rOrdered[other] = 0; // the new read is not ordered on the other queue yet
        cell.wPending = false;
    }

    // ---- Emission -------------------------------------------------------------

    // Turns needs_[first, last) -- one use's cells in mip-major order -- into
    // barriers: runs of layers per mip, merged across mips when runs line up.
    // The use is on queue q, with `info` (null for frame-end states).
    void emit(uint32_t resource, bool texture, VkImageAspectFlags aspect, const Subresource& range, const SyncScope& s,
              size_t first, size_t last, uint32_t q, const UseInfo* info) {
        std::vector<Barrier>& out = st_.plan.barriers;
        const size_t firstBarrier = out.size();
        const uint32_t layers = texture ? range.layerCount : 1;
        size_t i = first;
        while (i < last) {
            const Need& n = needs_[i];
            if (!n.barrier) {
                ++i;
                continue;
            }
            const auto offset = static_cast<uint32_t>(i - first);
            const uint32_t mip = texture ? range.baseMip + offset / layers : 0;
            const uint32_t layer = texture ? range.baseLayer + offset % layers : 0;
            VkPipelineStageFlags2 srcStages = n.srcStages;
            VkAccessFlags2 srcAccess = n.srcAccess;
            uint32_t layerCount = 1;
            size_t j = i + 1;
            while (j < last && (j - first) / layers == offset / layers && needs_[j].barrier &&
                   needs_[j].oldLayout == n.oldLayout) {
                srcStages |= needs_[j].srcStages;
                srcAccess |= needs_[j].srcAccess;
                ++layerCount;
                ++j;
            }
            const VkImageLayout oldLayout = texture ? n.oldLayout : VK_IMAGE_LAYOUT_UNDEFINED;
            // Barriers are built in place: assembling one on the stack and
            // copying it costs store-forwarding stalls on this hot path.
            if (out.size() > firstBarrier) {
                Barrier& prev = out.back();
                if (prev.oldLayout == oldLayout && prev.range.baseLayer == layer &&
                    prev.range.layerCount == layerCount && prev.range.baseMip + prev.range.mipCount == mip) {
                    ++prev.range.mipCount;
                    prev.srcStages |= srcStages;
                    prev.srcAccess |= srcAccess;
                    noteFirstUses(out.size() - 1, resource, texture, q, info, i, j);
                    i = j;
                    continue;
                }
            }
            noteFirstUses(out.size(), resource, texture, q, info, i, j);
            out.emplace_back(Barrier{resource, Subresource{mip, 1, layer, layerCount}, aspect, srcStages, srcAccess,
                                     s.stages, s.access, oldLayout, texture ? s.layout : VK_IMAGE_LAYOUT_UNDEFINED,
                                     false});
            i = j;
        }
        if (st_.log) {
            const ir::Resource& r = d_.resources[resource];
            for (size_t k = firstBarrier; k < out.size(); ++k)
                if (!holdsFirstUse(k)) spdlog::debug("rg barriers: {}", describeBarrier(r.name, out[k], r.kind));
        }
    }

    // Records the first uses among needs_[first, last) of a use of
    // `resource` on queue q, merged into barrier `barrier`.
    void noteFirstUses(size_t barrier, uint32_t resource, bool texture, uint32_t q, const UseInfo* info, size_t first,
                       size_t last) {
        for (size_t k = first; k < last; ++k)
            if (needs_[k].firstUse) [[unlikely]]
                firstUses_.push_back({static_cast<uint32_t>(barrier), needs_[k].cell, resource, q, texture, info});
    }

    // Whether barrier k waits for resolveFirstUses() (debug logging only).
    bool holdsFirstUse(size_t k) const {
        return std::any_of(firstUses_.begin(), firstUses_.end(), [&](const FirstUse& f) { return f.barrier == k; });
    }

    // emit() of a use of one cell (most uses): one barrier, nothing to merge.
    void emitOne(uint32_t resource, const UseRef& ref, const Subresource& range, const SyncScope& s, const Need& n,
                 uint32_t q) {
        if (n.firstUse) [[unlikely]]
            firstUses_.push_back(
                {static_cast<uint32_t>(st_.plan.barriers.size()), n.cell, resource, q, ref.texture, ref.info});
        // Constructed from its fields (braces: clang 14 has no parenthesised
        // aggregate initialisation). The aspect is read only when a barrier
        // needs it; the aliasing flag is set by resolveFirstUses() where
        // bytes are shared.
        const Barrier& b = st_.plan.barriers.emplace_back(Barrier{
            resource, ref.texture ? Subresource{range.baseMip, 1, range.baseLayer, 1} : Subresource{0, 1, 0, 1},
            ref.texture ? st_.plan.resources[resource].aspect : 0, n.srcStages, n.srcAccess, s.stages, s.access,
            ref.texture ? n.oldLayout : VK_IMAGE_LAYOUT_UNDEFINED, ref.texture ? s.layout : VK_IMAGE_LAYOUT_UNDEFINED,
            false});
        if (st_.log && !n.firstUse) {
            const ir::Resource& r = d_.resources[resource];
            spdlog::debug("rg barriers: {}", describeBarrier(r.name, b, r.kind));
        }
    }

    void walkPass(uint32_t pos) {
        pos_ = pos;
        const uint32_t p = st_.order[pos];
        const ir::Pass& pass = d_.passes[p];
        const uint32_t q = queueIndex(st_.queueOf[p]);
        clearPending();
        needs_.clear();
        useNeed_.clear();
        refs_.clear();
        for (uint32_t u = pass.firstUse; u < pass.firstUse + pass.useCount; ++u) {
            const UseRef& ref = refs_.emplace_back(useRefOf(pass, u));
            useNeed_.push_back(static_cast<uint32_t>(needs_.size()));
            // Most uses name one cell: analysed directly, not through forCells' callback.
            if (ref.single)
                analyse(needs_.emplace_back(), ref.cell, q, *ref.info, ref.writes, ref.texture);
            else
                forCells(d_.resources[d_.uses[u].resource], d_.uses[u].range,
                         [&](uint32_t c) { analyse(needs_.emplace_back(), c, q, *ref.info, ref.writes, ref.texture); });
        }
        useNeed_.push_back(static_cast<uint32_t>(needs_.size())); // use i's needs end where use i + 1's begin
        // A new wait changes only what uses that asked crossQueue() get;
        // whether a use asks depends on its cell alone, so those needs,
        // analysed again in the same order, replay the requests as a
        // second full pass would.
        if (pending_[0].active || pending_[1].active) {
            for (uint32_t i = 0; i < pass.useCount; ++i) {
                const UseRef& ref = refs_[i];
                for (size_t k = useNeed_[i]; k < useNeed_[i + 1]; ++k) {
                    if (!needs_[k].waits) continue;
                    const uint32_t cell = needs_[k].cell;
                    needs_[k] = Need{};
                    analyse(needs_[k], cell, q, *ref.info, ref.writes, ref.texture);
                }
            }
        }
        const uint32_t ordinal = batches_.placePass(static_cast<Queue>(q), pos, pending_);
        const TimelinePoint now{0, ordinal};

        st_.barrierFirst[pos] = static_cast<uint32_t>(st_.plan.barriers.size());
        for (uint32_t i = 0; i < pass.useCount; ++i) {
            const UseRef& ref = refs_[i];
            const UseInfo& info = *ref.info;
            const SyncScope& s = info.scope;
            const size_t first = useNeed_[i];
            const size_t last = useNeed_[i + 1];
            if (ref.single) {
                const Need& n = needs_[first];
                if (n.barrier)
                    emitOne(d_.uses[pass.firstUse + i].resource, ref, d_.uses[pass.firstUse + i].range, s, n, q);
                update(n, q, info, ref.writes, now);
                continue;
            }
            // Most uses need no barrier; emit() is not worth a call for them.
            size_t firstBarrier = first;
            while (firstBarrier < last && !needs_[firstBarrier].barrier) ++firstBarrier;
            if (firstBarrier < last) {
                const ir::Use& use = d_.uses[pass.firstUse + i];
                emit(use.resource, ref.texture, ref.texture ? st_.plan.resources[use.resource].aspect : 0, use.range, s,
                     first, last, q, ref.info);
            }
            for (size_t k = first; k < last; ++k) update(needs_[k], q, info, ref.writes, now);
        }
        st_.barrierCount[pos] = static_cast<uint32_t>(st_.plan.barriers.size()) - st_.barrierFirst[pos];
    }

    // ---- Frame end --------------------------------------------------------------

    void finalStates() {
        // The imports that end in a state someone cares about, by the queue
        // of that state, with its scope looked up once.
        std::vector<FinalImport>* targets = scratch_.finalImports;
        std::vector<UseInfo>& rawFinals = scratch_.rawFinals;
        targets[0].clear();
        targets[1].clear();
        rawFinals.clear();
        rawFinals.reserve(imports_.size()); // keeps pointers into it valid
        for (uint32_t r : imports_) {
            const ir::Resource& res = d_.resources[r];
            if (!res.hasFinal) continue;
            if (!res.final.isRaw && res.final.access == Access::None) continue; // the caller does not care
            if (!st_.lifetimes[r].used() && res.hasInitial && res.initial == res.final) continue;
            FinalImport& target = targets[queueIndex(st_.boundaryQueue(res.final.queue))].emplace_back();
            target.resource = r;
            target.cellBase = res.cellBase;
            target.cellCount = res.cellCount;
            target.texture = res.kind == ResourceKind::Texture;
            // A state named by an access kind is a use of that kind: the table has its masks.
            target.state = res.final.isRaw ? &rawFinals.emplace_back(makeUseInfo(boundaryScope(res.final, res.kind)))
                                           : &useInfoOf(res.final.access, res.kind, res.final.pipeline);
        }
        for (uint32_t qi = 0; qi < kQueueCount; ++qi) {
            const auto q = static_cast<Queue>(qi);
            clearPending();
            finals_.clear();
            needs_.clear();
            for (const FinalImport& target : targets[qi]) {
                // Every cell, mip-major, is the run of cells from cellBase.
                const auto first = static_cast<uint32_t>(needs_.size());
                bool matters = false;
                for (uint32_t c = target.cellBase; c < target.cellBase + target.cellCount; ++c) {
                    Need& n = needs_.emplace_back();
                    analyseFinal(n, c, qi, *target.state, target.texture);
                    matters = matters || n.barrier || n.waits;
                }
                // Most imports end as the frame left them: nothing to keep.
                if (matters)
                    finals_.push_back({&target, first, static_cast<uint32_t>(needs_.size())});
                else
                    needs_.resize(first);
            }
            // As in walkPass(): a new wait changes only the needs that asked
            // for one, and analysing those again in order replays the requests.
            if (pending_[0].active || pending_[1].active) {
                for (const Final& f : finals_) {
                    for (uint32_t k = f.firstNeed; k < f.endNeed; ++k) {
                        if (!needs_[k].waits) continue;
                        const uint32_t cell = needs_[k].cell;
                        needs_[k] = Need{};
                        analyseFinal(needs_[k], cell, qi, *f.target->state, f.target->texture);
                    }
                }
            }
            std::erase_if(finals_, [&](const Final& f) {
                return std::none_of(needs_.begin() + f.firstNeed, needs_.begin() + f.endNeed,
                                    [](const Need& n) { return n.barrier; });
            });
            // A final state can need only a wait: the import must be visible on
            // its final queue after the other queue's last use.
            if (finals_.empty() && !pending_[0].active && !pending_[1].active) continue;
            batches_.placeEnd(q, pending_);
            const auto firstBarrier = static_cast<uint32_t>(st_.plan.barriers.size());
            for (const Final& f : finals_) {
                const uint32_t r = f.target->resource;
                const bool texture = f.target->texture;
                emit(r, texture, texture ? st_.plan.resources[r].aspect : 0, wholeOf(d_.resources[r]),
                     f.target->state->scope, f.firstNeed, f.endNeed, qi, nullptr);
            }
            batches_.setEndBarriers(q, firstBarrier, static_cast<uint32_t>(st_.plan.barriers.size()) - firstBarrier);
        }
    }

    // A request's other fields mean nothing while it is inactive. (Clearing
    // the flag alone also spares a store-forwarding stall per pass that
    // copying a fresh WaitRequest costs.)
    void clearPending() { pending_[0].active = pending_[1].active = false; }

    static Subresource wholeOf(const ir::Resource& r) {
        return r.kind == ResourceKind::Texture ? Subresource{0, r.texture.mips, 0, r.texture.layers}
                                               : Subresource{0, 1, 0, 1};
    }

    CompileState& st_;
    const ir::Declaration& d_;
    BatchBuilder batches_;
    Scratch& scratch_;
    std::vector<Cell>& cells_ = scratch_.cells;
    std::vector<EndState>& ends_ = scratch_.ends;
    std::vector<Visibility>& endSeen_ = scratch_.endSeen;     // history cells: visibility at the frame's end
    std::vector<uint8_t>& early_ = scratch_.early;
    std::vector<UseRef>& refs_ = scratch_.passRefs; // the walked pass's uses, in order
    std::vector<UseInfo>& mergedInfo_ = scratch_.mergedInfo;
    std::vector<Need>& needs_ = scratch_.needs;
    std::vector<uint32_t>& useNeed_ = scratch_.useNeed;
    std::vector<Final>& finals_ = scratch_.finals;
    std::vector<uint32_t>& imports_ = scratch_.imports;
    std::vector<FirstUse>& firstUses_ = scratch_.firstUses;
    std::vector<LastUses>& aliasedPriors_ = scratch_.aliasedPriors;
    WaitRequest pending_[kQueueCount];
    uint32_t pos_ = 0; // schedule position of the pass being walked
};

} // namespace

void placeBarriersAndBatches(CompileState& st) { Walk(st).run(); }

void refreshUseInfo(Access a, ResourceKind k, Pipeline p) {
    kUseInfo.info[static_cast<uint32_t>(a)][static_cast<uint32_t>(k)][static_cast<uint32_t>(p)] =
        makeUseInfo(scopeOf(a, k, p));
}

} // namespace glint::rg::detail
