#pragma once
// The GPU side of the BVH manager: executes a scene::BvhPlan.
//
// BvhManager owns what lives across frames: the reflection-LOD geometry of
// every mesh a BLAS was built from (uploaded once per asset revision,
// scene::Scene::assetRevision; material sampled at the
// vertices on the CPU, copied from staging inside the update pass of the
// frame that first builds it: no submission of its own, no host wait; a
// morphing instance's own BLAS instead gets its morphed vertices, morph
// targets applied on the CPU, per build), one AccelerationStructure per
// resident BLAS, the unwrapped build positions of the deformable ones, the
// one primitive pool (PackedPrimitive per triangle, glint/packing.h), the
// primitive offset buffer and its parallel material table (emission and
// the alpha test, passes/bvh_hit_materials.h: alpha-tested geometry is not
// opaque in its BLAS, and each instance's motion), the deform motion buffer
// (how the frame's rebuilt triangles moved), the TLAS and its per-frame
// instance buffers.
//
// addBvhUpdatePass() declares the frame's builds as ONE render-graph pass on
// the async compute queue (the graphics queue on one-queue devices, or where
// BvhUpdateOptions::queue says Graphics):
//   copies (new geometry, the offset table, ...) -> barrier ->
//   pack dispatches (positions + packed primitives, skinning included; a
//   rebuild also writes how each triangle moved, BvhUpdateOutputs::deformMotion)
//   -> barrier -> BLAS builds -> barrier -> TLAS build,
// with build scratch from the graph.
//
// Particles (a TLAS of their own): when the plan says particleTlas and the
// pass is given the camera, the same pass uploads the scene's particles
// (per frame in flight), writes three quads per particle, one facing each
// of the camera's axes
// (shaders/bvh/particle_quads.comp, in the pack step; why three:
// glint/particles_shared.h), builds a BLAS per axis beside the other
// BLASes and a particle TLAS of their three instances (mask
// particleAxisMask(axis), kSbtOffsetParticles) beside the TLAS, all every
// frame with fast build. A scene without particles gets no
// particle buffer, BLAS, TLAS or dispatch (nothing is modelled that the
// scene does not need); BvhUpdateOutputs::particleTlas is then invalid.
//
//   passes::BvhManager bvh(ctx, scene);
//   each frame:
//     const scene::BvhPlan plan = planner.plan(scene, camera);
//     rg::Graph graph(executor.queueCaps());
//     const auto out = passes::addBvhUpdatePass(graph, bvh, plan, camera);  // camera: particles face it
//     ... passes reading out.tlas (AccelRead), out.primitivePool and
//         out.primitiveOffsets (StorageRead) on the graphics queue ...
//     rg::FrameResources frame;
//     bvh.bind(frame, out);
//     executor.run(graph.compile(executor.compileOptions()), frame);
//
// Cross-frame safety: the imports' boundary states say the trace passes on
// the graphics queue read the TLAS, pool and offsets, so the graph orders
// this frame's builds after last frame's traces (a barrier on one queue, a
// wait on the previous frame's graphics batches with two). The BLASes stay
// inside the pass: they are only read through the TLAS, so the TLAS's edge
// covers a BLAS rebuilt while last frame's traversal could still read it.
// Objects the plan drops (BLASes, an outgrown pool, TLAS or buffer) are
// destroyed only after every frame that could use them has finished.

#include "glint/gpu/accel.h"
#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/passes/bvh_hit_materials.h"
#include "glint/passes/retired_objects.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include "glint/particles_shared.h"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <tuple>
#include <vector>

