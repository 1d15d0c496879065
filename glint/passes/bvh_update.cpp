// The BVH update pass: BvhManager's frame -- what to build, pack and copy,
// decided on the CPU when the pass is declared (prepare, the particles'
// quads included), then recorded (record) -- and the pass's declaration in
// a graph (addBvhUpdatePass). Per-object state and the buffers that grow
// with the scene are made in bvh_update_resources.cpp.

#include "glint/passes/bvh_update.h"
#include "glint/passes/bvh_update_internal.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/scene/animation.h"
#include "glint/scene/packed_primitives.h"
#include "glint/scene/smoke_scene.h"

#include "glint/bvh_shared.h"
#include "glint/packing.h"
#include "glint/particles_shared.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <optional>
#include <string>

namespace glint::passes {

namespace {

// Where a world point on `instance` this frame was last frame: its last
// transform after the inverse of this one (in double: a far instance's
// float inverse would move still points). Identity for a still instance.
glm::mat4 instanceMotion(const scene::Instance& instance) {
    if (instance.previousTransform == instance.transform) return glm::mat4(1.0f);
    return glm::mat4(glm::dmat4(instance.previousTransform) * glm::inverse(glm::dmat4(instance.transform)));
}

void setPreviousFromCurrent(shader::RtGeometryMaterial& row, const glm::mat4& m) {
    for (int r = 0; r < 3; ++r) {
        row.previousFromCurrent[r] = glm::vec4(m[0][r], m[1][r], m[2][r], m[3][r]);  // glm is column-major
    }
}

VkPipelineStageFlags2 traceStages(const gpu::Capabilities& caps) {
    VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    if (caps.rayTracingPipeline) {
        stages |= VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR;
    }
    return stages;
}

} // namespace

using namespace bvh_update_detail;

rg::BoundaryState tracedAccelState(const gpu::Capabilities& caps) {
    return rg::BoundaryState::raw(traceStages(caps), VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
                                  VK_IMAGE_LAYOUT_UNDEFINED, rg::Queue::Graphics);
}

rg::BoundaryState tracedBufferState(const gpu::Capabilities& caps) {
    return rg::BoundaryState::raw(traceStages(caps), VK_ACCESS_2_SHADER_STORAGE_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                  rg::Queue::Graphics);
}

BvhManager::BvhManager(gpu::Context& ctx, const scene::Scene& scene, uint32_t framesInFlight,
                       const BvhUpdateOptions& options)
    : ctx_(ctx),
      scene_(scene),
      framesInFlight_(std::max(framesInFlight, 1u)),
      options_(options),
      hitMaterials_(std::make_unique<HitMaterials>(ctx, scene, options.hitMaterials)),
      assets_(scene::assetStamp(scene)),
      retired_(framesInFlight_) {
    packPipeline_ = gpu::createComputePipeline(
        ctx, {"bvh/pack_primitives.comp", {}, sizeof(shader::BvhPackParams), "bvh.pack_primitives"});
    particleQuadsPipeline_ = gpu::createComputePipeline(
        ctx, {"bvh/particle_quads.comp", {}, sizeof(shader::ParticleBillboardParams), "bvh.particle_quads"});
    particleStaging_.resize(framesInFlight_);
    particleInstances_.resize(framesInFlight_);
    offsetStaging_.resize(framesInFlight_);
    materialStaging_.resize(framesInFlight_);
    instanceBuffers_.resize(framesInFlight_);
    jointPalettes_.resize(framesInFlight_);
}

BvhManager::~BvhManager() {
    // Retired objects and resident BLASes may still be referenced by frames
    // in flight.
    ctx_.waitIdleForTeardown("BVH manager");
}

const gpu::AccelerationStructure* BvhManager::blas(scene::BlasId id) const {
    const auto it = blases_.find(id);
    return it == blases_.end() ? nullptr : &it->second->structure;
}

void BvhManager::bind(rg::FrameResources& resources, const BvhUpdateOutputs& outputs) const {
    resources.bind(outputs.tlas, *tlas_);
    resources.bind(outputs.primitivePool, pool_);
    resources.bind(outputs.primitiveOffsets, offsets_);
    resources.bind(outputs.materials, materials_);
    resources.bind(outputs.deformMotion, deformMotion_);
    resources.bind(outputs.alphaTriangles, hitMaterials_->alphaTriangles());
    resources.bind(outputs.alphaMasks, hitMaterials_->alphaMasks());
    if (outputs.particleTlas.valid()) {
        resources.bind(outputs.particleTlas, *particleTlas_);
        resources.bind(outputs.particles, particleData_);
    }
}

// ---------------------------------------------------------------------------
// The frame: CPU decisions, then recording
// ---------------------------------------------------------------------------

void BvhManager::prepareParticles(const scene::BvhPlan& plan, const scene::Camera& camera, FrameWork& work) {
    const uint32_t count = uint32_t(std::min(plan.particleCount, uint32_t(scene_.particles.size())));
    if (count == 0) return;
    if (count > particleCapacity_) {
        particleCapacity_ = uint32_t(grownCapacity(count, kMinParticles));
        const VkDeviceSize dataBytes = VkDeviceSize(particleCapacity_) * sizeof(shader::ParticleData);
        const auto replace = [&](gpu::Buffer& buffer, const gpu::BufferDesc& desc) {
            if (buffer) retire(std::move(buffer));
            buffer = gpu::Buffer(ctx_, desc);
        };
        replace(particleData_, {dataBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                gpu::MemoryUsage::DeviceLocal, "bvh.particles", true});
        for (gpu::Buffer& staging : particleStaging_) {
            replace(staging, {dataBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                              "bvh.particles.staging", true});
        }
        replace(particleQuads_, {VkDeviceSize(particleCapacity_) * shader::kParticleQuadAxes *
                                     shader::kParticleQuadVertices * sizeof(glm::vec3),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kBuildInput, gpu::MemoryUsage::DeviceLocal,
                                 "bvh.particle_quads", true});
        for (gpu::Buffer& instances : particleInstances_) {
            if (!instances) {
                instances = gpu::Buffer(ctx_, {sizeof(VkAccelerationStructureInstanceKHR) * shader::kParticleQuadAxes,
                                               kBuildInput, gpu::MemoryUsage::Upload, "bvh.particle_tlas_instances",
                                               true});
            }
        }
        // Sized for the capacity: a build of fewer quads fits (Vulkan only
        // asks the structure to be as large as the size query for at least
        // as many primitives).
        gpu::TriangleGeometry sizing;
        sizing.vertices = particleQuads_.address();
        sizing.vertexCount = particleCapacity_ * shader::kParticleQuadVertices;
        sizing.triangleCount = particleCapacity_ * 2;
        sizing.opaque = false;
        const gpu::AccelBuild blasSizing = gpu::AccelBuild::bottomLevel(ctx_, {&sizing, 1}, options_.particleFlags);
        stats_.particleBytes = particleData_.size() + particleQuads_.size();
        for (std::unique_ptr<gpu::AccelerationStructure>& blas : particleBlases_) {
            if (blas) retire(std::move(blas));
            blas = std::make_unique<gpu::AccelerationStructure>(ctx_, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                                blasSizing.structureSize(), "bvh.particle_blas", true);
            stats_.particleBytes += blas->buffer().size();
        }
        if (!particleTlas_) {
            const gpu::AccelBuild tlasSizing = gpu::AccelBuild::topLevel(ctx_, particleInstances_[0].address(),
                                                                         shader::kParticleQuadAxes, options_.particleFlags);
            particleTlas_ = std::make_unique<gpu::AccelerationStructure>(
                ctx_, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, tlasSizing.structureSize(), "bvh.particle_tlas",
                true);
        }
        stats_.particleBytes += particleTlas_->buffer().size();
    }

    work.particles.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
        const scene::Particle& p = scene_.particles[i];
        work.particles[i] = {p.position, p.radius, p.color};
    }
    // The camera's basis in world space, the quads' axes: the view
    // matrix's rows (its rotation is orthonormal). The forward pass
    // (passes/particles.cpp) faces its billboards along the same right and up.
    work.billboard = particleBasis(camera.view);
    work.billboard.count = count;

