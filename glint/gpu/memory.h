#pragma once
// Device memory suballocation: memory is taken from the driver in large
// blocks and handed out as (block, offset) ranges. A range can be bound to
// more than one resource; the render graph uses that to alias transients
// whose lifetimes do not overlap.

#include "glint/gpu/fault.h"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace glint::gpu {

class Context;

// First-fit allocator over [0, capacity) with coalescing frees. Pure logic:
// it knows nothing of Vulkan and is tested on its own.
class RangeAllocator {
public:
    explicit RangeAllocator(uint64_t capacity);

    // Offset of a free range of `size` bytes aligned to `alignment` (a power
    // of two), or nothing when no free range fits.
    std::optional<uint64_t> allocate(uint64_t size, uint64_t alignment);
    // Returns [offset, offset + size) to the free list; it must have come
    // from allocate() with the same size.
    void free(uint64_t offset, uint64_t size);

    uint64_t capacity() const { return capacity_; }
    uint64_t used() const { return used_; }
    bool empty() const { return used_ == 0; }
    size_t freeRangeCount() const { return free_.size(); }

private:
    uint64_t capacity_;
    uint64_t used_ = 0;
    std::map<uint64_t, uint64_t> free_;  // offset -> size, no two adjacent
};

enum class MemoryUsage {
    DeviceLocal,  // GPU only
    Upload,       // host-visible, coherent, written by the CPU every frame or once
    Readback,     // host-visible, cached, read by the CPU
};

// What a range of device memory is: enough to bind a resource to it.
struct MemoryRange {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
    std::byte* mapped = nullptr;  // non-null for host-visible memory
    uint32_t memoryTypeIndex = 0;
};

class MemoryAllocator;

// Owns one suballocation; returns it to its block when destroyed.
class Allocation {
public:
    Allocation() = default;
    Allocation(Allocation&& other) noexcept { *this = std::move(other); }
    Allocation& operator=(Allocation&& other) noexcept;
    Allocation(const Allocation&) = delete;
    Allocation& operator=(const Allocation&) = delete;
    ~Allocation() { reset(); }

    void reset();
    explicit operator bool() const { return owner_ != nullptr; }
    const MemoryRange& range() const { return range_; }

private:
    friend class MemoryAllocator;
    MemoryAllocator* owner_ = nullptr;
    uint32_t block_ = 0;
    uint64_t blockOffset_ = 0;  // where the aligned range's padding starts
    uint64_t blockSize_ = 0;    // bytes reserved in the block, padding included
    MemoryRange range_;
};

struct MemoryStats {
    uint64_t blockBytes = 0;  // taken from the driver
    uint64_t usedBytes = 0;   // handed out
    uint32_t blockCount = 0;
};

class MemoryAllocator {
public:
    // Blocks are `blockSize` bytes; a request over half of that gets a block
    // of its own so one large image does not strand a block's tail.
    // `faults` (may be null) is asked before each vkAllocateMemory.
    MemoryAllocator(VkPhysicalDevice physicalDevice, VkDevice device, FaultInjector* faults = nullptr,
                    VkDeviceSize blockSize = 64ull << 20);
    ~MemoryAllocator();
    MemoryAllocator(const MemoryAllocator&) = delete;
    MemoryAllocator& operator=(const MemoryAllocator&) = delete;

    // `linear`: buffers and linear images vs optimal-tiling images. They are
    // kept in separate blocks so bufferImageGranularity never matters.
    Allocation allocate(const VkMemoryRequirements& requirements, MemoryUsage usage, bool linear,
                        std::string_view name);

    uint32_t findMemoryType(uint32_t typeBits, MemoryUsage usage) const;
    MemoryStats stats() const;

private:
    friend class Allocation;
    struct Block {
        VkDeviceMemory memory = VK_NULL_HANDLE;
        uint32_t memoryTypeIndex = 0;
        bool linear = true;
        bool dedicated = false;
        std::byte* mapped = nullptr;
        std::unique_ptr<RangeAllocator> ranges;
    };
    uint32_t createBlock(uint32_t memoryTypeIndex, VkDeviceSize size, bool linear, bool dedicated,
                         std::string_view name);
    void release(uint32_t block, uint64_t offset, uint64_t size);

    VkDevice device_;
    FaultInjector* faults_ = nullptr;
    VkPhysicalDeviceMemoryProperties properties_{};
    VkDeviceSize blockSize_;
    mutable std::mutex mutex_;
    std::vector<Block> blocks_;  // index = block id; freed dedicated blocks leave a null slot
};

} // namespace glint::gpu
