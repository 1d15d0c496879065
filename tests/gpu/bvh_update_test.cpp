// The GPU side of the BVH manager (passes/bvh_update.h) on a real device,
// validation and synchronization validation on: the packed pool against the
// CPU reference, rays that hit known triangles through both ray backends,
// skinned objects over several frames, and the cross-queue ordering of the
// builds in a two-queue plan.
#include "support/gpu_test.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan.h"
#include "glint/passes/bvh_update.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/packed_primitives.h"

#include "glint/bvh_shared.h"
#include "glint/packing.h"

#include <glm/gtc/matrix_inverse.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <string>

using namespace glint;

namespace {

enum class Backend { RayQuery, Pipeline };

const char* backendName(Backend b) { return b == Backend::RayQuery ? "ray query" : "ray tracing pipeline"; }

constexpr rg::BoundaryState kHostWritten =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
constexpr rg::BoundaryState kHostRead =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
constexpr uint32_t kMaxRays = 256;

// Traces BvhProbeRays through the BVH update's outputs with either backend,
// as a graph pass on the graphics queue.
class Probe {
public:
    explicit Probe(gpu::Context& ctx) : ctx_(ctx) {
        const VkShaderStageFlags all =
            VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
        const std::vector<gpu::Binding> bindings = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, all},
                                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all},
                                                    {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all},
                                                    {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all},
                                                    {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all}};
        if (ctx.caps().rayQuery) {
            backends.push_back(Backend::RayQuery);
            query_ = gpu::createComputePipeline(ctx, {"test/bvh_probe_query.comp", bindings, 4, "test.bvh_probe_query"});
        }
        if (ctx.caps().rayTracingPipeline) {
            backends.push_back(Backend::Pipeline);
            pipeline_ = gpu::createRayTracingPipeline(
                ctx, {"test/bvh_probe.rgen", {"test/bvh_probe.rmiss"}, {{"test/bvh_probe.rchit", ""}}, bindings, 4, 1,
                      "test.bvh_probe_pipeline"});
            sbt_.emplace(ctx, pipeline_, 1, 1);
        }
        rays_ = gpu::Buffer(ctx, {kMaxRays * sizeof(shader::BvhProbeRay), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                  gpu::MemoryUsage::Upload, "test.probe_rays", true});
        for (size_t i = 0; i < backends.size(); ++i) {
            hits_[i] = gpu::Buffer(ctx, {kMaxRays * sizeof(shader::BvhProbeHit), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                         gpu::MemoryUsage::Readback, "test.probe_hits", true});
        }
    }

    // Adds one probe pass per backend; the rays are written now (the caller
    // waits for the previous frame before declaring the next).
    void add(rg::Graph& graph, const passes::BvhUpdateOutputs& bvh, const std::vector<shader::BvhProbeRay>& rays,
             rg::FrameResources& frame) {
        REQUIRE(rays.size() <= kMaxRays);
        rayCount_ = uint32_t(rays.size());
        std::memcpy(rays_.mapped(), rays.data(), rays.size() * sizeof(rays[0]));
        const rg::Buffer rayHandle = graph.importBuffer("probe.rays", {{rays_.size()}, kHostWritten, kHostWritten});
        frame.bind(rayHandle, rays_);
        for (size_t i = 0; i < backends.size(); ++i) {
            const Backend backend = backends[i];
            const rg::Buffer hitHandle =
                graph.importBuffer(std::string("probe.hits.") + backendName(backend), {{hits_[i].size()}, kHostRead, kHostRead});
            frame.bind(hitHandle, hits_[i]);
            struct Data {
                rg::AccelStruct tlas;
                rg::Buffer pool, offsets, rays, hits;
            };
            graph.addPass<Data>(
                std::string("probe ") + backendName(backend), rg::Queue::Graphics,
                [&](rg::Builder& b, Data& d) {
                    b.setPipeline(backend == Backend::RayQuery ? rg::Pipeline::Compute : rg::Pipeline::RayTracing);
                    d.tlas = b.read(bvh.tlas, rg::Access::AccelRead);
                    d.pool = b.read(bvh.primitivePool, rg::Access::StorageRead);
                    d.offsets = b.read(bvh.primitiveOffsets, rg::Access::StorageRead);
                    d.rays = b.read(rayHandle, rg::Access::StorageRead);
                    d.hits = b.write(hitHandle, rg::Access::StorageWrite);
                },
                [this, backend](const Data& d, rg::PassContext& pc) {
                    const gpu::Pipeline& p = backend == Backend::RayQuery ? query_ : pipeline_;
                    p.bind(pc.cmd());
                    gpu::PushDescriptors(p)
                        .accelerationStructure(0, pc.accel(d.tlas).handle())
                        .storageBuffer(1, pc.buffer(d.pool))
                        .storageBuffer(2, pc.buffer(d.offsets))
                        .storageBuffer(3, pc.buffer(d.rays))
                        .storageBuffer(4, pc.buffer(d.hits))
                        .push(pc.gpu(), pc.cmd());
                    p.pushConstants(pc.cmd(), rayCount_);
                    if (backend == Backend::RayQuery) {
                        vkCmdDispatch(pc.cmd(), (rayCount_ + shader::kBvhProbeGroupSize - 1) / shader::kBvhProbeGroupSize,
                                      1, 1);
                    } else {
                        sbt_->traceRays(pc.gpu(), pc.cmd(), rayCount_, 1);
                    }
                });
        }
    }

    // After the frame finished.
    std::vector<shader::BvhProbeHit> hits(size_t backendIndex) const {
        const auto span = hits_[backendIndex].mappedSpan<shader::BvhProbeHit>();
        return {span.begin(), span.begin() + rayCount_};
    }

    std::vector<Backend> backends;

