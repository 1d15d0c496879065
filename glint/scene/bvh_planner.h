#pragma once
// The BVH policy of the reflections as pure CPU logic: each frame, which
// BLASes exist, which are built or rebuilt and why, which instances go into
// the TLAS, and where every BLAS's packed primitives live in the one
// primitive pool. The GPU side executes the plan; nothing here touches
// Vulkan, so every decision is testable.
//
// Policy (Far Cry 6, GDC 2022 "Performant Reflective Beauty"):
//  - one BLAS per object, split per material only when an object has more
//    than 32 geometries, and into its single- and double-sided geometries
//    when it has both (a reflection ray passes through the back of a
//    single-sided triangle, glTF's doubleSided: culling is per instance);
//    reflection BLASes use the mesh's lower LOD;
//  - static BLASes are built once (and shared by the instances of a mesh);
//  - dynamic and skinned BLASes are rebuilt in a round-robin loop of at most
//    16 rebuilds per frame, at most 12 of them skinned, and only when the
//    object deformed (Instance::deformVersion changed) or the instance at
//    its index is no longer shaped as it was built (instances removed or
//    reordered: its skin, joint matrices or morph weights differ). Rigid
//    motion is a TLAS instance transform, never a BLAS rebuild;
//  - edited assets (Scene::assetRevision, or meshes, materials or textures
//    added or removed) drop every BLAS, which then builds as new;
//  - first-person objects that deformed are rebuilt every frame, ahead of
//    the loop and inside the same budget;
//  - first builds (objects entering the radius) have a budget of their own,
//    BLASes and triangles per frame, so that a crowd entering range builds
//    over several frames instead of stalling one: first-person objects
//    first, then the largest on screen (bounding radius over distance),
//    then the nearest. An instance is in the TLAS once all its BLASes are
//    built; until then the frame reflects it through SSLR or the
//    environment (BvhPlan::complete, passes::ReflectionRenderer: "SSLR is
//    the fallback while the BVH builds", the talk);
//  - the TLAS holds the instances within the frame's radius of the camera
//    (Far Cry 6: 100 m; the long-range group: a larger radius); an object never within the radius gets no
//    BLAS; the particle TLAS exists only when there are particles.
//
// The primitive pool: every BLAS owns a contiguous range of triangles
// (24 bytes each, glint/packing.h). TLAS instance i has custom index c_i,
// and primitiveOffsets[c_i + g] is the first pool triangle of its BLAS
// geometry g, so a hit finds its triangle at
//   pool[primitiveOffsets[customIndex + geometryIndex] + primitiveIndex].