    // Axis a's quads are the a-th third of the quads buffer (particle_quads.comp).
    const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const VkDeviceSize axisBytes = VkDeviceSize(count) * shader::kParticleQuadVertices * sizeof(glm::vec3);
    for (uint32_t axis = 0; axis < shader::kParticleQuadAxes; ++axis) {
        gpu::TriangleGeometry quads;
        quads.vertices = particleQuads_.address() + axis * axisBytes;
        quads.vertexCount = count * shader::kParticleQuadVertices;
        quads.triangleCount = count * 2;
        // Not opaque: the traces look at every quad a ray crosses (any-hit or
        // the ray query's candidates) and keep the nearest covering ones.
        quads.opaque = false;
        work.particleBlasBuilds.push_back(gpu::AccelBuild::bottomLevel(ctx_, {&quads, 1}, options_.particleFlags));
        work.particleInstances[axis] = gpu::makeInstance(*particleBlases_[axis], identity, 0,
                                                         uint8_t(shader::particleAxisMask(axis)),
                                                         shader::kSbtOffsetParticles);
    }
    work.particleTlasBuild = gpu::AccelBuild::topLevel(ctx_, particleInstances_[work.slot].address(),
                                                       shader::kParticleQuadAxes, options_.particleFlags);
    stats_.particleTlasBuilds = 1;
    stats_.particles = count;
    stats_.particleQuads = count * shader::kParticleQuadAxes;
    stats_.particleDispatches = 1;
}