private:
    gpu::Context& ctx_;
    gpu::Pipeline query_, pipeline_;
    std::optional<gpu::ShaderBindingTable> sbt_;
    gpu::Buffer rays_;
    gpu::Buffer hits_[2];
    uint32_t rayCount_ = 0;
};

// A triangle of a TLAS instance that a probe ray aims at.
struct Target {
    uint32_t customIndex = 0;
    uint32_t geometry = 0;
    uint32_t primitive = 0;
    glm::vec3 world[3];        // vertices, world space, as the CPU reference places them
    glm::vec2 barycentrics{0.25f, 0.35f};
    shader::SurfaceVertex unquantised[3];  // surfaceAtVertex (normals unskinned)
    bool skinned = false;
};

// The reference's object-space positions of one BLAS geometry (skinned with
// the instance's current joints where it is skinned).
scene::UnwrappedGeometry unwrapBlasGeometry(const scene::Scene& s, const scene::BlasDesc& blas, uint32_t g) {
    const scene::Geometry& geometry = s.meshes[blas.mesh].lods[blas.lod].geometries[blas.geometries[g].meshGeometry];
    std::span<const glm::mat4> joints;
    if (blas.motion == scene::Motion::Skinned && blas.instance != scene::kNone) {
        const scene::Instance& inst = s.instances[size_t(blas.instance)];
        joints = {s.jointMatrices.data() + inst.jointOffset, s.skins[size_t(inst.skin)].joints.size()};
    }
    return scene::unwrapGeometry(s, geometry, joints);
}

// The largest triangle of geometry `g` of the TLAS instance `ti`.
Target targetLargestTriangle(const scene::Scene& s, const scene::BvhPlan& plan, const scene::TlasInstance& ti,
                             uint32_t g) {
    const scene::BlasDesc& blas = *plan.find(ti.blas);
    const scene::UnwrappedGeometry u = unwrapBlasGeometry(s, blas, g);
    Target t;
    t.customIndex = ti.customIndex;
    t.geometry = g;
    t.skinned = blas.motion == scene::Motion::Skinned;
    float best = -1.0f;
    for (uint32_t p = 0; p < u.primitives.size(); ++p) {
        const float area = glm::length(glm::cross(u.positions[3 * p + 1] - u.positions[3 * p],
                                                  u.positions[3 * p + 2] - u.positions[3 * p]));
        if (area > best) {
            best = area;
            t.primitive = p;
        }
    }
    const scene::Geometry& geometry =
        s.meshes[blas.mesh].lods[blas.lod].geometries[blas.geometries[g].meshGeometry];
    for (uint32_t k = 0; k < 3; ++k) {
        t.world[k] = glm::vec3(ti.transform * glm::vec4(u.positions[3 * t.primitive + k], 1.0f));
        t.unquantised[k] = scene::surfaceAtVertex(s, geometry, geometry.indices[3 * t.primitive + k]);
    }
    return t;
}