namespace glint::passes {

struct BvhUpdateOutputs {
    rg::AccelStruct tlas;          // built; read it with Access::AccelRead
    rg::Buffer primitivePool;      // PackedPrimitive per triangle; Access::StorageRead
    rg::Buffer primitiveOffsets;   // uint per (custom index + geometry); Access::StorageRead
    // Parallel to primitiveOffsets: shader::RtGeometryMaterial per row, the
    // geometry's material emission in glTF units (emissiveFactor x strength
    // x the emissive texture's mean, scene::meanEmission) and its alpha
    // test; the packed primitives have no room for them. Access::StorageRead.
    rg::Buffer materials;
    // The alpha test's data (passes/bvh_hit_materials.h), imported, never
    // written: shader::AlphaTriangle per alpha-tested triangle
    // (Access::StorageRead) and the alpha mask array (Access::SampledRead,
    // with HitMaterials::alphaSampler()).
    rg::Buffer alphaTriangles;
    rg::Texture alphaMasks;
    rg::Buffer scratch;            // the builds' scratch (transient)
    // How this frame's rebuilt deformable geometry moved inside its
    // objects: shader::DeformMotion per triangle where a material row's
    // deformMotion points (glint/bvh_shared.h), rewritten every frame;
    // Access::StorageRead by the traces' hit motion.
    rg::Buffer deformMotion;
    // Invalid when the frame has no particles (or was declared without a
    // camera): the particle TLAS (Access::AccelRead; one instance, SBT
    // offset kSbtOffsetParticles, its primitive p is particle p / 2) and
    // the particles as shader::ParticleData (glint/particles_shared.h;
    // Access::StorageRead), indexed by primitive / 2.
    rg::AccelStruct particleTlas;
    rg::Buffer particles;
    // The box around every particle's quads (world, min and max; empty,
    // min > max, without particles): rays that miss it skip the particle
    // TLAS altogether.
    glm::vec3 particleBoundsMin{1.0f};
    glm::vec3 particleBoundsMax{-1.0f};
};

// What the GPU side did this frame and holds now.
struct BvhGpuStats {
    uint64_t frame = 0;            // addBvhUpdatePass calls so far
    uint32_t blasBuilds = 0;       // this frame: first builds of a BLAS
    uint32_t blasRebuilds = 0;     // this frame: rebuilds of resident BLASes
    uint32_t blasReleased = 0;     // this frame: BLASes the plan dropped
    uint32_t packedTriangles = 0;  // this frame: triangles the pack dispatches wrote
    uint32_t packDispatches = 0;   // this frame
    uint64_t deformedTriangles = 0;  // this frame: rebuilt triangles with a DeformMotion (skinning, morphing)
    uint32_t tlasInstances = 0;    // this frame
    uint32_t residentBlases = 0;
    uint32_t uploadedGeometries = 0;  // reflection-LOD geometries on the GPU
    uint32_t poolGrowths = 0;         // total times the pool was reallocated (contents kept)
    uint64_t blasBytes = 0;           // storage of the resident BLASes
    uint64_t tlasBytes = 0;
    uint64_t poolBytes = 0;           // allocated (capacity), not just used
    uint64_t deformMotionBytes = 0;   // allocated for BvhUpdateOutputs::deformMotion
    uint64_t positionBytes = 0;       // unwrapped build positions (deformable BLASes, and static ones until built)
    uint64_t geometryBytes = 0;       // uploaded vertices, indices and skin data
    uint64_t uploadBytes = 0;         // staged for those uploads, all frames (copied inside the update pass)
    uint64_t scratchBytes = 0;        // this frame's scratch request to the graph
    uint64_t totalBlasBuilds = 0;     // first builds and rebuilds, all frames
    // Particles: this frame's particle TLAS builds (1 or 0: none without
    // particles), their particles, their quads in the particle BLASes
    // (kParticleQuadAxes per particle) and quad dispatches; the bytes of
    // what is allocated for them (BLASes, TLAS, quads, particle data).
    uint32_t particleTlasBuilds = 0;
    uint32_t particles = 0;
    uint32_t particleQuads = 0;
    uint32_t particleDispatches = 0;
    uint64_t particleBytes = 0;
};

struct BvhUpdateOptions {
    // Build flags: static BLASes are built once and traced for many frames
    // (fast trace); deformable ones are rebuilt in the round-robin loop, so
    // their build time is paid again and again (fast build).
    VkBuildAccelerationStructureFlagsKHR staticFlags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    VkBuildAccelerationStructureFlagsKHR deformableFlags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
    VkBuildAccelerationStructureFlagsKHR tlasFlags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    // The particle BLAS and TLAS are rebuilt every frame (the quads face
    // the camera) and traced once, by one ray per pixel: fast build.
    VkBuildAccelerationStructureFlagsKHR particleFlags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
    // The queue of the update pass. AsyncCompute overlaps the builds with
    // graphics work that does not need the TLAS (the graph maps it to the
    // graphics queue on one-queue devices); Graphics serializes them with it
    // (a baseline, or where async compute is slower). Fixed for the manager's
    // lifetime: the pass orders itself after its own earlier frames by a
    // barrier on this one queue.
    rg::Queue queue = rg::Queue::AsyncCompute;
    HitMaterialOptions hitMaterials;  // the alpha test's mask size
};

class BvhManager {
public:
    // `scene` must outlive the manager. Its instances and joint palette may
    // change between frames; edited meshes, materials and textures
    // (scene::Scene::assetRevision) are uploaded again, and the planner
    // drops every BLAS built from them. `framesInFlight` must be at least
    // the executor's: host-written buffers are kept once per frame in flight.
    BvhManager(gpu::Context& ctx, const scene::Scene& scene, uint32_t framesInFlight = 2,
               const BvhUpdateOptions& options = {});
    ~BvhManager();
    BvhManager(const BvhManager&) = delete;
    BvhManager& operator=(const BvhManager&) = delete;

