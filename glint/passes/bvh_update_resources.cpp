// BvhManager's per-object state on the GPU and the buffers that grow with
// the scene: a mesh geometry's source vertices, indices and skin uploaded
// the first time a BLAS uses it (copied by the frame's pass, FrameWork::
// uploads), BLASes created, and the primitive pool, deform motion, TLAS,
// offset and material tables, joint palettes and morphed vertex buffers
// grown in powers of two (bvh_update_internal.h, grownCapacity).

#include "glint/passes/bvh_update_internal.h"

#include "glint/scene/packed_primitives.h"

#include "glint/packing.h"

#include <cstring>
#include <string>

namespace glint::passes {

namespace bvh_update_detail {

std::vector<shader::BvhSourceVertex> sourceVertices(const scene::Scene& scene, const scene::Geometry& g) {
    std::vector<shader::BvhSourceVertex> vertices(g.vertexCount());
    for (uint32_t v = 0; v < g.vertexCount(); ++v) {
        const shader::SurfaceVertex s = scene::surfaceAtVertex(scene, g, v);
        const shader::PackedVertex packed = shader::packVertex(s);
        vertices[v] = {g.positions[v], s.normal, packed.albedoSmoothness,
                       packed.normalMetallicReflectance & 0xFFFF0000u};
    }
    return vertices;
}

} // namespace bvh_update_detail

using namespace bvh_update_detail;

// ---------------------------------------------------------------------------
// Uploads and growth
// ---------------------------------------------------------------------------

const BvhManager::SourceGeometry& BvhManager::sourceGeometry(uint32_t mesh, uint32_t lod, uint32_t geometry,
                                                             FrameWork& work) {
    auto& slot = geometries_[{mesh, lod, geometry}];
    if (slot) {
        return *slot;
    }
    const scene::Geometry& g = scene_.meshes.at(mesh).lods.at(lod).geometries.at(geometry);
    const std::string name = "bvh." + scene_.meshes[mesh].name + ".lod" + std::to_string(lod) + ".geometry" +
                             std::to_string(geometry);
    // Sampled once: see sourceVertices.
    const std::vector<shader::BvhSourceVertex> vertices = sourceVertices(scene_, g);
    auto source = std::make_unique<SourceGeometry>();
    source->triangleCount = g.triangleCount();
    // `target` is filled by the frame's pass (FrameWork::uploads); the
    // staging lives until that frame has finished.
    const auto upload = [&](gpu::Buffer& target, const void* data, size_t bytes, const std::string& what) {
        const VkDeviceSize size = std::max<VkDeviceSize>(bytes, 4);
        auto staging = std::make_shared<gpu::Buffer>(
            ctx_, gpu::BufferDesc{size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                  name + what + ".staging", true});
        std::memcpy(staging->mapped(), data, bytes);
        target = gpu::Buffer(ctx_, {size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                    gpu::MemoryUsage::DeviceLocal, name + what, true});
        stats_.uploadBytes += size;
        retired_.keepShared(staging, frame_);
        work.uploads.push_back({std::move(staging), &target});
    };
    upload(source->vertices, vertices.data(), vertices.size() * sizeof(vertices[0]), ".vertices");
    upload(source->indices, g.indices.data(), g.indices.size() * sizeof(uint32_t), ".indices");
    stats_.geometryBytes += source->vertices.size() + source->indices.size();
    if (g.skinned()) {
        std::vector<shader::BvhSkinVertex> skin(g.vertexCount());
        for (uint32_t v = 0; v < g.vertexCount(); ++v) {
            const glm::u16vec4 j = g.joints[v];
            skin[v] = {glm::uvec2(uint32_t(j.x) | uint32_t(j.y) << 16, uint32_t(j.z) | uint32_t(j.w) << 16),
                       g.weights[v]};
        }
        upload(source->skin, skin.data(), skin.size() * sizeof(skin[0]), ".skin");
        stats_.geometryBytes += source->skin.size();
    }
    ++stats_.uploadedGeometries;
    slot = std::move(source);
    return *slot;
}

BvhManager::ResidentBlas& BvhManager::createBlas(const scene::BlasDesc& desc, FrameWork& work) {
    auto blas = std::make_unique<ResidentBlas>();
    blas->desc = desc;
    const std::string name = "bvh.blas" + std::to_string(desc.id) + "." + scene_.meshes.at(desc.mesh).name;
    blas->positions = gpu::Buffer(ctx_, {std::max<VkDeviceSize>(VkDeviceSize(desc.triangleCount) * 3 * sizeof(glm::vec3), 12),
                                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kBuildInput,
                                         gpu::MemoryUsage::DeviceLocal, name + ".positions", true});
    std::vector<gpu::TriangleGeometry> triangles;
    VkDeviceSize first = 0;
    for (const scene::BlasGeometry& g : desc.geometries) {
        blas->sources.push_back(&sourceGeometry(desc.mesh, desc.lod, g.meshGeometry, work));
        blas->materialRows.push_back(hitMaterials_->row(desc.mesh, desc.lod, g.meshGeometry));
        gpu::TriangleGeometry t;
        t.vertices = blas->positions.address() + first * sizeof(glm::vec3);
        t.vertexCount = 3 * g.triangleCount;
        t.triangleCount = g.triangleCount;
        // Alpha-tested geometry runs the any-hit test (glint/alpha_test.h);
        // everything else stays opaque, so rays never stop on it for a test.
        t.opaque = blas->materialRows.back().alphaTriangles == shader::kAlphaOpaque;
        triangles.push_back(t);
        first += 3 * VkDeviceSize(g.triangleCount);
    }
    const bool deformable = desc.motion != scene::Motion::Static;
    blas->build = gpu::AccelBuild::bottomLevel(ctx_, triangles, deformable ? options_.deformableFlags : options_.staticFlags);
    blas->structure = gpu::AccelerationStructure(ctx_, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                 blas->build->structureSize(), name, true);
    stats_.blasBytes += blas->structure.buffer().size();
    stats_.positionBytes += blas->positions.size();
    auto& slot = blases_[desc.id];
    slot = std::move(blas);
    return *slot;
}

void BvhManager::ensurePool(uint32_t triangles, FrameWork& work) {
    const VkDeviceSize needed = std::max<VkDeviceSize>(triangles, 1) * sizeof(shader::PackedPrimitive);
    if (pool_ && pool_.size() >= needed) {
        return;
    }
    const VkDeviceSize capacity = grownCapacity(needed, 1024 * sizeof(shader::PackedPrimitive));
    gpu::Buffer grown(ctx_, {capacity,
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                 VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             gpu::MemoryUsage::DeviceLocal, "bvh.primitive_pool", true});
    if (pool_) {
        // Static BLASes were packed once; their primitives must survive.
        work.poolCopyBytes = pool_.size();
        work.poolCopySource = std::make_shared<gpu::Buffer>(std::move(pool_));
        retired_.keepShared(work.poolCopySource, frame_);
        ++stats_.poolGrowths;
    }
    pool_ = std::move(grown);
    stats_.poolBytes = pool_.size();
}

void BvhManager::ensureDeformMotion(uint64_t triangles) {
    const VkDeviceSize needed = std::max<uint64_t>(triangles, 1) * sizeof(shader::DeformMotion);
    if (deformMotion_ && deformMotion_.size() >= needed) {
        return;
    }
    // Each frame writes what it reads: nothing to keep from the old one.
    if (deformMotion_) {
        stats_.deformMotionBytes -= deformMotion_.size();
        retire(std::move(deformMotion_));
    }
    deformMotion_ = gpu::Buffer(ctx_, {grownCapacity(needed, kMinDeformMotionBytes), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                       gpu::MemoryUsage::DeviceLocal, "bvh.deform_motion", true});
    stats_.deformMotionBytes += deformMotion_.size();
}

void BvhManager::ensureTlas(uint32_t instances) {
    if (tlas_ && instances <= tlasCapacity_) {
        return;
    }
    tlasCapacity_ = uint32_t(grownCapacity(instances, kMinTlasInstances));
    for (gpu::Buffer& buffer : instanceBuffers_) {
        if (buffer) retire(std::move(buffer));
        buffer = gpu::Buffer(ctx_, {VkDeviceSize(tlasCapacity_) * sizeof(VkAccelerationStructureInstanceKHR), kBuildInput,
                                    gpu::MemoryUsage::Upload, "bvh.tlas_instances", true});
    }
    // Sized for the capacity so instance counts up to it reuse the structure.
    const gpu::AccelBuild sizing =
        gpu::AccelBuild::topLevel(ctx_, instanceBuffers_[0].address(), tlasCapacity_, options_.tlasFlags);
    if (tlas_) retire(std::move(tlas_));
    tlas_ = std::make_unique<gpu::AccelerationStructure>(ctx_, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                                         sizing.structureSize(), "bvh.tlas", true);
    stats_.tlasBytes = tlas_->buffer().size();
}

void BvhManager::ensureOffsets(size_t entries) {
    const VkDeviceSize needed = std::max<VkDeviceSize>(entries, 1) * sizeof(uint32_t);
    if (offsets_ && offsets_.size() >= needed) {
        return;
    }
    const VkDeviceSize capacity = grownCapacity(needed, kMinOffsetEntries * sizeof(uint32_t));
    if (offsets_) retire(std::move(offsets_));
    offsets_ = gpu::Buffer(ctx_, {capacity, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                  gpu::MemoryUsage::DeviceLocal, "bvh.primitive_offsets", true});
    for (gpu::Buffer& staging : offsetStaging_) {
        if (staging) retire(std::move(staging));
        staging = gpu::Buffer(ctx_, {capacity, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                     "bvh.primitive_offsets.staging", true});
    }
    // The material table has as many rows.
    const VkDeviceSize materialCapacity = capacity / sizeof(uint32_t) * kMaterialRowBytes;
    if (materials_) retire(std::move(materials_));
    materials_ = gpu::Buffer(ctx_, {materialCapacity, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                    gpu::MemoryUsage::DeviceLocal, "bvh.materials", true});
    for (gpu::Buffer& staging : materialStaging_) {
        if (staging) retire(std::move(staging));
        staging = gpu::Buffer(ctx_, {materialCapacity, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                     "bvh.materials.staging", true});
    }
}

void BvhManager::ensureJointPalette(size_t matrices) {
    const VkDeviceSize needed = std::max<VkDeviceSize>(matrices, 1) * sizeof(glm::mat4);
    for (gpu::Buffer& palette : jointPalettes_) {
        if (palette && palette.size() >= needed) continue;
        if (palette) retire(std::move(palette));
        palette = gpu::Buffer(ctx_, {grownCapacity(needed, 64 * sizeof(glm::mat4)), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     gpu::MemoryUsage::Upload, "bvh.joint_palette", true});
    }
}

const gpu::Buffer& BvhManager::morphedVertexBuffer(ResidentBlas& blas, size_t geometryIndex, uint32_t slot,
                                                  VkDeviceSize bytes) {
    // Sized once for every slot and geometry: the frame's packs keep
    // pointers to these buffers, which must not move.
    if (blas.morphedVertices.empty()) {
        blas.morphedVertices.resize(framesInFlight_);
        for (std::vector<gpu::Buffer>& buffers : blas.morphedVertices) {
            buffers.resize(blas.desc.geometries.size());
        }
    }
    std::vector<gpu::Buffer>& buffers = blas.morphedVertices.at(slot);
    gpu::Buffer& buffer = buffers.at(geometryIndex);
    if (!buffer || buffer.size() < bytes) {
        if (buffer) retire(std::move(buffer));
        buffer = gpu::Buffer(ctx_, {std::max<VkDeviceSize>(bytes, 4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                    gpu::MemoryUsage::Upload, "bvh.morphed_vertices", true});
    }
    return buffer;
}

} // namespace glint::passes