glm::vec3 pointOf(const Target& t) {
    const float w0 = 1.0f - t.barycentrics.x - t.barycentrics.y;
    return t.world[0] * w0 + t.world[1] * t.barycentrics.x + t.world[2] * t.barycentrics.y;
}

// A short ray along the face normal onto the target point: 1 mm away, so
// nothing but the target (or a surface within a millimetre) can be hit.
constexpr float kProbeOffset = 1.0e-3f;
shader::BvhProbeRay rayAt(const Target& t) {
    const glm::vec3 n = glm::normalize(glm::cross(t.world[1] - t.world[0], t.world[2] - t.world[0]));
    return {pointOf(t) + n * kProbeOffset, 0.0f, -n, 2.0f * kProbeOffset};
}

struct AttributeError {
    float albedo = 0, roughness = 0, metallic = 0, reflectance = 0, normalDegrees = 0;
};

float angleDegrees(const glm::vec3& a, const glm::vec3& b) {
    return glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f)));
}

AttributeError compare(const shader::BvhProbeHit& h, const shader::SurfaceVertex& e) {
    AttributeError err;
    err.albedo = glm::length(h.albedo - e.albedo);
    err.roughness = std::abs(h.roughness - e.roughness);
    err.metallic = std::abs(h.metallic - e.metallic);
    err.reflectance = std::abs(h.reflectance - e.reflectance);
    err.normalDegrees = angleDegrees(h.normal, e.normal);
    return err;
}

// Octahedral X/Y codes of two packed words may differ by one step each (the
// GPU normalises with its own rounding); every other bit must match.
bool packedWordsMatch(const shader::PackedVertex& gpu, const shader::PackedVertex& cpu) {
    if (gpu.albedoSmoothness != cpu.albedoSmoothness) return false;
    if ((gpu.normalMetallicReflectance >> 16) != (cpu.normalMetallicReflectance >> 16)) return false;
    for (uint32_t shift : {0u, 8u}) {
        const int a = int8_t((gpu.normalMetallicReflectance >> shift) & 0xFFu);
        const int b = int8_t((cpu.normalMetallicReflectance >> shift) & 0xFFu);
        if (std::abs(a - b) > 1) return false;
    }
    return true;
}

struct PoolComparison {
    size_t triangles = 0;
    size_t exact = 0;
    size_t withinOneStep = 0;
    size_t mismatches = 0;
    std::string firstMismatch;
};

PoolComparison comparePools(const std::vector<shader::PackedPrimitive>& gpu,
                            const std::vector<shader::PackedPrimitive>& cpu) {
    PoolComparison c;
    c.triangles = cpu.size();
    for (size_t t = 0; t < cpu.size(); ++t) {
        if (std::memcmp(&gpu[t], &cpu[t], sizeof(cpu[t])) == 0) {
            ++c.exact;
            continue;
        }
        bool ok = true;
        for (int k = 0; k < 3; ++k) ok = ok && packedWordsMatch(gpu[t].vertices[k], cpu[t].vertices[k]);
        if (ok) {
            ++c.withinOneStep;
        } else if (c.mismatches++ == 0) {
            c.firstMismatch = "triangle " + std::to_string(t);
        }
    }
    return c;
}

std::vector<shader::PackedPrimitive> readPool(gpu::Context& ctx, const passes::BvhManager& bvh, uint32_t triangles) {
    std::vector<shader::PackedPrimitive> pool = gpu::readbackBufferAs<shader::PackedPrimitive>(ctx, bvh.primitivePool());
    REQUIRE(pool.size() >= triangles);
    pool.resize(triangles);
    return pool;
}

// One scene, its planner and the GPU side, frame after frame.
struct Rig {
    test::GpuTest gpu;
    rg::Executor executor{gpu.ctx()};
    scene::Scene scene;
    scene::BvhPlanner planner;
    std::unique_ptr<passes::BvhManager> bvh;
    Probe probe{gpu.ctx()};
    glm::vec3 camera{0.0f};
    uint64_t frame = 0;

    explicit Rig(scene::Scene s, const scene::BvhSettings& settings = {}) : scene(std::move(s)), planner(settings) {
        bvh = std::make_unique<passes::BvhManager>(gpu.ctx(), scene);
        camera = scene.cameraPath.atFrame(0, 1).position;
    }