    // Binds the imports addBvhUpdatePass declared to this frame's objects.
    void bind(rg::FrameResources& resources, const BvhUpdateOutputs& outputs) const;

    const BvhGpuStats& stats() const { return stats_; }
    const BvhUpdateOptions& options() const { return options_; }
    // The current objects, for tools and tests (valid after addBvhUpdatePass).
    const gpu::Buffer& primitivePool() const { return pool_; }
    const gpu::Buffer& primitiveOffsets() const { return offsets_; }
    const gpu::Buffer& materials() const { return materials_; }
    const HitMaterials& hitMaterials() const { return *hitMaterials_; }
    const gpu::AccelerationStructure& tlas() const { return *tlas_; }
    // Nullptr when the BLAS is not resident.
    const gpu::AccelerationStructure* blas(scene::BlasId id) const;

private:
    friend BvhUpdateOutputs addBvhUpdatePass(rg::Graph&, BvhManager&, const scene::BvhPlan&);
    friend BvhUpdateOutputs addBvhUpdatePass(rg::Graph&, BvhManager&, const scene::BvhPlan&, const scene::Camera&);
    static BvhUpdateOutputs declare(rg::Graph& graph, BvhManager& manager, const scene::BvhPlan& plan,
                                    const scene::Camera* camera);
    struct SourceGeometry;
    struct ResidentBlas;
    struct FrameWork;
    using GeometryKey = std::tuple<uint32_t, uint32_t, uint32_t>;  // mesh, lod, geometry

    std::shared_ptr<FrameWork> prepare(const scene::BvhPlan& plan, const scene::Camera* camera);
    void prepareParticles(const scene::BvhPlan& plan, const scene::Camera& camera, FrameWork& work);
    void recordParticleQuads(const FrameWork& work, VkCommandBuffer cmd, const gpu::Buffer& particles);
    void record(FrameWork& work, rg::PassContext& pc, const BvhUpdateOutputs& handles);
    const SourceGeometry& sourceGeometry(uint32_t mesh, uint32_t lod, uint32_t geometry, FrameWork& work);
    ResidentBlas& createBlas(const scene::BlasDesc& desc, FrameWork& work);
    // A morphing instance's BLAS geometry: its host-visible source vertex
    // buffer of frame slot `slot`, at least `bytes` large.
    const gpu::Buffer& morphedVertexBuffer(ResidentBlas& blas, size_t geometryIndex, uint32_t slot, VkDeviceSize bytes);
    void ensurePool(uint32_t triangles, FrameWork& work);
    void ensureTlas(uint32_t instances);
    void ensureDeformMotion(uint64_t triangles);
    void ensureOffsets(size_t entries);
    void ensureJointPalette(size_t matrices);
    template <class T> void retire(T&& object);

