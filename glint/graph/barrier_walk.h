#pragma once

// What the barrier walk keeps, shared by the two files that run it:
// barriers.cpp (the walk over the schedule: each use's hazards and the
// barriers and waits they need, and the imports' final states) and
// barrier_frame_start.cpp (where each resource starts the frame).
// barriers.cpp explains the walk. Internal to glint_graph: nothing else
// includes it.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <iterator>
#include <string_view>
#include <utility>
#include <vector>

#include "glint/graph/batches.h"
#include "glint/graph/compile_state.h"

namespace glint::rg::detail::barrier_walk {

inline bool within(VkFlags64 inner, VkFlags64 outer) { return (inner & ~outer) == 0; }

// Visibility is tracked per stage: the stages uses can name (the access
// table's, transfers as one) each keep the access bits made visible there,
// packed into 16 bits (the access bits the table uses; any other bit is
// the last one, which only a semaphore wait makes visible).
inline constexpr VkPipelineStageFlags2 kTrackedStages[] = {
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
inline constexpr uint32_t kStageSlots = std::size(kTrackedStages);

inline constexpr VkAccessFlags2 kPackedAccess[] = {
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
inline constexpr uint16_t kOtherAccess = 1u << 15;
inline constexpr uint16_t kAnyPacked = 0xFFFF;

struct PackTable {
    uint16_t bit[64] = {};
    constexpr PackTable() {
        for (uint32_t b = 0; b < 64; ++b) bit[b] = kOtherAccess;
        for (uint32_t i = 0; i < std::size(kPackedAccess); ++i)
            bit[std::countr_zero(kPackedAccess[i])] = uint16_t(1u << i);
    }
};
inline constexpr PackTable kPack;

inline uint16_t pack(VkAccessFlags2 a) {
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
inline constexpr SlotTable kSlots;

inline Slots slotsOf(VkPipelineStageFlags2 s) {
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

inline VisMask maskOf(Slots s, uint16_t a) {
    VisMask m;
    m.untracked = s.untracked;
    for (uint32_t rest = s.mask; rest; rest &= rest - 1) {
        const auto slot = static_cast<uint32_t>(std::countr_zero(rest));
        m.word[slot / 4] |= uint64_t{a} << (16 * (slot % 4));
    }
    return m;
}

inline VisMask maskOf(VkPipelineStageFlags2 stages, uint16_t a) { return maskOf(slotsOf(stages), a); }

// One declared use, looked up in the access table once per compile.
struct UseInfo {
    SyncScope scope;
    VkAccessFlags2 reads = 0;       // the read bits of scope.access
    VkAccessFlags2 writeAccess = 0; // and its write bits
    VisMask accessMask;             // its stages x its accesses
    VisMask readMask;               // its stages x its reads
};

inline UseInfo makeUseInfo(const SyncScope& scope) {
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

// The table of every single access kind (defined in barriers.cpp).
extern UseInfoTable kUseInfo;

inline const UseInfo& useInfoOf(Access a, ResourceKind k, Pipeline p) {
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

// The calling thread's (barriers.cpp).
Scratch& scratch();

// The walk over one compile's schedule (placeBarriersAndBatches). Its
// functions live in barriers.cpp (the walk: hazards, emission, frame end)
// and barrier_frame_start.cpp. Those marked inline are used only in the file
// that defines them: inline, as when the walk was one class body, so the
// compiler inlines them as it did then (measured: out of line, the walk ran
// some 13% more instructions).
class Walk {
public:
    explicit Walk(CompileState& st) : st_(st), d_(st.decl), batches_(st), scratch_(scratch()) {}

    inline void run();

private:
    // ---- Frame start (barrier_frame_start.cpp) --------------------------------

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

    void initialiseCells();
    [[noreturn]] inline void priorsElsewhere(uint32_t r) const;
    void resolveFirstUses();
    inline void applyEnd(const ir::Pass& pass, uint32_t u, uint32_t q);
    inline void seedHistoryPrevious(uint32_t current);
    inline void startImport(uint32_t r);
    inline void startHistory(uint32_t r);
    inline std::string_view lastUserName(uint32_t r) const;
    inline void startAliased();
    inline void addAliasedPriors(uint32_t r, const LastUses& priors);
    inline LastUses summary(uint32_t r) const;
    inline LastUses lastUsesOf(uint32_t c, uint32_t q, uint32_t r) const;

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

    // ---- Hazards, emission, frame end (barriers.cpp) ----------------------------

    inline VkPipelineStageFlags2 crossQueue(uint32_t q, uint32_t from, TimelinePoint point,
                                            VkPipelineStageFlags2 stages);
    [[gnu::always_inline]] inline void analyse(Need& n, uint32_t c, uint32_t q, const UseInfo& use, bool writes,
                                               bool texture);
    static inline VkPipelineStageFlags2 ownStages(const SyncScope& s);
    [[gnu::noinline]] void viaOtherQueue(Need& n, uint32_t q, const SyncScope& s, uint32_t from, TimelinePoint point,
                                         bool makesVisible);
    inline void analyseFinal(Need& n, uint32_t c, uint32_t q, const UseInfo& state, bool texture);
    [[gnu::always_inline]] inline void update(const Need& n, uint32_t q, const UseInfo& use, bool writes,
                                              TimelinePoint now);
    inline void emit(uint32_t resource, bool texture, VkImageAspectFlags aspect, const Subresource& range,
                     const SyncScope& s, size_t first, size_t last, uint32_t q, const UseInfo* info);
    inline void noteFirstUses(size_t barrier, uint32_t resource, bool texture, uint32_t q, const UseInfo* info,
                              size_t first, size_t last);
    inline bool holdsFirstUse(size_t k) const;
    inline void emitOne(uint32_t resource, const UseRef& ref, const Subresource& range, const SyncScope& s,
                        const Need& n, uint32_t q);
    inline void walkPass(uint32_t pos);
    inline void finalStates();
    static inline Subresource wholeOf(const ir::Resource& r);

    // A request's other fields mean nothing while it is inactive. (Clearing
    // the flag alone also spares a store-forwarding stall per pass that
    // copying a fresh WaitRequest costs.)
    void clearPending() { pending_[0].active = pending_[1].active = false; }

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

} // namespace glint::rg::detail::barrier_walk