    // Plans, builds and (optionally) probes one frame; waits for it unless
    // told not to (then frames overlap as in an application).
    scene::BvhPlan run(const std::vector<shader::BvhProbeRay>& rays = {}, bool wait = true) {
        scene::BvhPlan plan = planner.plan(scene, camera, frame++);
        rg::Graph graph(executor.queueCaps());
        const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, *bvh, plan);
        rg::FrameResources resources;
        bvh->bind(resources, out);
        if (!rays.empty()) {
            probe.add(graph, out, rays, resources);
        }
        executor.run(graph.compile(executor.compileOptions()), resources);
        if (wait) {
            executor.waitIdle();
        }
        return plan;
    }
};

} // namespace

namespace {

void checkPoolMatchesReference(const std::string& name) {
    Rig rig(scene::loadScene(name));
    const scene::BvhPlan plan = rig.run();
    REQUIRE(plan.poolTriangles > 0);
    const auto gpuPool = readPool(rig.gpu.ctx(), *rig.bvh, plan.poolTriangles);
    const auto cpuPool = scene::buildPrimitivePool(rig.scene, plan);
    const PoolComparison c = comparePools(gpuPool, cpuPool);
    MESSAGE(name << ": " << c.triangles << " triangles, " << c.exact << " bit-exact, " << c.withinOneStep
                 << " within one octahedral step");
    CHECK_MESSAGE(c.mismatches == 0, c.firstMismatch);
    CHECK(c.exact * 2 > c.triangles);  // the same maths on both sides: most match bit for bit
    CHECK(rig.bvh->stats().blasBuilds == plan.stats.built);
    CHECK(rig.bvh->stats().residentBlases == plan.stats.residentBlases);
}

} // namespace

TEST_CASE("the GPU-packed primitive pool of the plaza (textures, skins) equals the CPU reference") {
    checkPoolMatchesReference("plaza");
}

TEST_CASE("the GPU-packed primitive pool of a textured glTF equals the CPU reference") {
    checkPoolMatchesReference(std::string(GLINT_SCENES_DIR) + "/WaterBottle/WaterBottle.gltf");
}

TEST_CASE("a morphing instance's BLAS packs its morphed shape, equal to the CPU reference, and follows new weights") {
    // Quads whose one morph target lifts them along +z and tilts their
    // normals towards +x; half weight, then full.
    scene::Geometry quad;
    quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    quad.normals.assign(4, {0, 0, 1});
    quad.indices = {0, 1, 2, 0, 2, 3};
    scene::MorphTarget target;
    target.positions.assign(4, {0, 0, 2});
    target.normals.assign(4, {1, 0, -1});
    quad.morphTargets.push_back(target);
    scene::Scene s;
    s.name = "bvh-morph-test";
    s.materials.emplace_back();
    scene::Mesh mesh;
    mesh.name = "morphing quad";
    // Two geometries: each BLAS geometry gets morphed vertices of its own.
    scene::Geometry second = quad;
    for (glm::vec3& p : second.positions) p.x += 3.0f;
    mesh.lods.push_back({{quad, second}});
    mesh.morphWeights = {0.5f};
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.motion = scene::Motion::Dynamic;
    s.instances.push_back(inst);
    s.cameraPath.keys = {{0.0f, {0, 0, 5}, {0, 0, 0}}};
    scene::prepareScene(s);
    REQUIRE(s.instances[0].morphWeights == std::vector<float>{0.5f});

    Rig rig(std::move(s));
    for (const float weight : {0.5f, 1.0f}) {
        INFO("weight " << weight);
        rig.scene.instances[0].morphWeights = {weight};
        ++rig.scene.instances[0].deformVersion;
        const scene::BvhPlan plan = rig.run();
        REQUIRE(plan.poolTriangles == 4);
        REQUIRE(plan.builds.size() == 1);
        const auto gpuPool = readPool(rig.gpu.ctx(), *rig.bvh, plan.poolTriangles);
        const auto cpuPool = scene::buildPrimitivePool(rig.scene, plan);
        const PoolComparison c = comparePools(gpuPool, cpuPool);
        CHECK_MESSAGE(c.mismatches == 0, c.firstMismatch);
        // The morphed normal, not the base one: (w, 0, 1 - w) normalised.
        const glm::vec3 n = shader::unpackOctNormal(gpuPool[0].vertices[0].normalMetallicReflectance & 0xFFFFu);
        const glm::vec3 expected = glm::normalize(glm::vec3(weight, 0.0f, 1.0f - weight));
        CHECK(glm::length(n - expected) < 0.02f);
    }
    // Frames in flight: each rebuild writes its own slot's morphed vertices.
    scene::BvhPlan last;
    for (int frame = 0; frame < 5; ++frame) {
        rig.scene.instances[0].morphWeights = {0.2f * float(frame)};
        ++rig.scene.instances[0].deformVersion;
        last = rig.run({}, false);
    }
    rig.executor.waitIdle();
    const PoolComparison c =
        comparePools(readPool(rig.gpu.ctx(), *rig.bvh, last.poolTriangles), scene::buildPrimitivePool(rig.scene, last));
    CHECK_MESSAGE(c.mismatches == 0, c.firstMismatch);
}