void BvhManager::recordParticleQuads(const FrameWork& work, VkCommandBuffer cmd, const gpu::Buffer& particles) {
    gpu::ScopedLabel label(ctx_, cmd, "bvh.particle_quads");
    particleQuadsPipeline_.bind(cmd);
    gpu::PushDescriptors(particleQuadsPipeline_)
        .storageBuffer("Particles", particles)
        .storageBuffer("Positions", particleQuads_)
        .push(ctx_, cmd);
    particleQuadsPipeline_.pushConstants(cmd, work.billboard);
    vkCmdDispatch(cmd, (work.billboard.count + shader::kParticleBillboardGroupSize - 1) / shader::kParticleBillboardGroupSize,
                  1, 1);
}

std::shared_ptr<BvhManager::FrameWork> BvhManager::prepare(const scene::BvhPlan& plan, const scene::Camera* camera) {
    ++frame_;
    retired_.release(frame_);
    auto work = std::make_shared<FrameWork>();
    work->slot = uint32_t(frame_ % framesInFlight_);
    stats_.frame = frame_;
    stats_.blasBuilds = stats_.blasRebuilds = stats_.blasReleased = 0;
    stats_.packedTriangles = stats_.packDispatches = 0;
    stats_.particleTlasBuilds = stats_.particles = stats_.particleQuads = stats_.particleDispatches = 0;

    for (const scene::BlasDrop& drop : plan.drops) {
        const auto it = blases_.find(drop.blas);
        if (it == blases_.end()) continue;  // never built here (the plan dropped it before a build)
        stats_.blasBytes -= it->second->structure.buffer().size();
        stats_.positionBytes -= it->second->positions.size();
        retire(std::move(it->second));
        blases_.erase(it);
        ++stats_.blasReleased;
    }

    // Edited assets (Scene::assetRevision): the planner dropped every BLAS
    // above; the geometry uploaded for them and the hit materials were made
    // from the old meshes and materials.
    if (const scene::AssetStamp assets = scene::assetStamp(scene_); assets != assets_) {
        for (auto& [id, blas] : blases_) retire(std::move(blas));
        blases_.clear();
        for (auto& [key, source] : geometries_) retire(std::move(source));
        geometries_.clear();
        stats_.blasBytes = stats_.positionBytes = stats_.geometryBytes = 0;
        stats_.uploadedGeometries = 0;
        retire(std::move(hitMaterials_));
        hitMaterials_ = std::make_unique<HitMaterials>(ctx_, scene_, options_.hitMaterials);
        assets_ = assets;
        spdlog::info("BVH: the scene's assets changed (revision {}): geometry and hit materials uploaded again",
                     assets.revision);
    }

    // Static BLASes built in an earlier frame need their positions no more
    // (36 bytes per triangle, half again the pool's 24).
    for (auto& [id, blas] : blases_) {
        if (blas->desc.motion == scene::Motion::Static && blas->positions && blas->builtInFrame < frame_) {
            stats_.positionBytes -= blas->positions.size();
            retire(std::move(blas->positions));
            blas->positions = gpu::Buffer();
        }
    }

    ensurePool(plan.poolTriangles, *work);

    // Builds: pack dispatches per geometry, BLAS scratch laid out end to end
    // because the builds run without barriers between them.
    const bool anySkinned = std::any_of(plan.builds.begin(), plan.builds.end(), [&](const scene::BlasBuild& b) {
        const scene::BlasDesc* d = plan.find(b.blas);
        return d && d->motion == scene::Motion::Skinned;
    });
    if (anySkinned) {
        ensureJointPalette(scene_.jointMatrices.size());
        work->joints = scene_.jointMatrices;
    } else {
        ensureJointPalette(0);
    }
    VkDeviceSize blasScratch = 0;
    uint64_t deformTriangles = 0;  // DeformMotion entries this frame's rebuilds write
    for (const scene::BlasBuild& build : plan.builds) {
        const scene::BlasDesc* desc = plan.find(build.blas);
        if (!desc) {
            throw gpu::GpuError("BVH update: the plan builds BLAS " + std::to_string(build.blas) +
                                " but does not describe it");
        }
        auto it = blases_.find(build.blas);
        const bool resident = it != blases_.end();
        if (resident && !it->second->positions) {
            // A static BLAS asked to build again (the planner builds them
            // once): its positions are gone, so it starts over.
            stats_.blasBytes -= it->second->structure.buffer().size();
            retire(std::move(it->second));
            blases_.erase(it);
            it = blases_.end();
        }
        // Only a rebuild has a last shape to tell the traces how its
        // triangles moved.
        const bool deforms = it != blases_.end() && desc->motion != scene::Motion::Static;
        ResidentBlas& blas = it != blases_.end() ? *it->second : createBlas(*desc, *work);
        blas.builtInFrame = frame_;
        blas.deformMotion.assign(desc->geometries.size(), shader::kNoDeformMotion);
        ++(resident ? stats_.blasRebuilds : stats_.blasBuilds);

        uint32_t jointOffset = 0, jointCount = 0;
        if (desc->motion == scene::Motion::Skinned && desc->instance != scene::kNone) {
            const scene::Instance& inst = scene_.instances.at(size_t(desc->instance));
            jointOffset = inst.jointOffset;
            jointCount = uint32_t(scene_.skins.at(size_t(inst.skin)).joints.size());
        }
        uint32_t first = 0;
        for (size_t g = 0; g < desc->geometries.size(); ++g) {
            const scene::BlasGeometry& geometry = desc->geometries[g];
            const SourceGeometry* source = blas.sources[g];
            FrameWork::Pack pack{source, &blas.positions, {}, nullptr, {}};
            // A morphing instance's own BLAS packs its morphed shape: the
            // weights as they are when the frame is declared (like the
            // joints), applied on the CPU, written when the pass records.
            const scene::Geometry& sourceShape =
                scene_.meshes.at(desc->mesh).lods.at(desc->lod).geometries.at(geometry.meshGeometry);
            if (desc->instance != scene::kNone && !sourceShape.morphTargets.empty()) {
                const std::vector<float>& weights = scene_.instances.at(size_t(desc->instance)).morphWeights;
                if (!weights.empty()) {
                    pack.morphed = sourceVertices(scene_, scene::morphedGeometry(sourceShape, weights));
                    pack.vertices = &morphedVertexBuffer(blas, g, work->slot,
                                                         pack.morphed.size() * sizeof(shader::BvhSourceVertex));
                }
            }
            pack.params.triangleCount = geometry.triangleCount;
            pack.params.poolOffset = geometry.poolOffset;
            pack.params.positionOffset = 3 * first;
            // A geometry without skin data stays rigid even in a skinned instance,
            // as in the CPU reference.
            pack.params.jointOffset = jointOffset;
            pack.params.jointCount = source->skin ? jointCount : 0;
            pack.params.motionOffset = shader::kNoDeformMotion;
            if (deforms) {
                pack.params.motionOffset = blas.deformMotion[g] = uint32_t(deformTriangles);
                deformTriangles += geometry.triangleCount;
            }
            work->packs.push_back(pack);
            first += geometry.triangleCount;
            stats_.packedTriangles += geometry.triangleCount;
        }
        work->builds.push_back({&blas, blasScratch});
        blasScratch += blas.build->scratchSize();
    }
    stats_.packDispatches = uint32_t(work->packs.size());
    stats_.deformedTriangles = deformTriangles;
    ensureDeformMotion(deformTriangles);
    stats_.totalBlasBuilds += work->builds.size();
    stats_.residentBlases = uint32_t(blases_.size());

    // TLAS instances and the offset table, written to host memory when the
    // pass records (the frame slot is free by then).
    ensureTlas(uint32_t(plan.tlas.size()));
    ensureOffsets(plan.primitiveOffsets.size());
    work->offsets = plan.primitiveOffsets;
    shader::RtGeometryMaterial unused{};
    unused.alphaTriangles = shader::kAlphaOpaque;
    unused.alphaMask = shader::kAlphaNoMask;
    unused.deformMotion = shader::kNoDeformMotion;
    setPreviousFromCurrent(unused, glm::mat4(1.0f));
    work->materials.assign(plan.primitiveOffsets.size(), unused);
    work->instances.reserve(plan.tlas.size());
    for (const scene::TlasInstance& ti : plan.tlas) {
        const auto it = blases_.find(ti.blas);
        if (it == blases_.end()) {
            throw gpu::GpuError("BVH update: TLAS instance of scene instance " + std::to_string(ti.sceneInstance) +
                                " uses BLAS " + std::to_string(ti.blas) + ", which was never built");
        }
        // The material rows beside the offset rows the planner wrote, each
        // with its instance's motion since last frame.
        const ResidentBlas& blas = *it->second;
        const std::vector<shader::RtGeometryMaterial>& rows = blas.materialRows;
        const glm::mat4 previousFromCurrent = instanceMotion(scene_.instances.at(ti.sceneInstance));
        const bool deformedNow = blas.builtInFrame == frame_;
        for (size_t g = 0; g < rows.size(); ++g) {
            const size_t row = shader::primitiveOffsetSlot(ti.customIndex, uint32_t(g));
            if (row >= work->materials.size()) continue;
            work->materials[row] = rows[g];
            setPreviousFromCurrent(work->materials[row], previousFromCurrent);
            work->materials[row].deformMotion =
                deformedNow && g < blas.deformMotion.size() ? blas.deformMotion[g] : shader::kNoDeformMotion;
        }
        const auto transform = scene::rowMajor3x4(ti.transform);
        // glTF's front faces wind counter-clockwise in its right-handed
        // space, which is Vulkan's default facing (clockwise seen from the
        // ray origin in a left-handed space; FRONT_COUNTERCLOCKWISE would
        // flip it: measured on lavapipe, the backs of single-sided panels
        // then stayed and their fronts were culled). The facing is decided
        // in object space, so a mirroring transform keeps glTF's front faces
        // front ("an instance transform does not change the winding").
        // Reflection rays cull back faces except on double-sided geometry.
        const VkGeometryInstanceFlagsKHR flags =
            ti.doubleSided ? VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR : 0;
        work->instances.push_back(gpu::makeInstance(it->second->structure, transform.data(), ti.customIndex, ti.mask,
                                                    ti.sbtOffset, flags));
    }
    stats_.tlasInstances = uint32_t(work->instances.size());
    work->tlasBuild = gpu::AccelBuild::topLevel(ctx_, instanceBuffers_[work->slot].address(),
                                                uint32_t(work->instances.size()), options_.tlasFlags);

    // The particle BLAS builds beside the others, the particle TLAS beside
    // the TLAS: their scratch follows.
    VkDeviceSize tlasScratch = work->tlasBuild->scratchSize();
    if (plan.particleTlas && camera) {
        prepareParticles(plan, *camera, *work);
    }
    if (work->particleTlasBuild) {
        for (uint32_t axis = 0; axis < shader::kParticleQuadAxes; ++axis) {
            work->particleBlasScratchOffsets[axis] = blasScratch;
            blasScratch += work->particleBlasBuilds[axis].scratchSize();
        }
        work->particleTlasScratchOffset = tlasScratch;
        tlasScratch += work->particleTlasBuild->scratchSize();
    }

    // The TLAS builds follow a barrier after the BLAS builds, so they reuse
    // the scratch from offset 0.
    const VkDeviceSize scratch = std::max(blasScratch, tlasScratch);
    stats_.scratchBytes = scratch;
    scratchCapacity_ = std::max(scratchCapacity_, grownCapacity(scratch, kMinScratchBytes));
    return work;
}

