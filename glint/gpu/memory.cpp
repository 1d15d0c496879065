#include "glint/gpu/memory.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

namespace glint::gpu {

namespace {
uint64_t alignUp(uint64_t value, uint64_t alignment) { return (value + alignment - 1) & ~(alignment - 1); }
} // namespace

// ---------------------------------------------------------------- RangeAllocator

RangeAllocator::RangeAllocator(uint64_t capacity) : capacity_(capacity) {
    if (capacity > 0) {
        free_.emplace(0, capacity);
    }
}

std::optional<uint64_t> RangeAllocator::allocate(uint64_t size, uint64_t alignment) {
    if (size == 0 || alignment == 0 || (alignment & (alignment - 1)) != 0) {
        return std::nullopt;
    }
    for (auto it = free_.begin(); it != free_.end(); ++it) {
        const uint64_t start = it->first;
        const uint64_t end = start + it->second;
        const uint64_t aligned = alignUp(start, alignment);
        if (aligned < start || aligned > end || end - aligned < size) {
            continue;
        }
        free_.erase(it);
        // Keep the head padding and the tail as free ranges.
        if (aligned > start) {
            free_.emplace(start, aligned - start);
        }
        if (aligned + size < end) {
            free_.emplace(aligned + size, end - (aligned + size));
        }
        used_ += size;
        return aligned;
    }
    return std::nullopt;
}

void RangeAllocator::free(uint64_t offset, uint64_t size) {
    auto next = free_.lower_bound(offset);
    uint64_t start = offset;
    uint64_t length = size;
    if (next != free_.begin()) {
        auto prev = std::prev(next);
        if (prev->first + prev->second == offset) {
            start = prev->first;
            length += prev->second;
            free_.erase(prev);
        }
    }
    if (next != free_.end() && offset + size == next->first) {
        length += next->second;
        free_.erase(next);
    }
    free_.emplace(start, length);
    used_ -= size;
}

// ---------------------------------------------------------------- Allocation

Allocation& Allocation::operator=(Allocation&& other) noexcept {
    if (this != &other) {
        reset();
        owner_ = std::exchange(other.owner_, nullptr);
        block_ = other.block_;
        blockOffset_ = other.blockOffset_;
        blockSize_ = other.blockSize_;
        range_ = std::exchange(other.range_, {});
    }
    return *this;
}

void Allocation::reset() {
    if (owner_ != nullptr) {
        owner_->release(block_, blockOffset_, blockSize_);
        owner_ = nullptr;
        range_ = {};
    }
}

// ---------------------------------------------------------------- MemoryAllocator

MemoryAllocator::MemoryAllocator(VkPhysicalDevice physicalDevice, VkDevice device, FaultInjector* faults,
                                 VkDeviceSize blockSize)
    : device_(device), faults_(faults), blockSize_(blockSize) {
    vkGetPhysicalDeviceMemoryProperties(physicalDevice, &properties_);
}

MemoryAllocator::~MemoryAllocator() {
    for (auto& block : blocks_) {
        if (block.memory != VK_NULL_HANDLE) {
            if (block.ranges && !block.ranges->empty()) {
                spdlog::warn("memory: block of type {} destroyed with {} bytes still allocated",
                             block.memoryTypeIndex, block.ranges->used());
            }
            vkFreeMemory(device_, block.memory, nullptr);
        }
    }
}

uint32_t MemoryAllocator::findMemoryType(uint32_t typeBits, MemoryUsage usage) const {
    VkMemoryPropertyFlags required = 0;
    VkMemoryPropertyFlags preferred = 0;
    switch (usage) {
    case MemoryUsage::DeviceLocal: preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT; break;
    case MemoryUsage::Upload:
        required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
        break;
    case MemoryUsage::Readback:
        required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
        break;
    }
    // Pass 1 wants required + preferred; pass 2 settles for required.
    for (VkMemoryPropertyFlags want : {required | preferred, required}) {
        for (uint32_t i = 0; i < properties_.memoryTypeCount; ++i) {
            if ((typeBits & (1u << i)) && (properties_.memoryTypes[i].propertyFlags & want) == want) {
                return i;
            }
        }
    }
    throw GpuError("memory: no memory type for type bits 0x" + std::to_string(typeBits) +
                   " with the required properties");
}

uint32_t MemoryAllocator::createBlock(uint32_t memoryTypeIndex, VkDeviceSize size, bool linear, bool dedicated,
                                      std::string_view name) {
    // Every block can hold buffers with device addresses (acceleration
    // structure inputs, scratch, shader binding tables).
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.pNext = &flags;
    info.allocationSize = size;
    info.memoryTypeIndex = memoryTypeIndex;
    Block block;
    block.memoryTypeIndex = memoryTypeIndex;
    block.linear = linear;
    block.dedicated = dedicated;
    VkResult result = faults_ ? faults_->next(FaultSite::Allocation) : VK_SUCCESS;
    if (result == VK_SUCCESS) result = vkAllocateMemory(device_, &info, nullptr, &block.memory);
    if (result != VK_SUCCESS) {
        throw GpuError("memory: allocating " + std::to_string(size) + " bytes for '" + std::string(name) +
                       "' failed: " + std::string(resultName(result)));
    }
    if (properties_.memoryTypes[memoryTypeIndex].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
        void* mapped = nullptr;
        result = vkMapMemory(device_, block.memory, 0, VK_WHOLE_SIZE, 0, &mapped);
        if (result != VK_SUCCESS) {
            vkFreeMemory(device_, block.memory, nullptr);
            throw GpuError("memory: mapping a block for '" + std::string(name) +
                           "' failed: " + std::string(resultName(result)));
        }
        block.mapped = static_cast<std::byte*>(mapped);
    }
    block.ranges = std::make_unique<RangeAllocator>(size);
    spdlog::debug("memory: new {} block of {} KiB, type {} (for '{}')", dedicated ? "dedicated" : "shared",
                  size >> 10, memoryTypeIndex, name);
    for (uint32_t i = 0; i < blocks_.size(); ++i) {
        if (blocks_[i].memory == VK_NULL_HANDLE) {
            blocks_[i] = std::move(block);
            return i;
        }
    }
    blocks_.push_back(std::move(block));
    return static_cast<uint32_t>(blocks_.size() - 1);
}

Allocation MemoryAllocator::allocate(const VkMemoryRequirements& requirements, MemoryUsage usage, bool linear,
                                     std::string_view name) {
    const uint32_t type = findMemoryType(requirements.memoryTypeBits, usage);
    const uint64_t alignment = std::max<uint64_t>(requirements.alignment, 1);
    std::lock_guard lock(mutex_);

    auto place = [&](uint32_t blockIndex) -> std::optional<Allocation> {
        Block& block = blocks_[blockIndex];
        auto offset = block.ranges->allocate(requirements.size, alignment);
        if (!offset) {
            return std::nullopt;
        }
        Allocation a;
        a.owner_ = this;
        a.block_ = blockIndex;
        a.blockOffset_ = *offset;
        a.blockSize_ = requirements.size;
        a.range_ = {block.memory, *offset, requirements.size, block.mapped ? block.mapped + *offset : nullptr, type};
        return a;
    };

    const bool dedicated = requirements.size > blockSize_ / 2;
    if (!dedicated) {
        for (uint32_t i = 0; i < blocks_.size(); ++i) {
            const Block& b = blocks_[i];
            if (b.memory != VK_NULL_HANDLE && !b.dedicated && b.memoryTypeIndex == type && b.linear == linear) {
                if (auto a = place(i)) {
                    return std::move(*a);
                }
            }
        }
    }
    const uint32_t index = createBlock(type, dedicated ? requirements.size : blockSize_, linear, dedicated, name);
    auto a = place(index);
    if (!a) {
        throw GpuError("memory: a fresh block cannot hold '" + std::string(name) + "' (alignment " +
                       std::to_string(alignment) + ")");
    }
    return std::move(*a);
}

void MemoryAllocator::release(uint32_t blockIndex, uint64_t offset, uint64_t size) {
    std::lock_guard lock(mutex_);
    Block& block = blocks_[blockIndex];
    block.ranges->free(offset, size);
    // Dedicated blocks go back to the driver at once; shared blocks are kept
    // for reuse (transient memory is recreated rarely, not every frame).
    if (block.dedicated && block.ranges->empty()) {
        vkFreeMemory(device_, block.memory, nullptr);
        block = Block{};
    }
}

MemoryStats MemoryAllocator::stats() const {
    std::lock_guard lock(mutex_);
    MemoryStats s;
    for (const auto& b : blocks_) {
        if (b.memory != VK_NULL_HANDLE) {
            s.blockBytes += b.ranges->capacity();
            s.usedBytes += b.ranges->used();
            ++s.blockCount;
        }
    }
    return s;
}

} // namespace glint::gpu