TEST_CASE("a probe ray hits a known triangle of the plaza and reads its interpolated packed attributes") {
    Rig rig(scene::makePlaza());
    const scene::BvhPlan first = rig.run();  // builds everything in range
    REQUIRE(first.tlas.size() >= 8);

    // The largest triangle of geometry 0 of every eighth TLAS instance.
    std::vector<Target> targets;
    for (size_t i = 0; i < first.tlas.size(); i += 8) {
        targets.push_back(targetLargestTriangle(rig.scene, first, first.tlas[i], 0));
    }
    std::vector<shader::BvhProbeRay> rays;
    for (const Target& t : targets) rays.push_back(rayAt(t));
    // Same scene time: nothing deforms, so the second plan only refits the TLAS.
    const scene::BvhPlan plan = rig.run(rays);
    CHECK(plan.builds.empty());
    const auto cpuPool = scene::buildPrimitivePool(rig.scene, plan);

    REQUIRE(!rig.probe.backends.empty());
    for (size_t b = 0; b < rig.probe.backends.size(); ++b) {
        const std::string backend = backendName(rig.probe.backends[b]);
        CAPTURE(backend);
        const auto hits = rig.probe.hits(b);
        AttributeError worstPacked, worstTrue;
        for (size_t i = 0; i < targets.size(); ++i) {
            const Target& t = targets[i];
            const shader::BvhProbeHit& h = hits[i];
            CAPTURE(i);
            REQUIRE(h.hit == 1u);
            CHECK(h.customIndex == t.customIndex);
            CHECK(h.geometry == t.geometry);
            CHECK(h.primitive == t.primitive);
            CHECK(h.t == doctest::Approx(kProbeOffset).epsilon(0.05));
            CHECK(std::abs(h.barycentrics.x - t.barycentrics.x) < 1e-3f);
            CHECK(std::abs(h.barycentrics.y - t.barycentrics.y) < 1e-3f);

            // Against the CPU pool: the same interpolation of the same bits.
            const uint32_t row = cpuPool.size() ? plan.primitiveOffsets.at(shader::primitiveOffsetSlot(h.customIndex, h.geometry)) : 0;
            const shader::SurfaceVertex packed = shader::interpolateSurface(cpuPool.at(row + h.primitive), h.barycentrics);
            const AttributeError e = compare(h, packed);
            worstPacked.albedo = std::max(worstPacked.albedo, e.albedo);
            worstPacked.normalDegrees = std::max(worstPacked.normalDegrees, e.normalDegrees);
            CHECK(e.albedo < 1e-4f);
            CHECK(e.roughness < 1e-4f);
            CHECK(e.metallic < 1e-4f);
            CHECK(e.reflectance < 1e-4f);
            CHECK(e.normalDegrees < 1.0f);  // one octahedral step at most

            // Against the unquantised surface: within 8-bit quantisation.
            shader::SurfaceVertex truth{};
            const float w[3] = {1.0f - t.barycentrics.x - t.barycentrics.y, t.barycentrics.x, t.barycentrics.y};
            for (int k = 0; k < 3; ++k) {
                truth.albedo += w[k] * t.unquantised[k].albedo;
                truth.roughness += w[k] * t.unquantised[k].roughness;
                truth.metallic += w[k] * t.unquantised[k].metallic;
                truth.reflectance += w[k] * t.unquantised[k].reflectance;
                truth.normal += w[k] * glm::normalize(t.unquantised[k].normal);
            }
            const AttributeError q = compare(h, truth);
            worstTrue.albedo = std::max(worstTrue.albedo, q.albedo);
            worstTrue.roughness = std::max(worstTrue.roughness, q.roughness);
            // Half an 8-bit step in sRGB is at most ~0.5/255 * 2.4 in linear (the
            // steepest part of the curve), per channel.
            CHECK(q.albedo < 0.01f);
            CHECK(q.roughness < 1.0f / 255.0f);
            CHECK(q.metallic < 1.0f / 255.0f);
            CHECK(q.reflectance < 1.0f / 255.0f);
            if (!t.skinned) {
                worstTrue.normalDegrees = std::max(worstTrue.normalDegrees, q.normalDegrees);
                CHECK(q.normalDegrees < 1.0f);  // the precise encoder's 0.65 degrees, interpolated
            }
        }
        MESSAGE(backend << ": " << targets.size() << " targets; worst vs CPU pool: albedo "
                << worstPacked.albedo << ", normal " << worstPacked.normalDegrees << " deg; worst vs unquantised: albedo "
                << worstTrue.albedo << ", roughness " << worstTrue.roughness << ", normal " << worstTrue.normalDegrees
                << " deg");
    }
}