void BvhManager::record(FrameWork& work, rg::PassContext& pc, const BvhUpdateOutputs& handles) {
    const VkCommandBuffer cmd = pc.cmd();
    // The objects bound to this frame's handles (the manager's current ones
    // when the frame was declared).
    const gpu::Buffer& pool = pc.buffer(handles.primitivePool);
    const gpu::Buffer& offsets = pc.buffer(handles.primitiveOffsets);
    const gpu::Buffer& materials = pc.buffer(handles.materials);
    const gpu::Buffer& scratch = pc.buffer(handles.scratch);
    const gpu::Buffer& deformMotion = pc.buffer(handles.deformMotion);
    const gpu::AccelerationStructure& tlas = pc.accel(handles.tlas);
    const uint32_t slot = work.slot;

    // Host writes first: this slot's previous frame has finished (the executor
    // waited for it before recording), and writes before the submit are
    // visible to the device without a barrier.
    if (!work.instances.empty()) {
        std::memcpy(instanceBuffers_[slot].mapped(), work.instances.data(),
                    work.instances.size() * sizeof(VkAccelerationStructureInstanceKHR));
    }
    if (!work.joints.empty()) {
        std::memcpy(jointPalettes_[slot].mapped(), work.joints.data(), work.joints.size() * sizeof(glm::mat4));
    }
    if (!work.offsets.empty()) {
        std::memcpy(offsetStaging_[slot].mapped(), work.offsets.data(), work.offsets.size() * sizeof(uint32_t));
        std::memcpy(materialStaging_[slot].mapped(), work.materials.data(), work.materials.size() * kMaterialRowBytes);
    }
    for (const FrameWork::Pack& pack : work.packs) {
        if (pack.vertices && !pack.morphed.empty()) {
            std::memcpy(pack.vertices->mapped(), pack.morphed.data(),
                        pack.morphed.size() * sizeof(shader::BvhSourceVertex));
        }
    }
    const bool particles = !work.particles.empty();
    if (particles) {
        std::memcpy(particleStaging_[slot].mapped(), work.particles.data(),
                    work.particles.size() * sizeof(shader::ParticleData));
        std::memcpy(particleInstances_[slot].mapped(), work.particleInstances.data(), sizeof(work.particleInstances));
    }

    // Resources the graph does not see (BLASes, their positions, an outgrown
    // pool) were last touched by this pass in an earlier frame on this same
    // queue: order those builds, dispatches and copies before this frame's.
    gpu::memoryBarrier(cmd,
                       VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                           VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                           VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                           VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR |
                           VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                           VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);

    // Copies: new geometry, the outgrown pool into the new one, the offset
    // table, the particles.
    if (!work.uploads.empty() || work.poolCopySource || !work.offsets.empty() || particles) {
        gpu::ScopedLabel label(ctx_, cmd, "bvh.copies");
        for (const FrameWork::Upload& upload : work.uploads) {
            const VkBufferCopy region{0, 0, upload.staging->size()};
            vkCmdCopyBuffer(cmd, upload.staging->handle(), upload.target->handle(), 1, &region);
        }
        if (work.poolCopySource) {
            const VkBufferCopy region{0, 0, work.poolCopyBytes};
            vkCmdCopyBuffer(cmd, work.poolCopySource->handle(), pool.handle(), 1, &region);
        }
        if (!work.offsets.empty()) {
            const VkBufferCopy region{0, 0, work.offsets.size() * sizeof(uint32_t)};
            vkCmdCopyBuffer(cmd, offsetStaging_[slot].handle(), offsets.handle(), 1, &region);
            const VkBufferCopy materialRegion{0, 0, work.materials.size() * kMaterialRowBytes};
            vkCmdCopyBuffer(cmd, materialStaging_[slot].handle(), materials.handle(), 1, &materialRegion);
        }
        if (particles) {
            const VkBufferCopy region{0, 0, work.particles.size() * sizeof(shader::ParticleData)};
            vkCmdCopyBuffer(cmd, particleStaging_[slot].handle(), pc.buffer(handles.particles).handle(), 1, &region);
        }
        // The pack dispatches overwrite parts of the copied pool; the
        // particle quads read the particles.
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                           VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }

    if (particles) {
        recordParticleQuads(work, cmd, pc.buffer(handles.particles));
    }
    if (!work.packs.empty()) {
        gpu::ScopedLabel label(ctx_, cmd, "bvh.pack_primitives");
        packPipeline_.bind(cmd);
        for (const FrameWork::Pack& pack : work.packs) {
            const gpu::Buffer& skin = pack.source->skin ? pack.source->skin : pack.source->vertices;
            gpu::PushDescriptors(packPipeline_)
                .storageBuffer("Vertices", pack.vertices ? *pack.vertices : pack.source->vertices)
                .storageBuffer("Indices", pack.source->indices)
                .storageBuffer("Skin", skin)  // unread when jointCount is 0; the binding must still be valid
                .storageBuffer("Joints", jointPalettes_[slot])
                .storageBuffer("Positions", *pack.positions)
                .storageBuffer("Pool", pool)
                .storageBuffer("DeformMotions", deformMotion)  // written only where params.motionOffset says
                .push(ctx_, cmd);
            packPipeline_.pushConstants(cmd, pack.params);
            vkCmdDispatch(cmd, (pack.params.triangleCount + shader::kBvhPackGroupSize - 1) / shader::kBvhPackGroupSize,
                          1, 1);
        }
    }
    if (!work.packs.empty() || particles) {
        // Unwrapped positions and particle quads -> BLAS build input.
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_SHADER_READ_BIT);
    }

    if (!work.builds.empty() || particles) {
        gpu::ScopedLabel label(ctx_, cmd, "bvh.blas_builds");
        for (const FrameWork::Build& build : work.builds) {
            build.blas->build->record(ctx_, cmd, build.blas->structure.handle(), scratch.address() + build.scratchOffset);
        }
        if (particles) {
            // Rebuilt every frame: the quads turned with the camera.
            for (uint32_t axis = 0; axis < shader::kParticleQuadAxes; ++axis) {
                work.particleBlasBuilds[axis].record(ctx_, cmd, particleBlases_[axis]->handle(),
                                                     scratch.address() + work.particleBlasScratchOffsets[axis]);
            }
        }
        // BLAS writes -> TLAS build reads; the TLAS build also reuses the scratch.
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                           VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                           VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                           VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR |
                               VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);
    }

    gpu::ScopedLabel label(ctx_, cmd, "bvh.tlas_build");
    work.tlasBuild->record(ctx_, cmd, tlas.handle(), scratch.address());
    if (particles) {
        work.particleTlasBuild->record(ctx_, cmd, pc.accel(handles.particleTlas).handle(),
                                       scratch.address() + work.particleTlasScratchOffset);
    }
}

