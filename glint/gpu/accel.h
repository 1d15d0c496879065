#pragma once
// Acceleration structures (BLAS and TLAS) with their backing buffers, and
// the description of a build: geometry, sizes, and the recording of the
// build command with caller-provided scratch memory (the render graph
// provides scratch for per-frame builds).

#include "glint/gpu/resources.h"

#include <vulkan/vulkan.h>

#include <span>
#include <string>
#include <vector>

namespace glint::gpu {

class Context;

struct TriangleGeometry {
    VkDeviceAddress vertices = 0;
    VkDeviceSize vertexStride = 12;
    uint32_t vertexCount = 0;
    VkFormat vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    VkDeviceAddress indices = 0;  // 0: unindexed (three vertices per triangle)
    VkIndexType indexType = VK_INDEX_TYPE_UINT32;
    uint32_t triangleCount = 0;
    bool opaque = true;
};

// Everything vkCmdBuildAccelerationStructuresKHR needs, kept together so the
// pointers inside stay valid.
class AccelBuild {
public:
    static AccelBuild bottomLevel(Context& ctx, std::span<const TriangleGeometry> geometries,
                                  VkBuildAccelerationStructureFlagsKHR flags);
    // `instances`: device address of `count` VkAccelerationStructureInstanceKHR.
    static AccelBuild topLevel(Context& ctx, VkDeviceAddress instances, uint32_t count,
                               VkBuildAccelerationStructureFlagsKHR flags);

    VkAccelerationStructureTypeKHR type() const { return info_.type; }
    VkDeviceSize structureSize() const { return sizes_.accelerationStructureSize; }
    // Scratch bytes, padded so an aligned start fits inside (see alignScratch).
    VkDeviceSize scratchSize() const { return sizes_.buildScratchSize + scratchAlignment_; }
    VkDeviceAddress alignScratch(VkDeviceAddress address) const {
        return (address + scratchAlignment_ - 1) / scratchAlignment_ * scratchAlignment_;
    }

    // Records the build into `dst` using scratch at `scratch` (aligned here).
    void record(const Context& ctx, VkCommandBuffer cmd, VkAccelerationStructureKHR dst, VkDeviceAddress scratch);

private:
    AccelBuild() = default;
    void querySizes(Context& ctx, std::span<const uint32_t> primitiveCounts);

    VkAccelerationStructureBuildGeometryInfoKHR info_{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    std::vector<VkAccelerationStructureGeometryKHR> geometries_;
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges_;
    VkAccelerationStructureBuildSizesInfoKHR sizes_{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    VkDeviceSize scratchAlignment_ = 1;
};

class AccelerationStructure {
public:
    AccelerationStructure() = default;
    // `sharedAcrossQueues`: the storage buffer is shared by the graphics and
    // async compute families (built on one queue, traced on the other).
    AccelerationStructure(Context& ctx, VkAccelerationStructureTypeKHR type, VkDeviceSize size, std::string name,
                          bool sharedAcrossQueues = false);
    AccelerationStructure(AccelerationStructure&&) noexcept = default;
    AccelerationStructure& operator=(AccelerationStructure&&) noexcept = default;

    VkAccelerationStructureKHR handle() const { return as_.get(); }
    VkDeviceAddress address() const { return address_; }
    const Buffer& buffer() const { return buffer_; }
    const std::string& name() const { return name_; }

private:
    std::string name_;
    Buffer buffer_;  // declared first: destroyed after the structure
    Unique<VkAccelerationStructureKHR> as_;
    VkDeviceAddress address_ = 0;
};

// Builds `build` into a new structure on the graphics queue and waits; for
// one-time static builds and tests (per-frame builds go through the graph).
AccelerationStructure buildNow(Context& ctx, AccelBuild& build, const std::string& name);

// A VkAccelerationStructureInstanceKHR for `blas` with a row-major 3x4
// transform. flags: VkGeometryInstanceFlagBitsKHR.
VkAccelerationStructureInstanceKHR makeInstance(const AccelerationStructure& blas, const float transform[12],
                                                uint32_t customIndex, uint8_t mask = 0xff, uint32_t sbtOffset = 0,
                                                VkGeometryInstanceFlagsKHR flags = 0);

} // namespace glint::gpu