TEST_CASE("skinned and animated plaza objects: rebuilds follow the plan, the pool and the hits follow the CPU skinning") {
    Rig rig(scene::makePlaza());
    std::vector<shader::PackedPrimitive> mirror;  // what the pool must hold: each BLAS as of its last build
    uint32_t skinnedHitsChecked = 0;
    uint32_t movedTargets = 0;
    std::map<scene::BlasId, glm::vec3> firstPoint;
    constexpr int kFrames = 5;
    std::vector<shader::BvhProbeRay> rays;
    std::vector<Target> targets;
    for (int f = 0; f < kFrames; ++f) {
        CAPTURE(f);
        // 10 Hz steps: the palms, flags and walkers move visibly between frames.
        scene::advanceScene(rig.scene, 0.1 * f);
        // Aim at the skinned BLASes this frame will rebuild: their triangles
        // are where this frame's CPU skinning puts them. Needs this frame's
        // plan, so plan on a copy of the planner first.
        scene::BvhPlanner preview = rig.planner;
        const scene::BvhPlan expected = preview.plan(rig.scene, rig.camera, rig.frame);
        rays.clear();
        targets.clear();
        for (const scene::TlasInstance& ti : expected.tlas) {
            const scene::BlasDesc* d = expected.find(ti.blas);
            const bool rebuilt = std::any_of(expected.builds.begin(), expected.builds.end(),
                                             [&](const scene::BlasBuild& b) { return b.blas == ti.blas; });
            if (d->motion == scene::Motion::Skinned && rebuilt && targets.size() < 8) {
                targets.push_back(targetLargestTriangle(rig.scene, expected, ti, 0));
                rays.push_back(rayAt(targets.back()));
                const auto [it, inserted] = firstPoint.try_emplace(ti.blas, pointOf(targets.back()));
                if (!inserted && glm::distance(it->second, pointOf(targets.back())) > 1e-3f) ++movedTargets;
            }
        }

        const scene::BvhPlan plan = rig.run(rays);
        REQUIRE(plan.builds.size() == expected.builds.size());
        const passes::BvhGpuStats& stats = rig.bvh->stats();
        CHECK(stats.blasBuilds == plan.stats.built);
        CHECK(stats.blasRebuilds == plan.stats.rebuilt);
        CHECK(stats.blasReleased == plan.stats.dropped);
        CHECK(stats.tlasInstances == plan.tlas.size());
        CHECK(stats.residentBlases == plan.stats.residentBlases);
        if (f > 0) {
            CHECK(plan.stats.rebuiltSkinned > 0);
            CHECK(plan.stats.built == 0);
        }

        // The pool: rebuilt BLASes as the CPU skins them now, the others as of
        // their last build (a deferred BLAS keeps last build's primitives).
        mirror.resize(plan.poolTriangles);
        for (const scene::BlasBuild& b : plan.builds) {
            const scene::BlasDesc& d = *plan.find(b.blas);
            for (uint32_t g = 0; g < d.geometries.size(); ++g) {
                const auto u = unwrapBlasGeometry(rig.scene, d, g);
                std::copy(u.primitives.begin(), u.primitives.end(), mirror.begin() + d.geometries[g].poolOffset);
            }
        }
        const PoolComparison c = comparePools(readPool(rig.gpu.ctx(), *rig.bvh, plan.poolTriangles), mirror);
        CHECK_MESSAGE(c.mismatches == 0, c.firstMismatch);

        for (size_t b = 0; b < rig.probe.backends.size(); ++b) {
            const std::string backend = backendName(rig.probe.backends[b]);
        CAPTURE(backend);
            const auto hits = rig.probe.hits(b);
            for (size_t i = 0; i < targets.size(); ++i) {
                CAPTURE(i);
                CHECK(hits[i].hit == 1u);
                CHECK(hits[i].customIndex == targets[i].customIndex);
                CHECK(hits[i].primitive == targets[i].primitive);
                CHECK(hits[i].t == doctest::Approx(kProbeOffset).epsilon(0.05));
                ++skinnedHitsChecked;
            }
        }
    }
    MESSAGE(skinnedHitsChecked << " skinned hits checked; " << movedTargets << " targets had moved since first aimed at");
    CHECK(skinnedHitsChecked > 0);
    CHECK(movedTargets > 0);
}