shader::ParticleBillboardParams particleBasis(const glm::mat4& view) {
    shader::ParticleBillboardParams basis{};
    basis.right = glm::normalize(glm::vec3(view[0][0], view[1][0], view[2][0]));
    basis.up = glm::normalize(glm::vec3(view[0][1], view[1][1], view[2][1]));
    basis.back = glm::normalize(glm::vec3(view[0][2], view[1][2], view[2][2]));
    return basis;
}

BvhUpdateOutputs addBvhUpdatePass(rg::Graph& graph, BvhManager& manager, const scene::BvhPlan& plan) {
    return BvhManager::declare(graph, manager, plan, nullptr);
}

BvhUpdateOutputs addBvhUpdatePass(rg::Graph& graph, BvhManager& manager, const scene::BvhPlan& plan,
                                  const scene::Camera& camera) {
    return BvhManager::declare(graph, manager, plan, &camera);
}

BvhUpdateOutputs BvhManager::declare(rg::Graph& graph, BvhManager& manager, const scene::BvhPlan& plan,
                                     const scene::Camera* camera) {
    std::shared_ptr<BvhManager::FrameWork> work = manager.prepare(plan, camera);
    const gpu::Capabilities& caps = manager.ctx_.caps();
    const rg::BoundaryState accelState = tracedAccelState(caps);
    const rg::BoundaryState bufferState = tracedBufferState(caps);
    const rg::AccelStruct tlas = graph.importAccelStruct("bvh.tlas", {accelState, accelState});
    const rg::Buffer pool =
        graph.importBuffer("bvh.primitive_pool", {{manager.pool_.size()}, bufferState, bufferState});
    const rg::Buffer offsets =
        graph.importBuffer("bvh.primitive_offsets", {{manager.offsets_.size()}, bufferState, bufferState});
    const rg::Buffer materials =
        graph.importBuffer("bvh.materials", {{manager.materials_.size()}, bufferState, bufferState});
    const rg::Buffer deformMotion =
        graph.importBuffer("bvh.deform_motion", {{manager.deformMotion_.size()}, bufferState, bufferState});
    const uint64_t scratchBytes = manager.scratchCapacity_;
    const bool particles = !work->particles.empty();
    rg::AccelStruct particleTlas;
    rg::Buffer particleData;
    if (particles) {
        particleTlas = graph.importAccelStruct("bvh.particle_tlas", {accelState, accelState});
        particleData =
            graph.importBuffer("bvh.particles", {{manager.particleData_.size()}, bufferState, bufferState});
    }

    const BvhUpdateOutputs& out = graph.addPass<BvhUpdateOutputs>(
        "bvh_update", manager.options_.queue,
        [&](rg::Builder& b, BvhUpdateOutputs& d) {
            d.tlas = b.write(tlas, rg::Access::AccelBuildWrite);
            d.primitivePool = b.write(pool, rg::Access::StorageWrite);
            d.primitiveOffsets = b.write(offsets, rg::Access::TransferDst);
            d.materials = b.write(materials, rg::Access::TransferDst);
            d.scratch = b.write(b.createBuffer("bvh.scratch", {scratchBytes}), rg::Access::AccelBuildWrite);
            d.deformMotion = b.write(deformMotion, rg::Access::StorageWrite);
            if (particles) {
                d.particleTlas = b.write(particleTlas, rg::Access::AccelBuildWrite);
                d.particles = b.write(particleData, rg::Access::TransferDst);
            }
            // The BLASes are written here and observed only through the TLAS;
            // a frame whose TLAS nobody reads must still build them (static
            // BLASes are built exactly once).
            b.markSideEffects();
        },
        [&manager, work](const BvhUpdateOutputs& d, rg::PassContext& pc) {
            manager.record(*work, pc, d);
        });
    // The alpha test's data never changes after start-up: imported for the
    // traces to read, written by no pass.
    BvhUpdateOutputs outputs = out;
    if (!work->particles.empty()) {
        outputs.particleBoundsMin = glm::vec3(std::numeric_limits<float>::max());
        outputs.particleBoundsMax = glm::vec3(std::numeric_limits<float>::lowest());
        for (const shader::ParticleData& p : work->particles) {
            // A quad of half side r turned any way stays within r * sqrt(2).
            const glm::vec3 reach(p.radius * 1.4143f);
            outputs.particleBoundsMin = glm::min(outputs.particleBoundsMin, p.position - reach);
            outputs.particleBoundsMax = glm::max(outputs.particleBoundsMax, p.position + reach);
        }
    }
    const HitMaterials& hit = *manager.hitMaterials_;
    outputs.alphaTriangles =
        graph.importBuffer("bvh.alpha_triangles", {{hit.alphaTriangles().size()}, bufferState, bufferState});
    const gpu::ImageDesc& masks = hit.alphaMasks().desc();
    const rg::BoundaryState sampled = rg::BoundaryState::of(rg::Access::SampledRead);
    outputs.alphaMasks = graph.importTexture("bvh.alpha_masks", {{.width = masks.width,
                                                                  .height = masks.height,
                                                                  .layers = masks.layers,
                                                                  .mips = masks.mips,
                                                                  .format = masks.format},
                                                                 sampled,
                                                                 sampled});
    return outputs;
}

} // namespace glint::passes
