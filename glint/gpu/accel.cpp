#include "glint/gpu/accel.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/context.h"
#include "glint/gpu/error.h"

#include <cstring>

namespace glint::gpu {

namespace {
void requireAccel(const Context& ctx) {
    if (!ctx.caps().accelerationStructure) {
        throw GpuError("device '" + ctx.caps().deviceName + "' has no VK_KHR_acceleration_structure");
    }
}
} // namespace

AccelBuild AccelBuild::bottomLevel(Context& ctx, std::span<const TriangleGeometry> geometries,
                                   VkBuildAccelerationStructureFlagsKHR flags) {
    requireAccel(ctx);
    AccelBuild b;
    std::vector<uint32_t> counts;
    for (const auto& g : geometries) {
        VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
        geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
        geometry.flags = g.opaque ? VK_GEOMETRY_OPAQUE_BIT_KHR : 0;
        auto& t = geometry.geometry.triangles;
        t = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR};
        t.vertexFormat = g.vertexFormat;
        t.vertexData.deviceAddress = g.vertices;
        t.vertexStride = g.vertexStride;
        t.maxVertex = g.vertexCount > 0 ? g.vertexCount - 1 : 0;
        t.indexType = g.indices ? g.indexType : VK_INDEX_TYPE_NONE_KHR;
        t.indexData.deviceAddress = g.indices;
        b.geometries_.push_back(geometry);
        b.ranges_.push_back({g.triangleCount, 0, 0, 0});
        counts.push_back(g.triangleCount);
    }
    b.info_.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    b.info_.flags = flags;
    b.querySizes(ctx, counts);
    return b;
}

AccelBuild AccelBuild::topLevel(Context& ctx, VkDeviceAddress instances, uint32_t count,
                                VkBuildAccelerationStructureFlagsKHR flags) {
    requireAccel(ctx);
    AccelBuild b;
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geometry.geometry.instances = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
    geometry.geometry.instances.data.deviceAddress = instances;
    b.geometries_.push_back(geometry);
    b.ranges_.push_back({count, 0, 0, 0});
    b.info_.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    b.info_.flags = flags;
    const uint32_t counts[] = {count};
    b.querySizes(ctx, counts);
    return b;
}

void AccelBuild::querySizes(Context& ctx, std::span<const uint32_t> primitiveCounts) {
    info_.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info_.geometryCount = static_cast<uint32_t>(geometries_.size());
    info_.pGeometries = geometries_.data();
    ctx.fn().getAccelerationStructureBuildSizes(ctx.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info_,
                                                primitiveCounts.data(), &sizes_);
    scratchAlignment_ = std::max<VkDeviceSize>(ctx.caps().rayTracing.minScratchOffsetAlignment, 1);
}

void AccelBuild::record(const Context& ctx, VkCommandBuffer cmd, VkAccelerationStructureKHR dst,
                        VkDeviceAddress scratch) {
    info_.pGeometries = geometries_.data();  // the object may have moved since querySizes
    info_.dstAccelerationStructure = dst;
    info_.scratchData.deviceAddress = alignScratch(scratch);
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = ranges_.data();
    ctx.fn().cmdBuildAccelerationStructures(cmd, 1, &info_, &ranges);
}

AccelerationStructure::AccelerationStructure(Context& ctx, VkAccelerationStructureTypeKHR type, VkDeviceSize size,
                                             std::string name, bool sharedAcrossQueues)
    : name_(std::move(name)) {
    requireAccel(ctx);
    buffer_ = Buffer(ctx, {size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, MemoryUsage::DeviceLocal,
                           name_ + ".storage", sharedAcrossQueues});
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer_.handle();
    info.size = size;
    info.type = type;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    check(ctx.fn().createAccelerationStructure(ctx.device(), &info, nullptr, &as),
          "vkCreateAccelerationStructureKHR '" + name_ + "'");
    as_ = Unique<VkAccelerationStructureKHR>(ctx.device(), as, ctx.fn().destroyAccelerationStructure);
    VkAccelerationStructureDeviceAddressInfoKHR addressInfo{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    addressInfo.accelerationStructure = as;
    address_ = ctx.fn().getAccelerationStructureDeviceAddress(ctx.device(), &addressInfo);
    ctx.setName(as, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, name_);
}

AccelerationStructure buildNow(Context& ctx, AccelBuild& build, const std::string& name) {
    AccelerationStructure as(ctx, build.type(), build.structureSize(), name);
    Buffer scratch(ctx, {build.scratchSize(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal,
                         name + ".scratch"});
    submitAndWait(ctx, ctx.graphicsQueue(), "build '" + name + "'", [&](VkCommandBuffer cmd) {
        // Inputs were written by earlier submissions (uploads end with a
        // full barrier); order this build's reads after them anyway.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_2_SHADER_READ_BIT);
        build.record(ctx, cmd, as.handle(), scratch.address());
        // Make the structure visible to every later use (ray query,
        // ray tracing shaders, TLAS builds reading a BLAS).
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    });
    return as;
}

VkAccelerationStructureInstanceKHR makeInstance(const AccelerationStructure& blas, const float transform[12],
                                                uint32_t customIndex, uint8_t mask, uint32_t sbtOffset,
                                                VkGeometryInstanceFlagsKHR flags) {
    VkAccelerationStructureInstanceKHR instance{};
    std::memcpy(&instance.transform, transform, sizeof(float) * 12);
    instance.instanceCustomIndex = customIndex & 0xffffffu;
    instance.mask = mask;
    instance.instanceShaderBindingTableRecordOffset = sbtOffset & 0xffffffu;
    instance.flags = flags & 0xffu;
    instance.accelerationStructureReference = blas.address();
    return instance;
}

} // namespace glint::gpu