TEST_CASE("frames in flight: BLASes evicted and rebuilt, the pool grown, static primitives kept") {
    scene::BvhSettings settings;
    settings.evictAfterFramesOutside = 2;
    Rig rig(scene::makePlaza(), settings);
    const glm::vec3 home = rig.camera;
    // Out of everything's reach, closing in, away again (evictions), back.
    const glm::vec3 path[] = {home + glm::vec3(5000, 0, 0), home + glm::vec3(160, 0, 0), home + glm::vec3(60, 0, 0),
                              home, home + glm::vec3(5000, 0, 0), home + glm::vec3(5000, 0, 0),
                              home + glm::vec3(5000, 0, 0), home + glm::vec3(5000, 0, 0), home};
    std::vector<shader::PackedPrimitive> mirror;
    // Every resident BLAS's range holds its primitives, whichever frame built
    // it and however often the pool moved since.
    const auto checkResident = [&](const scene::BvhPlan& plan) {
        rig.executor.waitIdle();
        const auto gpuPool = readPool(rig.gpu.ctx(), *rig.bvh, plan.poolTriangles);
        std::vector<shader::PackedPrimitive> gpuResident, cpuResident;
        for (const scene::BlasDesc& d : plan.blases) {
            gpuResident.insert(gpuResident.end(), gpuPool.begin() + d.poolOffset,
                               gpuPool.begin() + d.poolOffset + d.triangleCount);
            cpuResident.insert(cpuResident.end(), mirror.begin() + d.poolOffset,
                               mirror.begin() + d.poolOffset + d.triangleCount);
        }
        REQUIRE(!cpuResident.empty());
        const PoolComparison c = comparePools(gpuResident, cpuResident);
        CHECK_MESSAGE(c.mismatches == 0, c.firstMismatch);
    };
    uint32_t builds = 0, drops = 0;
    scene::BvhPlan plan;
    for (size_t f = 0; f < std::size(path); ++f) {
        CAPTURE(f);
        rig.camera = path[f];
        // Objects entering range for the first time (frames 1-3) have their
        // geometry copied inside the update pass: no blocking submission.
        const uint64_t blockingBefore = rig.gpu.ctx().blockingSubmits();
        const uint32_t uploadedBefore = rig.bvh->stats().uploadedGeometries;
        plan = rig.run({}, false);
        if (f > 0) {
            CHECK(rig.gpu.ctx().blockingSubmits() == blockingBefore);
        }
        if (f == 1) {
            CHECK(rig.bvh->stats().uploadedGeometries > uploadedBefore);
        }
        builds += plan.stats.built;
        drops += plan.stats.dropped;
        mirror.resize(std::max<size_t>(mirror.size(), plan.poolTriangles));
        for (const scene::BlasBuild& b : plan.builds) {
            const scene::BlasDesc& d = *plan.find(b.blas);
            for (uint32_t g = 0; g < d.geometries.size(); ++g) {
                const auto u = unwrapBlasGeometry(rig.scene, d, g);
                std::copy(u.primitives.begin(), u.primitives.end(), mirror.begin() + d.geometries[g].poolOffset);
            }
        }
        CHECK(rig.bvh->stats().residentBlases == plan.stats.residentBlases);
        if (f == 2) {
            // The pool outgrew its first allocation while BLASes built in
            // frame 1 lived in it: their primitives must have moved along.
            CHECK(rig.bvh->stats().poolGrowths > 0);
            checkResident(plan);
        }
    }
    checkResident(plan);
    MESSAGE(builds << " builds, " << drops << " drops, " << rig.bvh->stats().poolGrowths << " pool growths over "
                   << std::size(path) << " overlapping frames");
    CHECK(drops > 0);
    CHECK(builds > plan.stats.residentBlases);  // evicted BLASes came back
}

