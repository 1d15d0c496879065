#pragma once
// What passes/bvh_update.cpp (the frame: BvhManager's CPU decisions, the
// pass's recording and its declaration) and passes/bvh_update_resources.cpp
// (geometry uploads, BLAS creation and the buffers that grow with the scene)
// share of BvhManager's insides: the growth policy and minimum sizes, the
// per-object state and a frame's work. Not part of the passes' interface.

#include "glint/passes/bvh_update.h"

#include "glint/bvh_shared.h"
#include "glint/particles_shared.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace glint::passes::bvh_update_detail {

inline constexpr VkBufferUsageFlags kBuildInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

// Growth policy of every buffer whose size follows the scene: the next power
// of two, so a slowly growing pool or TLAS reallocates O(log n) times.
inline uint64_t grownCapacity(uint64_t needed, uint64_t minimum) {
    return std::bit_ceil(std::max(needed, minimum));
}

// The executor keeps transient memory while the plan's transient layout is
// unchanged and rebuilds it after a device wait otherwise, so the scratch
// request only ever grows, in powers of two, from this size.
inline constexpr uint64_t kMinScratchBytes = 64 * 1024;
inline constexpr uint32_t kMinTlasInstances = 64;
inline constexpr uint32_t kMinOffsetEntries = 256;
inline constexpr VkDeviceSize kMaterialRowBytes = sizeof(shader::RtGeometryMaterial);
inline constexpr uint32_t kMinParticles = 64;
inline constexpr uint64_t kMinDeformMotionBytes = 1024 * sizeof(shader::DeformMotion);

// The pack pass's source vertices of `g`. Material attributes are sampled
// here with the CPU reference: texture sampling at the vertices gives the
// same answer every frame, so doing it per frame on the GPU would cost
// texture bindings and fetches for nothing. The pack pass then only skins
// the normal and packs it.
// (Defined in bvh_update_resources.cpp.)
std::vector<shader::BvhSourceVertex> sourceVertices(const scene::Scene& scene, const scene::Geometry& g);

} // namespace glint::passes::bvh_update_detail

namespace glint::passes {

// ---------------------------------------------------------------------------
// Per-object state
// ---------------------------------------------------------------------------

// One geometry of a mesh's reflection LOD on the GPU, uploaded the first time
// a BLAS uses it.
struct BvhManager::SourceGeometry {
    gpu::Buffer vertices;  // BvhSourceVertex per vertex
    gpu::Buffer indices;   // three per triangle
    gpu::Buffer skin;      // BvhSkinVertex per vertex; empty when not skinned
    uint32_t triangleCount = 0;
};

struct BvhManager::ResidentBlas {
    scene::BlasDesc desc;
    // Three vec3 per triangle, the build input. A static BLAS never rebuilds,
    // so its positions are released once its build has finished.
    gpu::Buffer positions;
    uint64_t builtInFrame = 0;
    // Per BLAS geometry, its first DeformMotion in the frame's deform motion
    // buffer, when the frame builtInFrame rebuilt it over an earlier shape
    // (kNoDeformMotion: a first build, or a static BLAS).
    std::vector<uint32_t> deformMotion;
    std::vector<const SourceGeometry*> sources;  // per BLAS geometry
    // Per BLAS geometry, its row of the material table (HitMaterials::row),
    // fixed for the BLAS's life: each frame copies them beside the offsets.
    std::vector<shader::RtGeometryMaterial> materialRows;
    std::optional<gpu::AccelBuild> build;        // geometry addresses into `positions`, reused by rebuilds
    gpu::AccelerationStructure structure;
    // A morphing instance's BLAS: per frame slot and BLAS geometry, its
    // source vertices with the instance's morph weights applied on the CPU
    // (host-visible, written when a build of that slot records; empty for
    // geometries without morph targets).
    std::vector<std::vector<gpu::Buffer>> morphedVertices;
};

struct BvhManager::FrameWork {
    struct Pack {
        const SourceGeometry* source = nullptr;
        const gpu::Buffer* positions = nullptr;
        shader::BvhPackParams params{};
        // Set for a morphing geometry: read these source vertices instead of
        // source->vertices, after writing `morphed` into them.
        const gpu::Buffer* vertices = nullptr;
        std::vector<shader::BvhSourceVertex> morphed;
    };
    struct Build {
        ResidentBlas* blas = nullptr;
        VkDeviceSize scratchOffset = 0;
    };
    uint32_t slot = 0;
    std::vector<Pack> packs;
    std::vector<Build> builds;
    std::vector<VkAccelerationStructureInstanceKHR> instances;
    std::vector<uint32_t> offsets;
    std::vector<shader::RtGeometryMaterial> materials;  // parallel to offsets
    std::vector<glm::mat4> joints;  // the palette as it was when the frame was declared
    std::optional<gpu::AccelBuild> tlasBuild;
    std::shared_ptr<gpu::Buffer> poolCopySource;  // the outgrown pool, copied into the new one first
    VkDeviceSize poolCopyBytes = 0;
    // Geometry that enters the GPU this frame: host-written staging copied
    // into its device-local buffer at the start of the pass, on the pass's
    // own queue, so a first entry into range never blocks the host on a
    // submission of its own.
    struct Upload {
        std::shared_ptr<gpu::Buffer> staging;
        const gpu::Buffer* target = nullptr;
    };
    std::vector<Upload> uploads;
    // Particles: empty without (then nothing below is recorded).
    std::vector<shader::ParticleData> particles;
    shader::ParticleBillboardParams billboard{};
    // One BLAS build and one TLAS instance per quad axis.
    std::vector<gpu::AccelBuild> particleBlasBuilds;
    std::optional<gpu::AccelBuild> particleTlasBuild;
    std::array<VkAccelerationStructureInstanceKHR, shader::kParticleQuadAxes> particleInstances{};
    std::array<VkDeviceSize, shader::kParticleQuadAxes> particleBlasScratchOffsets{};  // beside the BLAS builds
    VkDeviceSize particleTlasScratchOffset = 0;  // beside the TLAS build
};

template <class T> void BvhManager::retire(T&& object) {
    // Frames up to frame_ - 1 may have recorded uses; frame_ itself when the
    // object is still used by the frame being declared (a pool copy source).
    retired_.keep(std::forward<T>(object), frame_);
}

} // namespace glint::passes