    gpu::Context& ctx_;
    const scene::Scene& scene_;
    uint32_t framesInFlight_;
    BvhUpdateOptions options_;
    gpu::Pipeline packPipeline_;
    gpu::Pipeline particleQuadsPipeline_;
    uint64_t frame_ = 0;  // frames prepared so far

    std::map<GeometryKey, std::unique_ptr<SourceGeometry>> geometries_;
    std::map<scene::BlasId, std::unique_ptr<ResidentBlas>> blases_;
    gpu::Buffer pool_;
    gpu::Buffer deformMotion_;                    // BvhUpdateOutputs::deformMotion, grown as rebuilds need
    gpu::Buffer offsets_;                         // device-local, read by the traces
    std::vector<gpu::Buffer> offsetStaging_;      // host-visible, one per frame in flight
    // Per offset row, its geometry's material row (BvhUpdateOutputs::materials),
    // sized with the offsets; the rows come from hitMaterials_, built when
    // the manager is made and again when the scene's assets change.
    std::unique_ptr<HitMaterials> hitMaterials_;
    scene::AssetStamp assets_;  // of the scene hitMaterials_ and geometries_ were made from
    gpu::Buffer materials_;
    std::vector<gpu::Buffer> materialStaging_;
    std::vector<gpu::Buffer> instanceBuffers_;    // host-visible TLAS instances, one per frame in flight
    std::vector<gpu::Buffer> jointPalettes_;      // host-visible joint matrices, one per frame in flight
    std::unique_ptr<gpu::AccelerationStructure> tlas_;
    uint32_t tlasCapacity_ = 0;                   // instances the TLAS and instance buffers hold
    uint64_t scratchCapacity_ = 0;                // high-water mark of the scratch request
    // Particles, allocated on the first frame with particles, grown in
    // powers of two: the data (device-local, read by the traces) and its
    // per-slot staging, the quads (build input, three per particle), a
    // BLAS per quad axis and the TLAS sized for the capacity, the TLAS's
    // instances (one per axis) per slot.
    uint32_t particleCapacity_ = 0;
    gpu::Buffer particleData_;
    std::vector<gpu::Buffer> particleStaging_;
    gpu::Buffer particleQuads_;
    std::array<std::unique_ptr<gpu::AccelerationStructure>, shader::kParticleQuadAxes> particleBlases_;
    std::unique_ptr<gpu::AccelerationStructure> particleTlas_;
    std::vector<gpu::Buffer> particleInstances_;
    RetiredObjects retired_;
    BvhGpuStats stats_;
};

// Declares this frame's BVH work (see the top of this file). Frames are
// declared and run one at a time, once each: the manager's per-frame host
// buffers and deferred releases count frames by these calls. Throws
// gpu::GpuError when the plan names a BLAS the manager never built (a plan
// from another planner or scene).
// This overload has no camera to face the particles with: it builds no
// particle TLAS whatever the plan says.
BvhUpdateOutputs addBvhUpdatePass(rg::Graph& graph, BvhManager& manager, const scene::BvhPlan& plan);
// With the frame's camera (the G-buffer's): also the particle TLAS when
// plan.particleTlas (see the top of this file).
BvhUpdateOutputs addBvhUpdatePass(rg::Graph& graph, BvhManager& manager, const scene::BvhPlan& plan,
                                  const scene::Camera& camera);

// The camera's basis (right, up, back in world space) that the particle
// quads are built in and the forward pass's billboards face; count 0.
shader::ParticleBillboardParams particleBasis(const glm::mat4& view);

// The state the imports are left in and expected in: read by the trace
// passes on the graphics queue, from compute (ray query) or the ray tracing
// pipeline, so either backend (or both) may consume them.
rg::BoundaryState tracedAccelState(const gpu::Capabilities& caps);
rg::BoundaryState tracedBufferState(const gpu::Capabilities& caps);

} // namespace glint::passes