TEST_CASE("on two queues the async BVH build waits for the previous frame's graphics traces") {
    test::GpuTest gpu;
    scene::Scene s = scene::makePlaza();
    scene::BvhPlanner planner;
    passes::BvhManager bvh(gpu.ctx(), s);
    const scene::BvhPlan plan = planner.plan(s, s.cameraPath.atFrame(0, 1).position, 0);

    rg::QueueCaps caps;
    caps.separateComputeFamily = true;
    caps.graphicsFamily = 0;
    caps.computeFamily = 1;
    caps.rayQuery = true;
    caps.rayTracingPipeline = true;
    rg::Graph graph(caps);
    const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, plan);
    struct Data {
        rg::AccelStruct tlas;
        rg::Buffer pool, offsets, radiance;
    };
    const Data& trace = graph.addPass<Data>("trace_reflections", rg::Queue::Graphics, [&](rg::Builder& b, Data& d) {
        b.setPipeline(rg::Pipeline::RayTracing);
        d.tlas = b.read(out.tlas, rg::Access::AccelRead);
        d.pool = b.read(out.primitivePool, rg::Access::StorageRead);
        d.offsets = b.read(out.primitiveOffsets, rg::Access::StorageRead);
        d.radiance = b.write(b.createBuffer("rt.radiance", {1024}), rg::Access::StorageWrite);
    }, [](const Data&, rg::PassContext&) {});
    graph.markOutput(trace.radiance);
    const rg::Plan compiled = graph.compile();
    const std::string text = compiled.toText();
    CAPTURE(text);
    // The BVH batch on the compute queue waits for last frame's graphics work
    // (it rebuilds what that frame traced), and this frame's trace waits for it.
    CHECK(text.find("graphics batch 0 of the previous frame") != std::string::npos);
    CHECK(text.find("bvh_update") != std::string::npos);
    MESSAGE(text);
}

TEST_CASE("BvhUpdateOptions::queue = Graphics keeps the builds on the graphics queue of a two-queue device") {
    test::GpuTest gpu;
    scene::Scene s = scene::makePlaza();
    scene::BvhPlanner planner;
    passes::BvhUpdateOptions options;
    options.queue = rg::Queue::Graphics;
    passes::BvhManager bvh(gpu.ctx(), s, 2, options);
    CHECK((bvh.options().queue == rg::Queue::Graphics));
    const scene::BvhPlan plan = planner.plan(s, s.cameraPath.atFrame(0, 1).position, 0);

    rg::QueueCaps caps;
    caps.separateComputeFamily = true;
    caps.graphicsFamily = 0;
    caps.computeFamily = 1;
    caps.rayQuery = true;
    caps.rayTracingPipeline = true;
    rg::Graph graph(caps);
    const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, plan);
    struct Data {
        rg::AccelStruct tlas;
        rg::Buffer radiance;
    };
    const Data& trace = graph.addPass<Data>("trace_reflections", rg::Queue::Graphics, [&](rg::Builder& b, Data& d) {
        b.setPipeline(rg::Pipeline::RayTracing);
        d.tlas = b.read(out.tlas, rg::Access::AccelRead);
        d.radiance = b.write(b.createBuffer("rt.radiance", {1024}), rg::Access::StorageWrite);
    }, [](const Data&, rg::PassContext&) {});
    graph.markOutput(trace.radiance);
    const rg::Plan compiled = graph.compile();
    CAPTURE(compiled.toText());
    REQUIRE(compiled.passes.size() == 2);
    for (const rg::PlannedPass& p : compiled.passes) {
        CHECK((p.queue == rg::Queue::Graphics));
    }
    CHECK(compiled.batches.size() == 1);  // one queue: nothing to wait for across queues
}