#include "glint/scene/scene.h"

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace glint::scene {

// Far Cry 6's BVH radius around the camera; BvhPlanner::plan takes the
// radius per frame (passes::ReflectionFrameSettings::reach).
inline constexpr float kDefaultBvhRadius = 100.0f;

struct BvhSettings {
    // The long-range group's radius (at least the frame's): Glint's choice
    // for the terrain group; the talk gives no number.
    float longRangeRadius = 500.0f;
    uint32_t maxRebuildsPerFrame = 16;         // FC6
    uint32_t maxSkinnedRebuildsPerFrame = 12;  // FC6
    uint32_t maxGeometriesPerBlas = 32;        // FC6
    // false: every BLAS from full detail (lods[0]) instead of the reflection
    // LOD; the converged reference's choice, so that error is measured
    // against the full-detail scene.
    bool reflectionLods = true;
    // First builds per frame: at most this many BLASes and triangles (one
    // BLAS is always built, however large). Glint's values: above what the
    // built-in scenes and the shared glTF scenes build on their first frame
    // (the plaza 51 BLASes, 31k triangles), about 2 ms of builds on the
    // H200 (1M triangles build in 1.2-2.4 ms there).
    uint32_t maxFirstBuildsPerFrame = 64;
    uint64_t maxFirstBuildTrianglesPerFrame = 1'000'000;
    // 0 keeps a BLAS once built (FC6 builds static BLASes once); otherwise a
    // BLAS whose objects stayed outside their radius this many frames is
    // dropped to free memory.
    uint32_t evictAfterFramesOutside = 0;
    // A dropped BLAS's pool range is reused only after this many frames, so
    // frames still in flight never see it overwritten.
    uint32_t framesInFlight = 2;
};

using BlasId = uint32_t;

enum class BlasBuildReason : uint8_t {
    FirstInRange,  // first time an object of this BLAS is within its radius (or again after eviction)
    Deformed,      // the object's deformVersion changed; rebuilt in its round-robin turn
    FirstPerson,   // a first-person object deformed: rebuilt this frame, ahead of the loop
};

enum class BlasDropReason : uint8_t {
    ObjectRemoved,  // no instance refers to it any more (removed, mesh or motion changed)
    Evicted,        // outside the radius for BvhSettings::evictAfterFramesOutside frames
    AssetsEdited,   // the scene's meshes, materials or textures changed (Scene::assetRevision): every BLAS goes
};

std::string_view reasonName(BlasBuildReason reason);
std::string_view reasonName(BlasDropReason reason);

struct BlasGeometry {
    uint32_t meshGeometry = 0;  // index in the reflection LOD's geometries
    uint32_t material = 0;
    uint32_t triangleCount = 0;
    uint32_t poolOffset = 0;  // first triangle in the primitive pool
};

struct BlasDesc {
    BlasId id = 0;
    uint32_t mesh = 0;
    uint32_t lod = 0;          // the reflection LOD it is built from
    uint32_t part = 0;         // > 0 only for objects split per material
    int32_t instance = kNone;  // the owning instance of a deformable BLAS; kNone: a static mesh's shared BLAS
    Motion motion = Motion::Static;
    uint32_t poolOffset = 0;  // first triangle of its pool range
    uint32_t triangleCount = 0;
    std::vector<BlasGeometry> geometries;  // BLAS geometry index = position here
    // Its geometries' materials are double-sided (all or none are): rays
    // hit their back faces too; single-sided ones they pass through.
    bool doubleSided = false;
};

struct BlasBuild {
    BlasId blas = 0;
    BlasBuildReason reason = BlasBuildReason::FirstInRange;
};

struct BlasDrop {
    BlasId blas = 0;
    BlasDropReason reason = BlasDropReason::ObjectRemoved;
};

struct TlasInstance {
    uint32_t sceneInstance = 0;
    BlasId blas = 0;
    glm::mat4 transform{1.0f};  // object to world
    uint32_t customIndex = 0;   // first row of this instance in BvhPlan::primitiveOffsets (24 bits)
    uint32_t sbtOffset = 0;     // hit group record offset (glint/packing.h)
    uint8_t mask = 0;           // one group bit (glint/packing.h kInstanceMask*)
    bool doubleSided = false;   // its BLAS's: back faces are not culled
};

struct BvhStats {
    uint32_t built = 0;    // first builds (FirstInRange)
    uint32_t rebuilt = 0;  // rebuilds, first-person ones included
    uint32_t rebuiltSkinned = 0;
    uint32_t rebuiltFirstPerson = 0;
    uint32_t dropped = 0;
    uint32_t skippedUnchanged = 0;       // deformable BLASes whose object did not deform
    uint32_t skippedOutOfRange = 0;      // deformed, but outside the radius: rebuilt when back in range
    uint32_t deferredBudget = 0;         // deformed, waiting: the frame's 16 rebuilds were used
    uint32_t deferredSkinnedBudget = 0;  // skinned, waiting: the frame's 12 skinned rebuilds were used
    uint32_t deferredFirstBuilds = 0;    // BLASes of objects in range not built yet: the first-build budget was used
    uint32_t instancesAwaitingBlas = 0;  // in range, but a BLAS of theirs is not built yet: not in the TLAS
    uint32_t staticReused = 0;           // static BLASes in the TLAS without any build
    uint32_t instancesInRange = 0;
    uint32_t instancesCulled = 0;       // outside their radius: not in the TLAS
    uint32_t instancesWithoutBlas = 0;  // culled and never built (never within the radius)
    uint32_t instancesMoved = 0;        // transform changed: a TLAS update, no BLAS work
    uint32_t tlasInstances = 0;
    uint32_t residentBlases = 0;
    uint64_t poolTriangles = 0;
    uint64_t builtTriangles = 0;  // triangles of this frame's builds and rebuilds
};

struct BvhPlan {
    uint64_t frame = 0;
    std::vector<BlasDesc> blases;   // every resident BLAS after this frame, by id
    std::vector<BlasBuild> builds;  // build or rebuild these this frame, in this order
    std::vector<BlasDrop> drops;    // release these (they are no longer in `blases`)
    std::vector<TlasInstance> tlas;
    std::vector<uint32_t> primitiveOffsets;  // [customIndex + geometry] -> first triangle in the pool
    uint32_t poolTriangles = 0;              // pool size in triangles (times kPackedPrimitiveBytes)
    bool particleTlas = false;               // build the particle TLAS this frame
    uint32_t particleCount = 0;
    BvhStats stats;

    const BlasDesc* find(BlasId id) const;
    // Every instance in range is in the TLAS: no first build is waiting.
    // Until then a ray tracer's miss may have passed where an unbuilt
    // object stands.
    bool complete() const { return stats.instancesAwaitingBlas == 0; }
};

// One line of stats for logs.
std::string formatStats(const BvhStats& stats);

// Geometry indices of each BLAS of an object: one BLAS holding all of them
// when there are at most `maxGeometries`; otherwise geometries grouped by
// material (a material's geometries stay together), groups packed first-fit
// into BLASes of at most `maxGeometries`, a group larger than that chunked.
std::vector<std::vector<uint32_t>> partitionGeometries(const MeshLod& lod, uint32_t maxGeometries);

// Hands out contiguous triangle ranges of the primitive pool: first fit over
// the free ranges, growing the pool at the end when none fits; freed ranges
// merge with their neighbours and become reusable after a delay.
class PoolAllocator {
public:
    uint32_t allocate(uint32_t triangles);
    // `range` becomes reusable once `frame` >= `reusableFrom`.
    void release(uint32_t offset, uint32_t triangles, uint64_t reusableFrom);
    void advance(uint64_t frame);  // makes due releases reusable
    uint32_t size() const { return end_; }

private:
    void insertFree(uint32_t offset, uint32_t triangles);
    std::map<uint32_t, uint32_t> free_;  // offset -> triangles
    struct Pending {
        uint32_t offset, triangles;
        uint64_t reusableFrom;
    };
    std::vector<Pending> pending_;
    uint32_t end_ = 0;
};

class BvhPlanner {
public:
    explicit BvhPlanner(const BvhSettings& settings = {});

    // The plan for `frame` (strictly increasing) seen from `cameraPosition`:
    // the TLAS holds the instances within `radius` of it (> 0; the
    // long-range group within max(radius, BvhSettings::longRangeRadius)).
    BvhPlan plan(const Scene& scene, const glm::vec3& cameraPosition, uint64_t frame,
                 float radius = kDefaultBvhRadius);
    BvhPlan plan(const Scene& scene, const Camera& camera, float radius = kDefaultBvhRadius) {
        return plan(scene, camera.position, camera.frameIndex, radius);
    }

    const BvhSettings& settings() const { return settings_; }
    // Forgets every BLAS (device loss, scene switch): the next plan builds afresh.
    void reset();

private:
    struct Key {
        bool perInstance;  // deformable: owned by an instance; static: shared by a mesh
        uint32_t owner;    // instance or mesh index
        uint32_t mesh;
        uint32_t lod;
        uint32_t part;
        auto operator<=>(const Key&) const = default;
    };
    struct Resident {
        BlasDesc desc;
        uint64_t builtShape = 0;  // deformationStamp of the instance the BLAS was last built from
        uint64_t lastInRange = 0;   // last frame an object of it was within its radius
        uint64_t lastBuilt = 0;
    };

    BvhSettings settings_;
    std::map<Key, Resident> resident_;
    std::vector<Key> roundRobin_;  // deformable, non-first-person BLASes, least recently rebuilt first
    PoolAllocator pool_;
    BlasId nextId_ = 1;
    bool havePlanned_ = false;
    uint64_t lastFrame_ = 0;
    AssetStamp assets_;  // of the last plan's scene
};

// A hash of what shapes a deformable instance's BLAS: its deformVersion,
// mesh, skin, joint matrices (this frame's, of its skin's range) and morph
// weights. Equal stamps, equal shapes (up to a 64-bit hash collision).
uint64_t deformationStamp(const Scene& scene, const Instance& instance);

} // namespace glint::scene
