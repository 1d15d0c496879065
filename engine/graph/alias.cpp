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
// lifetimes, no quadratic interference test. A sweep by offset then marks
// the resources that share bytes: barriers.cpp makes their first uses wait
// for the last users of those bytes, and an alias starts from UNDEFINED.

#include <algorithm>
#include <queue>

#include <spdlog/spdlog.h>

#include "graph/compile_state.h"

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
    uint64_t size;
    uint64_t alignment;
};

struct Block {
    uint64_t offset;
    uint64_t size;
};

// Vulkan alignments are powers of two: a mask, not a 64-bit division, in
// the best-fit scan.
uint64_t alignUp(uint64_t v, uint64_t a) {
    if ((a & (a - 1)) == 0) [[likely]]
        return (v + a - 1) & ~(a - 1);
    return (v + a - 1) / a * a;
}

// Places items (sorted by first use) into one heap; returns its size.
uint64_t place(std::vector<Item>& items, std::vector<uint64_t>& offsets, bool alias) {
    std::vector<Block> free; // sorted by offset, coalesced
    uint64_t top = 0;
    auto byLast = [&](uint32_t a, uint32_t b) { return items[a].last > items[b].last; };
    std::priority_queue<uint32_t, std::vector<uint32_t>, decltype(byLast)> live(byLast);

    auto release = [&](uint32_t i) {
        Block b{offsets[i], items[i].size};
        auto it = std::lower_bound(free.begin(), free.end(), b.offset,
                                   [](const Block& x, uint64_t off) { return x.offset < off; });
        it = free.insert(it, b);
        if (it + 1 != free.end() && it->offset + it->size == (it + 1)->offset) {
            it->size += (it + 1)->size;
            free.erase(it + 1);
        }
        if (it != free.begin() && (it - 1)->offset + (it - 1)->size == it->offset) {
            (it - 1)->size += it->size;
            free.erase(it);
        }
    };

    for (uint32_t i = 0; i < items.size(); ++i) {
        const Item& item = items[i];
        if (alias) {
            while (!live.empty() && items[live.top()].last < item.first) {
                release(live.top());
                live.pop();
            }
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
            Block block = free[best];
            offset = alignUp(block.offset, item.alignment);
            free.erase(free.begin() + static_cast<ptrdiff_t>(best));
            const uint64_t tail = block.offset + block.size - (offset + item.size);
            if (tail) free.insert(free.begin() + static_cast<ptrdiff_t>(best), Block{offset + item.size, tail});
            if (offset > block.offset)
                free.insert(free.begin() + static_cast<ptrdiff_t>(best), Block{block.offset, offset - block.offset});
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
        live.push(i);
    }
    return top;
}

} // namespace

void aliasMemory(CompileState& st) {
    const ir::Declaration& d = st.decl;
    Plan& plan = st.plan;
    const MemoryRequirementsFn& requirementsOf = st.options.memoryRequirements;

    st.aliased.assign(d.resources.size(), 0);
    std::vector<HeapKey> keys;
    std::vector<std::vector<Item>> heapItems;

    for (uint32_t r = 0; r < d.resources.size(); ++r) {
        const ir::Resource& res = d.resources[r];
        const Lifetime& life = st.lifetimes[r];
        if (res.origin != ir::Origin::Transient || !life.used()) continue;
        PlannedResource& out = plan.resources[r];
        TransientDescription desc;
        desc.name = res.name;
        desc.kind = res.kind;
        desc.texture = res.texture;
        desc.buffer = res.buffer;
        desc.imageUsage = out.imageUsage;
        desc.bufferUsage = out.bufferUsage;
        const MemoryRequirements req = requirementsOf ? requirementsOf(desc) : estimateMemoryRequirements(desc);
        const uint64_t alignment = std::max<uint64_t>(req.alignment, 1);
        out.size = alignUp(req.size, alignment);
        out.alignment = alignment;
        plan.stats.transientBytes += out.size;

        const HeapKey key{life.crossQueue() ? 2u : queueIndex(out.queue), req.memoryTypeBits};
        auto it = std::find(keys.begin(), keys.end(), key);
        if (it == keys.end()) {
            keys.push_back(key);
            heapItems.emplace_back();
            it = keys.end() - 1;
        }
        const auto h = static_cast<uint32_t>(it - keys.begin());
        out.heap = h;
        const uint64_t granularity = std::max<uint64_t>(st.caps.bufferImageGranularity, 1);
        heapItems[h].push_back(
            {r, life.first, life.last, alignUp(out.size, granularity), std::max(alignment, granularity)});
    }

    std::vector<uint64_t> offsets;
    std::vector<uint32_t> byOffset, sortScratch;
    for (uint32_t h = 0; h < keys.size(); ++h) {
        std::vector<Item>& items = heapItems[h];
        // Ties on first use: larger first, so big resources get the low bytes.
        std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
            return a.first != b.first ? a.first < b.first
                                      : (a.size != b.size ? a.size > b.size : a.resource < b.resource);
        });
        offsets.assign(items.size(), 0);
        const bool alias = st.options.aliasing && keys[h].queueOrShared != 2;
        MemoryHeap heap;
        heap.queue = keys[h].queueOrShared == 1 ? Queue::AsyncCompute : Queue::Graphics;
        heap.crossQueue = keys[h].queueOrShared == 2;
        heap.memoryTypeBits = keys[h].memoryTypeBits;
        heap.size = place(items, offsets, alias);
        for (const Item& item : items) {
            heap.alignment = std::max(heap.alignment, item.alignment);
            const bool image = d.resources[item.resource].kind == ResourceKind::Texture;
            heap.images = heap.images || image;
            heap.buffers = heap.buffers || !image;
        }
        for (uint32_t i = 0; i < items.size(); ++i) plan.resources[items[i].resource].offset = offsets[i];
        plan.heaps.push_back(heap);
        plan.stats.aliasedTransientBytes += heap.size;

        if (!alias) continue;
        // Sweep by offset: a resource is aliased when it starts below the end
        // of an earlier one or the next one starts below its end.
        // (Which of several resources at one offset comes first does not
        // change the outcome: each is aliased by the other.)
        byOffset.resize(items.size());
        for (uint32_t i = 0; i < items.size(); ++i) byOffset[i] = i;
        radixSort(byOffset, sortScratch, [&](uint32_t i) { return offsets[i]; });
        uint64_t reach = 0;
        for (uint32_t i = 0; i < byOffset.size(); ++i) {
            const uint32_t a = byOffset[i];
            const uint64_t begin = offsets[a], end = begin + items[a].size;
            const bool next = i + 1 < byOffset.size() && offsets[byOffset[i + 1]] < end;
            if ((i > 0 && begin < reach) || next) st.aliased[items[a].resource] = 1;
            reach = std::max(reach, end);
        }
        if (st.log)
            for (uint32_t i = 0; i < items.size(); ++i)
                spdlog::debug("rg alias: '{}' heap {} [{}, +{}) passes {}..{}{}", d.resources[items[i].resource].name,
                              h, offsets[i], items[i].size, items[i].first, items[i].last,
                              st.aliased[items[i].resource] ? ", shares bytes" : "");
    }
}

} // namespace glint::rg::detail
