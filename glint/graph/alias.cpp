// ---- Alias ------------------------------------------------------------------
// Transients go into heaps keyed by (queue, memory type bits): never across
// queues, since within a frame two queues run concurrently and only a
// semaphore could order one resource's last use before the other's first;
// resources used on both queues get bytes of their own in a cross-queue
// heap. Buffers and optimal images share heaps (a frame's buffers mostly
// live while images of another stage are dead); every placement starts and
// ends on a bufferImageGranularity boundary, so a linear and an optimal
// resource never share a page.
//
// Placement walks each heap's resources in order of first use, releasing
// those whose last use is behind and placing each new one in the
// best-fitting free block (or at the top). It is linear-scan register
// allocation over bytes: O(n log n), good packing for frame-shaped
// lifetimes, no quadratic interference test. A sweep over the offsets then
// marks the resources that share bytes: the barrier walk
// (barrier_frame_start.cpp) makes their first uses wait for the last users
// of those bytes, and an alias starts from UNDEFINED.

#include <algorithm>
#include <bit>

#include <spdlog/spdlog.h>

#include "glint/graph/compile_state.h"

namespace glint::rg::detail {
namespace {

struct HeapKey {
    uint32_t queueOrShared; // 0 graphics, 1 async compute, 2 both queues
    uint32_t memoryTypeBits;
    friend bool operator==(const HeapKey&, const HeapKey&) = default;
};

struct Item {
    uint32_t resource;
    uint32_t first;
    uint32_t last;
    uint32_t heap; // index into the heap keys (fills what was padding)
    uint64_t size;
    uint64_t alignment;
};

struct Block {
    uint64_t offset;
    uint64_t size;
};

// The items of one heap placed at one offset, in a slot of the hash table
// from offsets to them.
struct OffsetGroup {
    uint64_t offset = 0;
    uint64_t end = 0;       // the furthest any of them reaches
    uint64_t below = 0;     // the furthest the groups at lower offsets reach
    uint64_t above = ~0ull; // the next offset up
    uint32_t count = 0;     // how many
    uint32_t stamp = 0;     // the call that filled the slot
};

// Vulkan alignments are powers of two: a mask, not a 64-bit division, in
// the best-fit scan.
uint64_t alignUp(uint64_t v, uint64_t a) {
    if ((a & (a - 1)) == 0) [[likely]]
        return (v + a - 1) & ~(a - 1);
    return (v + a - 1) / a * a;
}

// compile() runs every frame: the vectors keep their storage from one
// compile to the next (as the barrier walk's scratch does, barrier_walk.h).
struct Scratch {
    std::vector<HeapKey> keys;
    std::vector<Item> all;                       // used transients in resource order
    std::vector<Item> items;                     // the counting sort's output, where `all` is out of order
    std::vector<uint32_t> heapBegin;             // per heap: its span of the sorted items, then the end
    std::vector<uint32_t> count;                 // counting-sort buckets
    std::vector<uint64_t> offsets;               // per item of the heap being placed
    std::vector<Block> free;                     // the free list, between placements
    std::vector<uint32_t> releaseAt, next;       // per position / item: items by last use
    std::vector<OffsetGroup> groups;             // markShared's hash table
    uint32_t stamp = 0;                          // of the slots markShared's current call filled
    std::vector<uint32_t> groupOf;               // per item: its slot
    std::vector<uint32_t> byOffset, sortScratch; // the filled slots in order of offset
};

Scratch& scratch() {
    thread_local Scratch s;
    return s;
}

// Places items (sorted by first use) into one heap, writing each offset to
// `offsets` (by item) and to the planned resource; returns the heap's size.
// `positions` bounds every first and last use. Out of line: inlined into
// aliasMemory, its loop ran short of registers.
[[gnu::noinline]] uint64_t place(const Item* items, uint32_t n, uint64_t* offsets, PlannedResource* planned, bool alias,
                                 uint32_t positions, Scratch& s) {
    // The free list, sorted by offset and coalesced, is lent to a local for
    // the loop: as a member of the thread's scratch, every store through
    // `offsets` could change it as far as the compiler knows.
    std::vector<Block> free;
    free.swap(s.free);
    free.clear();
    uint64_t top = 0;
    // Items to release, listed by last use: after placing item i, it joins
    // the list of its last position, and each first use releases the lists
    // of the positions before it. Release order among them does not matter:
    // the free list stays coalesced, so it depends only on which bytes are
    // free.
    if (alias) {
        s.releaseAt.assign(positions, kNoIndex);
        s.next.resize(n);
    }
    uint32_t* const releaseAt = s.releaseAt.data();
    uint32_t* const next = s.next.data();
    uint32_t released = 0; // positions before this one have been released

    auto release = [&](uint32_t i) {
        const Block b{offsets[i], items[i].size};
        // The first block above it, by a scan: the list is short, and the
        // best-fit scan walks all of it for every item anyway.
        auto it = free.begin();
        while (it != free.end() && it->offset < b.offset) ++it;
        const bool joinsPrev = it != free.begin() && (it - 1)->offset + (it - 1)->size == b.offset;
        const bool joinsNext = it != free.end() && b.offset + b.size == it->offset;
        // Grow a neighbour in place where one touches: an insert shifts the
        // vector's tail.
        if (joinsPrev && joinsNext) {
            (it - 1)->size += b.size + it->size;
            free.erase(it);
        } else if (joinsPrev) {
            (it - 1)->size += b.size;
        } else if (joinsNext) {
            it->offset = b.offset;
            it->size += b.size;
        } else {
            free.insert(it, b);
        }
    };

    for (uint32_t i = 0; i < n; ++i) {
        const Item& item = items[i];
        if (alias) {
            for (; released < item.first; ++released)
                for (uint32_t r = releaseAt[released]; r != kNoIndex; r = next[r]) release(r);
        }
        // Best fit: the free block that leaves the least over.
        size_t best = free.size();
        uint64_t bestWaste = ~0ull;
        for (size_t b = 0; b < free.size(); ++b) {
            const uint64_t start = alignUp(free[b].offset, item.alignment);
            const uint64_t end = free[b].offset + free[b].size;
            if (start + item.size > end) continue;
            const uint64_t waste = free[b].size - item.size;
            if (waste < bestWaste) {
                bestWaste = waste;
                best = b;
                if (waste == 0) break; // nothing fits better
            }
        }
        uint64_t offset;
        if (best != free.size()) {
            const Block block = free[best];
            offset = alignUp(block.offset, item.alignment);
            // What is left of the block: the alignment gap below the item
            // and the tail above it, each in the block's place in order.
            const uint64_t tail = block.offset + block.size - (offset + item.size);
            const auto at = free.begin() + static_cast<ptrdiff_t>(best);
            if (offset > block.offset) {
                *at = Block{block.offset, offset - block.offset};
                if (tail) free.insert(at + 1, Block{offset + item.size, tail});
            } else if (tail) {
                *at = Block{offset + item.size, tail};
            } else {
                free.erase(at);
            }
        } else if (!free.empty() && free.back().offset + free.back().size == top &&
                   alignUp(free.back().offset, item.alignment) + item.size > top) {
            // Grow the heap from the free block at its top instead of past it.
            const Block block = free.back();
            free.pop_back();
            offset = alignUp(block.offset, item.alignment);
            if (offset > block.offset) free.push_back(Block{block.offset, offset - block.offset});
            top = offset + item.size;
        } else {
            offset = alignUp(top, item.alignment);
            if (offset > top) free.push_back(Block{top, offset - top});
            top = offset + item.size;
        }
        offsets[i] = offset;
        planned[item.resource].offset = offset;
        if (alias) {
            next[i] = releaseAt[item.last];
            releaseAt[item.last] = i;
        }
    }
    free.swap(s.free);
    return top;
}

// Marks the items that share bytes with another item of the heap: those
// at an offset where another one starts too, those starting below the end
// of one at a lower offset, those ending above the next offset up.
// Placement puts many items at a few offsets (a tiled frame's resources go
// where the previous tile's were), so the sweep runs over the distinct
// offsets, gathered in a hash table, instead of sorting the items.
void markShared(const Item* items, uint32_t n, const uint64_t* offsets, uint8_t* aliased, Scratch& s) {
    // At most half full. A slot is taken when it carries this call's stamp,
    // so the table is not cleared for every heap of every frame.
    const auto bits = static_cast<uint32_t>(std::bit_width(std::max<size_t>(2 * size_t{n}, 16) - 1));
    const size_t mask = (size_t{1} << bits) - 1;
    if (s.groups.size() <= mask) s.groups.resize(mask + 1);
    if (++s.stamp == 0) { // wrapped: no slot may look taken
        std::fill(s.groups.begin(), s.groups.end(), OffsetGroup{});
        s.stamp = 1;
    }
    const uint32_t stamp = s.stamp;
    OffsetGroup* const groups = s.groups.data();
    // Room for every item in a group of its own: the loop appends without a
    // capacity check.
    std::vector<uint32_t>& byOffset = s.byOffset;
    byOffset.resize(n);
    uint32_t groupCount = 0;
    s.groupOf.resize(n);
    uint32_t* const groupOf = s.groupOf.data();
    for (uint32_t i = 0; i < n; ++i) {
        const uint64_t offset = offsets[i];
        auto g = static_cast<uint32_t>((offset * 0x9E3779B97F4A7C15ull) >> (64 - bits));
        while (groups[g].stamp == stamp && groups[g].offset != offset) g = (g + 1) & mask;
        if (groups[g].stamp != stamp) {
            groups[g] = {.offset = offset, .stamp = stamp};
            byOffset[groupCount++] = g;
        }
        groupOf[i] = g;
        groups[g].end = std::max(groups[g].end, offset + items[i].size);
        ++groups[g].count;
    }
    byOffset.resize(groupCount);
    radixSort(byOffset, s.sortScratch, [&](uint32_t g) { return groups[g].offset; });
    uint64_t reach = 0;
    for (uint32_t k = 0; k < groupCount; ++k) {
        OffsetGroup& group = groups[byOffset[k]];
        group.below = reach;
        if (k + 1 < groupCount) group.above = groups[byOffset[k + 1]].offset;
        reach = std::max(reach, group.end);
    }
    for (uint32_t i = 0; i < n; ++i) {
        const OffsetGroup& group = groups[groupOf[i]];
        if (group.count > 1 || offsets[i] < group.below || group.above < offsets[i] + items[i].size)
            aliased[items[i].resource] = 1;
    }
}

struct Collected {
    uint32_t count; // items in s.all
    bool inOrder;   // sorted by (heap, first use) already
};

// Sizes the used transients and lists them as items in s.all, in resource
// order; each heap is described in plan.heaps (keyed in s.keys) when its
// first member turns up. Out of line, like place().
[[gnu::noinline]] Collected collect(CompileState& st, Scratch& s) {
    const ir::Declaration& d = st.decl;
    Plan& plan = st.plan;
    const MemoryRequirementsFn& requirementsOf = st.options.memoryRequirements;
    const uint64_t granularity = std::max<uint64_t>(st.caps.bufferImageGranularity, 1);
    std::vector<HeapKey>& keys = s.keys;
    keys.clear();
    // Room for every resource: the loop appends without a capacity check.
    if (s.all.size() < d.resources.size()) s.all.resize(d.resources.size());
    Item* const all = s.all.data();
    uint32_t n = 0;

    // Local pointers: the stores into the plan could alias any vector's
    // data pointer as far as the compiler knows.
    const ir::Resource* const resources = d.resources.data();
    const Lifetime* const lifetimes = st.lifetimes.data();
    PlannedResource* const planned = plan.resources.data();
    const auto resourceCount = static_cast<uint32_t>(d.resources.size());
    const bool custom = static_cast<bool>(requirementsOf);
    // The previous transient's heap, which most share: its index, key and
    // description (plan.heaps grows only where this is looked up).
    uint32_t heapOf = kNoIndex;
    HeapKey heapKey{};
    MemoryHeap* memberHeap = nullptr;
    uint64_t transientBytes = 0;
    uint64_t previousOrder = 0; // (heap, first use) of the previous transient
    bool inOrder = true;
    for (uint32_t r = 0; r < resourceCount; ++r) {
        const ir::Resource& res = resources[r];
        const Lifetime& life = lifetimes[r];
        if (res.origin != ir::Origin::Transient || !life.used()) continue;
        PlannedResource& out = planned[r];
        const TransientDescription desc{res.name, res.kind, res.texture, res.buffer, out.imageUsage, out.bufferUsage};
        const MemoryRequirements req = custom ? requirementsOf(desc) : estimateMemoryRequirements(desc);
        const uint64_t alignment = std::max<uint64_t>(req.alignment, 1);
        out.size = alignUp(req.size, alignment);
        out.alignment = alignment;
        transientBytes += out.size;

        const HeapKey key{life.crossQueue() ? 2u : queueIndex(out.queue), req.memoryTypeBits};
        if (heapOf == kNoIndex || !(key == heapKey)) {
            heapOf = static_cast<uint32_t>(std::find(keys.begin(), keys.end(), key) - keys.begin());
            if (heapOf == keys.size()) {
                keys.push_back(key);
                MemoryHeap& added = plan.heaps.emplace_back();
                added.queue = key.queueOrShared == 1 ? Queue::AsyncCompute : Queue::Graphics;
                added.crossQueue = key.queueOrShared == 2;
                added.memoryTypeBits = key.memoryTypeBits;
            }
            heapKey = key;
            memberHeap = &plan.heaps[heapOf];
        }
        const uint64_t placedAlignment = std::max(alignment, granularity);
        memberHeap->alignment = std::max(memberHeap->alignment, placedAlignment);
        memberHeap->images |= res.kind == ResourceKind::Texture;
        memberHeap->buffers |= res.kind != ResourceKind::Texture;
        out.heap = heapOf;
        all[n++] = {r, life.first, life.last, heapOf, alignUp(out.size, granularity), placedAlignment};
        const uint64_t order = uint64_t{heapOf} << 32 | life.first;
        inOrder = inOrder && order >= previousOrder;
        previousOrder = order;
    }
    plan.stats.transientBytes += transientBytes;
    return {n, inOrder};
}

} // namespace

void aliasMemory(CompileState& st) {
    const ir::Declaration& d = st.decl;
    Plan& plan = st.plan;
    Scratch& s = scratch();
    const auto positions = static_cast<uint32_t>(st.order.size());
    st.aliased.assign(d.resources.size(), 0);
    const auto [n, inOrder] = collect(st, s);
    Item* const all = s.all.data();
    PlannedResource* const planned = plan.resources.data();

    // Placement order: by first use, larger first on ties (big resources
    // get the low bytes), then by resource. One counting sort by (heap,
    // first use) gives each heap its items in first-use order, in resource
    // order within a position (it is stable); the runs sharing a first use
    // are short and get an insertion sort by size. Resources are mostly
    // declared in order of first use, and a frame mostly has one heap: when
    // the items come in that order already, they stay where they are.
    const auto heaps = static_cast<uint32_t>(s.keys.size());
    std::vector<uint32_t>& heapBegin = s.heapBegin;
    heapBegin.assign(heaps + 1, 0);
    Item* sorted = all;
    if (inOrder) {
        for (uint32_t h = 1; h <= heaps; ++h)
            heapBegin[h] = static_cast<uint32_t>(
                std::partition_point(all, all + n, [h](const Item& item) { return item.heap < h; }) - all);
    } else {
        const uint32_t buckets = heaps * positions;
        std::vector<uint32_t>& count = s.count;
        count.assign(buckets + 1, 0);
        for (uint32_t i = 0; i < n; ++i) ++count[all[i].heap * positions + all[i].first + 1];
        for (uint32_t b = 0; b < buckets; ++b) count[b + 1] += count[b];
        for (uint32_t h = 0; h <= heaps; ++h) heapBegin[h] = count[h * positions];
        s.items.resize(n);
        sorted = s.items.data();
        for (uint32_t i = 0; i < n; ++i) sorted[count[all[i].heap * positions + all[i].first]++] = all[i];
    }
    for (uint32_t h = 0; h < heaps; ++h) {
        Item* const items = sorted + heapBegin[h];
        const uint32_t size = heapBegin[h + 1] - heapBegin[h];
        for (uint32_t i = 1; i < size; ++i) {
            if (items[i].first != items[i - 1].first || items[i].size <= items[i - 1].size) continue;
            // Stable: equal sizes stay in resource order.
            const Item moving = items[i];
            uint32_t j = i;
            for (; j > 0 && items[j - 1].first == moving.first && items[j - 1].size < moving.size; --j)
                items[j] = items[j - 1];
            items[j] = moving;
        }
    }

    std::vector<uint64_t>& offsets = s.offsets;
    for (uint32_t h = 0; h < heaps; ++h) {
        const Item* const items = sorted + heapBegin[h];
        const uint32_t size = heapBegin[h + 1] - heapBegin[h];
        offsets.resize(size);
        MemoryHeap& heap = plan.heaps[h];
        const bool alias = st.options.aliasing && !heap.crossQueue;
        heap.size = place(items, size, offsets.data(), planned, alias, positions, s);
        plan.stats.aliasedTransientBytes += heap.size;

        if (!alias) continue;
        markShared(items, size, offsets.data(), st.aliased.data(), s);
        if (st.log)
            for (uint32_t i = 0; i < size; ++i)
                spdlog::debug("rg alias: '{}' heap {} [{}, +{}) passes {}..{}{}", d.resources[items[i].resource].name,
                              h, offsets[i], items[i].size, items[i].first, items[i].last,
                              st.aliased[items[i].resource] ? ", shares bytes" : "");
    }
}

} // namespace glint::rg::detail
