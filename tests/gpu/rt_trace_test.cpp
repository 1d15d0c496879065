// Ray-traced hits and lighting (passes/rt_trace.h) on a real device behind
// the real G-buffer and BVH update, validation on. The ray lists are built
// here (PackedRays + args uploaded), so nothing depends on ray generation
// or SSLR. The scene: a floor the rays leave, a floating, rotated and
// non-uniformly scaled quad with known per-vertex colours and normals, and
// a roof that shadows part of it. The CPU reference starts each ray where
// the pass does (the G-buffer's depth, read back, and the same origin
// offset), so it holds whatever the rasteriser's precision. Hits match a
// CPU evaluation of the same formula (the packed surface interpolated at
// the hit, lit by a port of glint/brdf.glsl with an analytic shadow test);
// under probe lighting their colour and normal match the unquantised
// surface within the packing's quantisation; misses give the environment;
// both backends agree bit for bit; rays leaving a plane 10^4 units from
// the origin (or at it) do not hit it; only listed rays are traced.
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/bvh_update.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/rt_trace.h"
#include "glint/scene/animation.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/packed_primitives.h"

#include "glint/packing.h"
#include "glint/ray_generation_shared.h"
#include "glint/rt_trace_shared.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <random>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
using test::square;

constexpr rg::BoundaryState kHostWritten =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

size_t pixelIndex(glm::uvec2 p) { return size_t(p.y) * kSize + p.x; }

// ---------------------------------------------------------------------------
// CPU port of glint/brdf.glsl (the formula the hits must reproduce)
// ---------------------------------------------------------------------------

constexpr float kPi = 3.14159265358979f;
constexpr float kMinRoughness = 0.045f;

struct CpuSurface {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec3 albedo{0.0f};
    float roughness = 0.0f;
    float metallic = 0.0f;
    float reflectance = 0.0f;
};

glm::vec3 skyRadiance(const shader::SceneLighting& l, glm::vec3 dir) {
    const float y = std::clamp(dir.y, -1.0f, 1.0f);
    if (y < 0.0f) {
        return glm::mix(glm::vec3(l.skyHorizon), glm::vec3(l.skyGround), std::clamp(-y * 10.0f, 0.0f, 1.0f));
    }
    return glm::mix(glm::vec3(l.skyHorizon), glm::vec3(l.skyZenith), std::sqrt(y));
}

glm::vec3 skyIrradiance(const shader::SceneLighting& l, glm::vec3 n) {
    const glm::vec3 up = kPi * glm::mix(glm::vec3(l.skyHorizon), glm::vec3(l.skyZenith), 0.5f);
    const glm::vec3 down = kPi * glm::vec3(l.skyGround);
    return glm::mix(down, up, 0.5f + 0.5f * std::clamp(n.y, -1.0f, 1.0f));
}

glm::vec3 environmentRadiance(const shader::SceneLighting& l, glm::vec3 dir, float roughness) {
    const float alpha = std::clamp(roughness * roughness, 0.0f, 1.0f);
    return glm::mix(skyRadiance(l, dir), skyIrradiance(l, dir) / kPi, alpha);
}

glm::vec3 shadeSurface(const shader::SceneLighting& l, const CpuSurface& s, glm::vec3 toViewer, float sunVisibility) {
    const glm::vec3 n = s.normal;
    const glm::vec3 L = glm::vec3(l.sunDirection);
    const float NoL = std::clamp(glm::dot(n, L), 0.0f, 1.0f);
    const float NoV = std::max(glm::dot(n, toViewer), 1e-4f);
    const glm::vec3 H = glm::normalize(L + toViewer);
    const float NoH = std::clamp(glm::dot(n, H), 0.0f, 1.0f);
    const float VoH = std::clamp(glm::dot(toViewer, H), 0.0f, 1.0f);
    const float roughness = std::max(s.roughness, kMinRoughness);
    const float alpha = roughness * roughness;
    const float a2 = alpha * alpha;
    const float dd = (NoH * a2 - NoH) * NoH + 1.0f;
    const float D = a2 / (kPi * dd * dd);
    const float ggxV = NoL * std::sqrt(NoV * NoV * (1.0f - a2) + a2);
    const float ggxL = NoV * std::sqrt(NoL * NoL * (1.0f - a2) + a2);
    const float V = 0.5f / std::max(ggxV + ggxL, 1e-7f);
    const glm::vec3 f0 = glm::mix(glm::vec3(0.16f * s.reflectance * s.reflectance), s.albedo, s.metallic);
    const glm::vec3 F = f0 + (glm::vec3(1.0f) - f0) * std::pow(1.0f - VoH, 5.0f);
    const glm::vec3 diffuseColor = s.albedo * (1.0f - s.metallic);
    const glm::vec3 sun = (diffuseColor / kPi + F * (D * V)) * glm::vec3(l.sunIrradiance) * (NoL * sunVisibility);
    return sun + diffuseColor / kPi * skyIrradiance(l, n);
}

// ---------------------------------------------------------------------------
// CPU scene: every triangle in world space with its packed and true surface
// ---------------------------------------------------------------------------

struct CpuTriangle {
    glm::dvec3 v[3];
    shader::PackedPrimitive packed{};
    shader::SurfaceVertex truth[3]{};
    glm::mat3 normalMatrix{1.0f};  // object -> world for normals
    uint32_t instance = 0;
    bool doubleSided = false;  // its material's: otherwise rays pass through its back
    bool mirrored = false;     // its instance's transform has a negative determinant
};

struct CpuHit {
    bool hit = false;
    double t = 0.0;
    glm::vec2 barycentrics{0.0f};
    const CpuTriangle* triangle = nullptr;
};

class CpuScene {
public:
    explicit CpuScene(const scene::Scene& s) {
        for (uint32_t i = 0; i < s.instances.size(); ++i) {
            const scene::Instance& inst = s.instances[i];
            const scene::Mesh& mesh = s.meshes[inst.mesh];
            const scene::MeshLod& lod = mesh.lods[scene::reflectionLodIndex(mesh)];
            const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(inst.transform)));
            for (const scene::Geometry& g : lod.geometries) {
                const scene::UnwrappedGeometry u = scene::unwrapGeometry(s, g);
                for (uint32_t p = 0; p < u.primitives.size(); ++p) {
                    CpuTriangle t;
                    for (int k = 0; k < 3; ++k) {
                        t.v[k] = glm::dmat4(inst.transform) * glm::dvec4(glm::dvec3(u.positions[3 * p + k]), 1.0);
                        t.truth[k] = scene::surfaceAtVertex(s, g, g.indices[3 * p + k]);
                    }
                    t.packed = u.primitives[p];
                    t.normalMatrix = normalMatrix;
                    t.instance = i;
                    t.doubleSided = g.material < s.materials.size() && s.materials[g.material].doubleSided;
                    t.mirrored = glm::determinant(glm::mat3(inst.transform)) < 0.0f;
                    triangles_.push_back(t);
                }
            }
        }
    }

    // Möller and Trumbore, in double: the closest hit with t in (tMin, tMax).
    // As the reflection rays do, it passes through the backs of
    // single-sided triangles: det > 0 where the triangle winds
    // counter-clockwise seen from the origin (glTF's front), the other way
    // round under a mirroring transform. Shadow rays (cullBackFaces false)
    // stop at either side.
    CpuHit trace(glm::dvec3 origin, glm::dvec3 dir, double tMin, double tMax, bool cullBackFaces = true) const {
        CpuHit best;
        for (const CpuTriangle& tri : triangles_) {
            const glm::dvec3 e1 = tri.v[1] - tri.v[0], e2 = tri.v[2] - tri.v[0];
            const glm::dvec3 p = glm::cross(dir, e2);
            const double det = glm::dot(e1, p);
            if (std::abs(det) < 1e-300) continue;
            if (cullBackFaces && !tri.doubleSided && (det > 0.0) == tri.mirrored) continue;
            const glm::dvec3 s = origin - tri.v[0];
            const double u = glm::dot(s, p) / det;
            const glm::dvec3 q = glm::cross(s, e1);
            const double v = glm::dot(dir, q) / det;
            const double t = glm::dot(e2, q) / det;
            if (u < 0.0 || v < 0.0 || u + v > 1.0 || t <= tMin || t >= tMax) continue;
            if (!best.hit || t < best.t) {
                best = {true, t, glm::vec2(float(u), float(v)), &tri};
            }
        }
        return best;
    }

private:
    std::vector<CpuTriangle> triangles_;
};

// The surface a hit sees, from the packed primitive (what the GPU reads) or
// from the unquantised vertices (what the scene says).
CpuSurface hitSurface(const CpuHit& h, glm::vec3 position, glm::vec3 rayDir, bool packed) {
    shader::SurfaceVertex v{};
    if (packed) {
        v = shader::interpolateSurface(h.triangle->packed, h.barycentrics);
    } else {
        const float w[3] = {1.0f - h.barycentrics.x - h.barycentrics.y, h.barycentrics.x, h.barycentrics.y};
        for (int k = 0; k < 3; ++k) {
            const shader::SurfaceVertex& t = h.triangle->truth[k];
            v.albedo += w[k] * t.albedo;
            v.roughness += w[k] * t.roughness;
            v.metallic += w[k] * t.metallic;
            v.reflectance += w[k] * t.reflectance;
            v.normal += w[k] * glm::normalize(t.normal);
        }
    }
    CpuSurface s;
    s.position = position;
    glm::vec3 n = glm::normalize(h.triangle->normalMatrix * v.normal);
    if (glm::dot(n, rayDir) >= 0.0f) n = -n;
    s.normal = n;
    s.albedo = v.albedo;
    s.roughness = v.roughness;
    s.metallic = v.metallic;
    s.reflectance = v.reflectance;
    return s;
}

// World point of pixel `p`'s centre on the plane through `point` with
// normal `normal`: the reconstruction's view ray, in double from the
// unjittered matrices.
std::optional<glm::dvec3> pixelOnPlane(const scene::Camera& camera, glm::uvec2 p, glm::dvec3 point, glm::dvec3 normal) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(camera.projection) * glm::dmat4(camera.view));
    const glm::vec2 ndc = test::pixelNdc(p.x, p.y);
    const glm::dvec4 a = inv * glm::dvec4(ndc.x, ndc.y, 1.0, 1.0);
    const glm::dvec4 b = inv * glm::dvec4(ndc.x, ndc.y, 0.5, 1.0);
    const glm::dvec3 pa = glm::dvec3(a) / a.w, pb = glm::dvec3(b) / b.w;
    const glm::dvec3 d = pb - pa;
    const double along = glm::dot(d, normal);
    if (std::abs(along) < 1e-12) return std::nullopt;
    const double s = glm::dot(point - pa, normal) / along;
    if (s <= 0.0) return std::nullopt;
    return pa + s * d;
}

std::optional<glm::dvec3> pixelOnFloor(const scene::Camera& camera, glm::uvec2 p, double floorY) {
    return pixelOnPlane(camera, p, {0.0, floorY, 0.0}, {0.0, 1.0, 0.0});
}

// glint/rt_trace.glsl's rtOffsetOrigin for a ray leaving the G-buffer
// surface at `p` (normal `n`) seen from `camera`, in double.
glm::dvec3 offsetOrigin(glm::dvec3 p, glm::dvec3 n, glm::dvec3 camera, double rasterErrorPerDistance) {
    const auto maxAbs = [](glm::dvec3 v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
    const double magnitude = std::max({maxAbs(p), maxAbs(camera), double(shader::kRtOriginMinimum)});
    int exponent = 0;
    std::frexp(float(magnitude), &exponent);  // magnitude = m 2^exponent, m in [0.5, 1)
    const double ulp = std::ldexp(1.0, exponent - 24);
    const double perDistance = double(shader::kRtDistanceRelativeError) + rasterErrorPerDistance;
    return p + n * (shader::kRtOriginUlps * ulp + perDistance * glm::distance(p, camera));
}

// The world position the G-buffer's depth gives pixel `p` (the pass's
// reconstruction, in double): the CPU reference starts where the GPU's rays
// start, whatever the rasteriser's precision.
glm::dvec3 gbufferPoint(const scene::Camera& camera, glm::uvec2 p, float depth) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(camera.jitteredProjection) * glm::dmat4(camera.view));
    const glm::vec2 ndc = test::pixelNdc(p.x, p.y);
    const glm::dvec4 w = inv * glm::dvec4(ndc.x, ndc.y, double(depth), 1.0);
    return glm::dvec3(w) / w.w;
}

// ---------------------------------------------------------------------------
// One frame: G-buffer, BVH update, the RT pass, readback
// ---------------------------------------------------------------------------

struct RtFrame {
    std::vector<std::array<uint16_t, 4>> radianceBits;
    std::vector<glm::vec4> radiance;
    std::vector<float> hitDistance;
    std::vector<float> depth;

    bool untouched(size_t i) const {
        return radianceBits[i] == std::array<uint16_t, 4>{0, 0, 0, 0} && hitDistance[i] == 0.0f;
    }
};

struct RayList {
    std::vector<shader::PackedRay> entries;  // the first `count` are the list, the rest lies past its end
    uint32_t count = 0;
};

class Rig {
public:
    Rig(gpu::Context& ctx, scene::Scene s, const scene::Camera& camera)
        : ctx_(ctx), scene_(std::move(s)), camera_(camera), executor_(ctx), renderer_(ctx, scene_), bvh_(ctx, scene_) {
        const VkDeviceSize capacity = VkDeviceSize(kSize) * kSize * sizeof(shader::PackedRay);
        rays_ = gpu::Buffer(ctx, {capacity, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Upload,
                                  "rt_test.ray_list"});
        args_ = gpu::Buffer(ctx, {shader::kRayListArgsWords * sizeof(uint32_t),
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                                  gpu::MemoryUsage::Upload, "rt_test.ray_list_args"});
    }

    const scene::Scene& scene() const { return scene_; }
    const scene::Camera& camera() const { return camera_; }

    // Where the pass starts the ray of `pixel` (a surface with normal `n`),
    // from the depth this frame's G-buffer wrote.
    glm::dvec3 rayOrigin(const RtFrame& f, glm::uvec2 pixel, glm::dvec3 n) const {
        VkPhysicalDeviceProperties properties{};
        vkGetPhysicalDeviceProperties(ctx_.physicalDevice(), &properties);
        const float raster = passes::rtRasterErrorPerDistance(camera_.projection, kSize, kSize,
                                                              properties.limits.subPixelPrecisionBits);
        return offsetOrigin(gbufferPoint(camera_, pixel, f.depth[pixelIndex(pixel)]), n, glm::dvec3(camera_.position),
                            raster);
    }

    RtFrame trace(passes::RtTracePipelines& pipelines, const RayList& list, const shader::SceneLighting& lighting,
                  const passes::RtTraceSettings& settings, float maxDistance = scene::kDefaultBvhRadius) {
        REQUIRE(list.entries.size() <= size_t(kSize) * kSize);
        REQUIRE(list.count <= list.entries.size());
        std::memcpy(rays_.mapped(), list.entries.data(), list.entries.size() * sizeof(shader::PackedRay));
        const uint32_t groups = (list.count + shader::kRayListGroupSize - 1) / shader::kRayListGroupSize;
        const std::array<uint32_t, shader::kRayListArgsWords> argWords = {groups, 1, 1, list.count, 1, 1};
        std::memcpy(args_.mapped(), argWords.data(), sizeof(argWords));

        // The graph orders each frame after the previous one as if it ran
        // the same plan (glint/graph/barriers.cpp); a backend switch
        // changes the trace's shader stages, so a switch first waits for
        // the device (a wait the validation layer sees, unlike a timeline's).
        const passes::RtBackend backend =
            settings.backend == passes::RtBackend::Auto ? pipelines.backend() : settings.backend;
        if (backend != lastBackend_) {
            ctx_.waitIdle();
            lastBackend_ = backend;
        }
        rg::Executor& executor = executor_;
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        const scene::BvhPlan plan = planner_.plan(scene_, camera_.position, frame_++);
        const passes::BvhUpdateOutputs bvh = passes::addBvhUpdatePass(graph, bvh_, plan);
        bvh_.bind(resources, bvh);
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer_, {camera_});
        const rg::Buffer rays = graph.importBuffer("rt_test.ray_list", {{rays_.size()}, kHostWritten, kHostWritten});
        const rg::Buffer args =
            graph.importBuffer("rt_test.ray_list_args", {{args_.size()}, kHostWritten, kHostWritten});
        resources.bind(rays, rays_);
        resources.bind(args, args_);
        passes::RtTraceInputs inputs{gbuf, rays, args, bvh, lighting, camera_, frame_};
        inputs.maxDistance = maxDistance;
        const passes::RtTraceOutputs out = passes::addRtTracePass(graph, pipelines, inputs, settings);
        REQUIRE(out.width == kSize);
        REQUIRE(out.height == kSize);
        addReadback(graph, out, gbuf.depth, resources);
        const rg::Plan compiled = graph.compile(executor.compileOptions());
        const auto report = rg::verify(compiled);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor.run(compiled, resources);
        executor.waitIdle();

        RtFrame f;
        const size_t n = size_t(kSize) * kSize;
        f.radianceBits.resize(n);
        f.radiance.resize(n);
        f.hitDistance.resize(n);
        std::memcpy(f.radianceBits.data(), radianceReadback_.bytes().data(), n * 8);
        std::memcpy(f.hitDistance.data(), distanceReadback_.bytes().data(), n * 4);
        f.depth.resize(n);
        std::memcpy(f.depth.data(), depthReadback_.bytes().data(), n * 4);
        for (size_t i = 0; i < n; ++i) {
            for (int c = 0; c < 4; ++c) f.radiance[i][c] = glm::unpackHalf1x16(f.radianceBits[i][c]);
        }
        return f;
    }

private:
    // Copies both outputs and the G-buffer's depth into host-visible
    // buffers inside the graph, under the graph's own barriers.
    void addReadback(rg::Graph& graph, const passes::RtTraceOutputs& out, rg::Texture depth,
                     rg::FrameResources& resources) const {
        radianceReadback_.copy(graph, resources, out.radiance);
        distanceReadback_.copy(graph, resources, out.hitDistance);
        depthReadback_.copy(graph, resources, depth);
    }

    gpu::Context& ctx_;
    scene::Scene scene_;
    scene::Camera camera_;
    rg::Executor executor_;
    passes::RtBackend lastBackend_ = passes::RtBackend::Auto;
    passes::GBufferRenderer renderer_;
    passes::BvhManager bvh_;
    scene::BvhPlanner planner_;
    uint64_t frame_ = 0;
    gpu::Buffer rays_, args_;
    static constexpr VkDeviceSize kPixels = VkDeviceSize(kSize) * kSize;
    rg::HostReadback radianceReadback_{ctx_, kPixels * 8, "rt_test.readback.radiance"};
    rg::HostReadback distanceReadback_{ctx_, kPixels * 4, "rt_test.readback.hit_distance"};
    rg::HostReadback depthReadback_{ctx_, kPixels * 4, "rt_test.readback.depth"};
};

std::vector<passes::RtBackend> availableBackends(const gpu::Context& ctx) {
    std::vector<passes::RtBackend> out;
    for (const passes::RtBackend b : {passes::RtBackend::RayQuery, passes::RtBackend::Pipeline}) {
        if (passes::RtTracePipelines::supported(ctx, b)) out.push_back(b);
    }
    return out;
}

passes::RtTraceSettings settingsFor(passes::RtBackend backend) {
    passes::RtTraceSettings s;
    s.backend = backend;
    return s;
}

// ---------------------------------------------------------------------------
// The scene of the hit tests
// ---------------------------------------------------------------------------

// A floor at y = -1 (the rays' origins), a quad floating at z ~ -5 (4 x 2
// after its instance's scale, turned 20 degrees about y) with a colour and
// a tilted normal per vertex, and a roof at y = 3 over its left part that
// the sun (from up, right, behind the camera) casts onto it.
constexpr float kFloorY = -1.0f;
constexpr float kFloorRoughness = 0.2f;  // 51/255 in the G-buffer's unorm: exact
const glm::vec3 kSun = glm::normalize(glm::vec3(0.4f, 1.0f, 0.6f));

scene::Scene hitScene() {
    scene::Scene s;
    s.name = "rt-trace-test";
    scene::Material floor;
    floor.baseColorFactor = {0.5f, 0.5f, 0.5f, 1.0f};
    floor.roughnessFactor = kFloorRoughness;
    floor.metallicFactor = 1.0f;
    scene::Material target;
    target.roughnessFactor = 0.4f;
    target.metallicFactor = 0.2f;
    target.reflectance = 0.6f;
    // Double-sided: some rays reach it from behind (the quad is turned),
    // where a single-sided quad lets them through.
    target.doubleSided = true;
    scene::Material roof;
    roof.baseColorFactor = {0.3f, 0.3f, 0.3f, 1.0f};
    roof.roughnessFactor = 0.9f;
    roof.metallicFactor = 0.0f;
    s.materials = {floor, target, roof};

    scene::Mesh floorMesh;
    floorMesh.name = "floor";
    floorMesh.lods.push_back({{square({0, kFloorY, -20}, {1, 0, 0}, {0, 0, -1}, 30.0f, 0)}});
    scene::Mesh targetMesh;
    targetMesh.name = "target";
    scene::Geometry quad = square({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1.0f, 1);
    quad.colors = {
        {0.9f, 0.2f, 0.1f, 1.0f}, {0.1f, 0.8f, 0.2f, 1.0f}, {0.2f, 0.3f, 0.9f, 1.0f}, {0.9f, 0.9f, 0.3f, 1.0f}};
    quad.normals = {glm::normalize(glm::vec3(-0.3f, -0.2f, 1.0f)), glm::normalize(glm::vec3(0.4f, -0.1f, 1.0f)),
                    glm::normalize(glm::vec3(0.2f, 0.5f, 1.0f)), glm::normalize(glm::vec3(-0.2f, 0.3f, 1.0f))};
    targetMesh.lods.push_back({{quad}});
    scene::Mesh roofMesh;
    roofMesh.name = "roof";
    // Facing down, over x in [-5, 0.5], z in [-8, -2].
    scene::Geometry roofQuad = square({-2.25f, 3.0f, -5.0f}, {0, 0, 1}, {1, 0, 0}, 1.0f, 2);
    for (glm::vec3& p : roofQuad.positions) {
        p = glm::vec3(-2.25f + (p.x + 2.25f) * 2.75f, p.y, -5.0f + (p.z + 5.0f) * 3.0f);
    }
    roofMesh.lods.push_back({{roofQuad}});
    s.meshes = {floorMesh, targetMesh, roofMesh};

    scene::Instance floorInstance;
    floorInstance.name = "floor";
    floorInstance.mesh = 0;
    scene::Instance targetInstance;
    targetInstance.name = "target";
    targetInstance.mesh = 1;
    targetInstance.transform = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.5f, -5.0f)) *
                               glm::rotate(glm::mat4(1.0f), glm::radians(20.0f), glm::vec3(0, 1, 0)) *
                               glm::scale(glm::mat4(1.0f), glm::vec3(2.0f, 1.0f, 1.0f));
    scene::Instance roofInstance;
    roofInstance.name = "roof";
    roofInstance.mesh = 2;
    s.instances = {floorInstance, targetInstance, roofInstance};
    scene::prepareScene(s);
    return s;
}

shader::SceneLighting sunAndSky() {
    shader::SceneLighting l{};
    l.sunDirection = glm::vec4(kSun, 0.0f);
    l.sunIrradiance = {3.0f, 2.8f, 2.5f, 0.0f};
    l.skyZenith = {0.2f, 0.35f, 0.65f, 0.0f};
    l.skyHorizon = {0.7f, 0.75f, 0.8f, 0.0f};
    l.skyGround = {0.2f, 0.18f, 0.16f, 0.0f};
    return l;
}

// No sun, a uniform white sky: a hit's radiance is its diffuse colour,
// albedo * (1 - metallic), and a miss's is 1.
shader::SceneLighting whiteSky() {
    shader::SceneLighting l{};
    l.sunDirection = glm::vec4(kSun, 0.0f);
    l.skyZenith = l.skyHorizon = l.skyGround = {1.0f, 1.0f, 1.0f, 0.0f};
    return l;
}

// No sun, sky only from above (zenith and horizon white, ground black): a
// hit's radiance is its diffuse colour times (1 + n.y) / 2.
shader::SceneLighting upperSky() {
    shader::SceneLighting l = whiteSky();
    l.skyGround = {0.0f, 0.0f, 0.0f, 0.0f};
    return l;
}

// The target quad's world point at (s, t) in [0, 1]^2 of its object square.
glm::dvec3 targetPoint(const scene::Scene& s, double a, double b) {
    const glm::dvec4 object(-1.0 + 2.0 * a, -1.0 + 2.0 * b, 0.0, 1.0);
    return glm::dvec3(glm::dmat4(s.instances[1].transform) * object);
}

struct ListedRay {
    glm::uvec2 pixel;
    glm::dvec3 origin;    // the analytic surface point the ray is aimed from
    glm::vec3 direction;  // as the GPU unpacks it
    bool aimedAtTarget = false;
};

// Floor pixels in front of the target (every `step`-th), each with a ray
// aimed at a random point well inside the target quad, or, every fourth,
// up and back into the empty sky.
std::vector<ListedRay> hitTestRays(const Rig& rig, uint32_t step) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> inside(0.1, 0.9);
    std::uniform_real_distribution<float> side(-0.5f, 0.5f);
    std::vector<ListedRay> rays;
    uint32_t n = 0;
    for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const auto origin = pixelOnFloor(rig.camera(), {x, y}, kFloorY);
            if (!origin || origin->z > -1.5 || origin->z < -4.0 || (n++ % step) != 0) continue;
            ListedRay r;
            r.pixel = {x, y};
            r.origin = *origin;
            glm::vec3 dir;
            if (rays.size() % 4 == 3) {
                dir = glm::normalize(glm::vec3(side(rng), 1.0f, 1.5f));
            } else {
                dir = glm::vec3(glm::normalize(targetPoint(rig.scene(), inside(rng), inside(rng)) - *origin));
                r.aimedAtTarget = true;
            }
            r.direction = shader::unpackRayDirection(shader::packRayDirection(dir));
            rays.push_back(r);
        }
    }
    return rays;
}

RayList toList(const std::vector<ListedRay>& rays) {
    RayList list;
    for (const ListedRay& r : rays) {
        list.entries.push_back({shader::packRayPixel(r.pixel, false), shader::packRayDirection(r.direction)});
    }
    list.count = uint32_t(list.entries.size());
    return list;
}

// The length of a ray leaving the floor (passes/rt_trace.h's rule).
float floorRayLength(const passes::RtTraceSettings& s, float maxDistance = scene::kDefaultBvhRadius) {
    const float roughness = 51.0f / 255.0f;
    const float k = std::clamp(roughness / s.shortRangeRoughness, 0.0f, 1.0f);
    return maxDistance * glm::mix(1.0f, s.shortRangeFraction, k);
}

bool near(glm::vec3 got, glm::vec3 expected, float relative, float absolute) {
    for (int c = 0; c < 3; ++c) {
        if (!(std::abs(got[c] - expected[c]) <= relative * std::abs(expected[c]) + absolute)) return false;
    }
    return true;
}

std::string text(glm::vec3 v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

} // namespace

TEST_CASE("RT hits interpolate the packed triangle and light it as the CPU does; misses give the environment") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    Rig rig(gpu.ctx(), hitScene(), test::testCamera());
    const CpuScene cpu(rig.scene());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    REQUIRE(rays.size() > 60);
    const RayList list = toList(rays);

    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        CHECK((pipelines.backend() == backend));
        const passes::RtTraceSettings settings = settingsFor(backend);
        const float tMax = floorRayLength(settings);
        const shader::SceneLighting lit = sunAndSky();
        const shader::SceneLighting white = whiteSky();
        const RtFrame litFrame = rig.trace(pipelines, list, lit, settings);
        const RtFrame whiteFrame = rig.trace(pipelines, list, white, settings);
        const RtFrame upperFrame = rig.trace(pipelines, list, upperSky(), settings);

        uint32_t hits = 0, misses = 0, shadowed = 0, sunlit = 0;
        float worstAlbedo = 0.0f, worstNormalY = 0.0f;
        for (const ListedRay& r : rays) {
            CAPTURE(r.pixel.x);
            CAPTURE(r.pixel.y);
            const size_t i = pixelIndex(r.pixel);
            const glm::vec4 got = litFrame.radiance[i];
            REQUIRE(got.a == 1.0f);
            REQUIRE(whiteFrame.radiance[i].a == 1.0f);
            const glm::dvec3 origin = rig.rayOrigin(litFrame, r.pixel, {0, 1, 0});
            const CpuHit h = cpu.trace(origin, glm::dvec3(r.direction), 0.0, tMax);
            REQUIRE(h.hit == r.aimedAtTarget);
            if (!h.hit) {
                ++misses;
                const glm::vec3 env = environmentRadiance(lit, r.direction, 51.0f / 255.0f);
                CHECK_MESSAGE(near(glm::vec3(got), env, 2e-3f, 1e-4f), text(glm::vec3(got)) << " vs " << text(env));
                CHECK(litFrame.hitDistance[i] == shader::kMissHitDistance);
                CHECK(near(glm::vec3(whiteFrame.radiance[i]), glm::vec3(1.0f), 0.0f, 1e-3f));
                continue;
            }
            ++hits;
            REQUIRE(h.triangle->instance == 1u);
            CHECK(litFrame.hitDistance[i] == doctest::Approx(h.t).epsilon(1e-4));
            const glm::vec3 position = glm::vec3(origin + h.t * glm::dvec3(r.direction));

            // White sky: the radiance is the interpolated diffuse colour.
            const CpuSurface packed = hitSurface(h, position, r.direction, true);
            const CpuSurface truth = hitSurface(h, position, r.direction, false);
            const glm::vec3 diffuse = glm::vec3(whiteFrame.radiance[i]);
            CHECK_MESSAGE(near(diffuse, packed.albedo * (1.0f - packed.metallic), 2e-3f, 2e-4f),
                          text(diffuse) << " vs packed " << text(packed.albedo * (1.0f - packed.metallic)));
            // Against the unquantised surface: half an 8-bit sRGB step is at
            // most ~0.005 in linear, and metallic's step 0.002.
            const glm::vec3 trueDiffuse = truth.albedo * (1.0f - truth.metallic);
            worstAlbedo = std::max(worstAlbedo, glm::length(diffuse - trueDiffuse));
            CHECK_MESSAGE(near(diffuse, trueDiffuse, 0.0f, 0.006f), text(diffuse) << " vs true " << text(trueDiffuse));
            // Sky from above only: the radiance is that colour times
            // (1 + n.y) / 2, which gives the world normal's y, through the
            // instance's rotation and non-uniform scale: within the
            // octahedral normals' ~1 degree of the unquantised one.
            const glm::vec3 upper = glm::vec3(upperFrame.radiance[i]);
            const float normalY = 2.0f * (upper.x + upper.y + upper.z) / (diffuse.x + diffuse.y + diffuse.z) - 1.0f;
            CHECK_MESSAGE(std::abs(normalY - packed.normal.y) < 2e-3f, normalY << " vs packed " << packed.normal.y);
            // A ray nearly tangent to the shading normal may see the front
            // of one normal and the back of the other (each is turned
            // towards the ray): the unquantised comparison leaves it out.
            if (std::abs(glm::dot(truth.normal, r.direction)) > 0.05f) {
                worstNormalY = std::max(worstNormalY, std::abs(normalY - truth.normal.y));
                CHECK_MESSAGE(std::abs(normalY - truth.normal.y) < 0.02f, normalY << " vs true " << truth.normal.y);
            }

            // Sun and sky, with an analytic shadow test. Hits within a
            // hand's width of the roof's shadow edge are left out.
            const glm::dvec3* v = h.triangle->v;
            const glm::dvec3 e1 = glm::normalize(v[1] - v[0]), e2 = glm::normalize(v[2] - v[0]);
            const glm::dvec3 face = glm::normalize(glm::cross(e1, e2));
            const glm::dvec3 lift = face * (glm::dot(face, glm::dvec3(kSun)) > 0.0 ? 1e-4 : -1e-4);
            bool anyOccluded = false, allOccluded = true;
            for (const glm::dvec3 offset : {glm::dvec3(0), 0.05 * e1, -0.05 * e1, 0.05 * e2, -0.05 * e2}) {
                const bool occluded = cpu.trace(glm::dvec3(position) + offset + lift, glm::dvec3(kSun), 0.0, 200.0, false).hit;
                anyOccluded = anyOccluded || occluded;
                allOccluded = allOccluded && occluded;
            }
            if (anyOccluded != allOccluded) continue;
            const float visibility = allOccluded ? 0.0f : 1.0f;
            (allOccluded ? shadowed : sunlit)++;
            const glm::vec3 expected = shadeSurface(lit, packed, -r.direction, visibility);
            CHECK_MESSAGE(near(glm::vec3(got), expected, 3e-3f, 3e-4f),
                          text(glm::vec3(got)) << " vs " << text(expected) << " visibility " << visibility);
        }
        MESSAGE(name << ": " << hits << " hits (" << sunlit << " sunlit, " << shadowed << " shadowed), " << misses
                     << " misses; worst error against the unquantised surface: diffuse colour " << worstAlbedo
                     << ", normal y " << worstNormalY);
        CHECK(hits > 40);
        CHECK(misses > 10);
        CHECK(sunlit > 10);
        CHECK(shadowed > 10);
    }
}

TEST_CASE("without shadows the roof's shadow is gone; rougher surfaces trace shorter rays") {
    test::GpuTest gpu;
    Rig rig(gpu.ctx(), hitScene(), test::testCamera());
    const CpuScene cpu(rig.scene());
    passes::RtTracePipelines pipelines(gpu.ctx());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    const RayList list = toList(rays);
    passes::RtTraceSettings settings;
    settings.shadows = false;
    const shader::SceneLighting lit = sunAndSky();
    const RtFrame f = rig.trace(pipelines, list, lit, settings);
    uint32_t checked = 0, underRoof = 0;
    for (const ListedRay& r : rays) {
        if (!r.aimedAtTarget) continue;
        const glm::dvec3 origin = rig.rayOrigin(f, r.pixel, {0, 1, 0});
        const CpuHit h = cpu.trace(origin, glm::dvec3(r.direction), 0.0, 100.0);
        REQUIRE(h.hit);
        const glm::vec3 position = glm::vec3(origin + h.t * glm::dvec3(r.direction));
        const glm::vec3 expected = shadeSurface(lit, hitSurface(h, position, r.direction, true), -r.direction, 1.0f);
        CHECK(near(glm::vec3(f.radiance[pixelIndex(r.pixel)]), expected, 3e-3f, 3e-4f));
        ++checked;
        if (cpu.trace(glm::dvec3(position), glm::dvec3(kSun), 1e-3, 200.0, false).hit) ++underRoof;
    }
    CHECK(checked > 40);
    CHECK(underRoof > 10);  // hits the roof shadows when shadows are on

    // Rays from the floor (roughness 0.2) with maxDistance 12 shrinking to a
    // quarter by roughness 0.1: 3 units long. The target lies 1-5 units
    // away: nearer hits stay, farther ones become misses.
    settings.shortRangeFraction = 0.25f;
    settings.shortRangeRoughness = 0.1f;
    const float length = floorRayLength(settings, 12.0f);
    REQUIRE(length == doctest::Approx(3.0f));
    const RtFrame shortRays = rig.trace(pipelines, list, lit, settings, 12.0f);
    uint32_t nearHits = 0, cutOff = 0;
    for (const ListedRay& r : rays) {
        if (!r.aimedAtTarget) continue;
        const CpuHit h = cpu.trace(rig.rayOrigin(shortRays, r.pixel, {0, 1, 0}), glm::dvec3(r.direction), 0.0, 100.0);
        if (std::abs(h.t - length) < 0.01) continue;
        const size_t i = pixelIndex(r.pixel);
        CHECK(shortRays.radiance[i].a == 1.0f);
        if (h.t < length) {
            ++nearHits;
            CHECK(shortRays.hitDistance[i] == doctest::Approx(h.t).epsilon(1e-3));
        } else {
            ++cutOff;
            CHECK(shortRays.hitDistance[i] == shader::kMissHitDistance);
        }
    }
    CHECK(nearHits > 5);
    CHECK(cutOff > 5);
}

TEST_CASE("ray query and the ray tracing pipeline write bit-identical radiance and hit distances") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    if (!(passes::RtTracePipelines::supported(ctx, passes::RtBackend::RayQuery) &&
          passes::RtTracePipelines::supported(ctx, passes::RtBackend::Pipeline))) {
        MESSAGE("device '" << ctx.caps().deviceName << "' has one backend; nothing to compare");
        return;
    }
    Rig rig(ctx, hitScene(), test::testCamera());
    // One ray per pixel, random over the upper hemisphere with a bias
    // towards the target: floor, target, roof and sky pixels, hits, misses,
    // shadowed and sunlit hits.
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    RayList list;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const float across = u(rng), up = 0.2f + std::abs(u(rng)), back = 0.3f - 1.2f * std::abs(u(rng));
            const glm::vec3 d = glm::normalize(glm::vec3(across, up, back));
            list.entries.push_back({shader::packRayPixel({x, y}, false), shader::packRayDirection(d)});
        }
    }
    list.count = uint32_t(list.entries.size());
    passes::RtTracePipelines pipelines(ctx, passes::RtBackend::RayQuery);
    const RtFrame query = rig.trace(pipelines, list, sunAndSky(), settingsFor(passes::RtBackend::RayQuery));
    const RtFrame pipeline = rig.trace(pipelines, list, sunAndSky(), settingsFor(passes::RtBackend::Pipeline));
    uint32_t hits = 0, misses = 0, differing = 0;
    for (size_t i = 0; i < query.hitDistance.size(); ++i) {
        if (query.radianceBits[i] != pipeline.radianceBits[i] ||
            std::memcmp(&query.hitDistance[i], &pipeline.hitDistance[i], sizeof(float)) != 0) {
            if (differing++ < 5) {
                MESSAGE("pixel " << i << ": " << text(glm::vec3(query.radiance[i])) << " at " << query.hitDistance[i]
                                 << " vs " << text(glm::vec3(pipeline.radiance[i])) << " at "
                                 << pipeline.hitDistance[i]);
            }
        }
        if (query.radiance[i].a == 1.0f) (query.hitDistance[i] == shader::kMissHitDistance ? misses : hits)++;
    }
    MESSAGE(hits << " hits and " << misses << " misses compared");
    CHECK(differing == 0);
    // 358 measured: the roof is single-sided and faces up, so the rays
    // from below pass through it (833 before back faces were culled).
    CHECK(hits > 300);
    CHECK(misses > 500);
}

namespace {

// A plane through (centre, 0, centre), tilted (its normal leans 15 degrees
// from +y, so errors in the large x and z coordinates move points off it),
// its vertices at those coordinates (no instance transform to subtract
// them), seen from 3 units above; a wall 30 units ahead, facing the camera.
// Grazing rays leave the plane away from the wall and must miss; rays
// aimed at the wall hit it sunlit (their shadow rays leave it too).
void checkNoSelfIntersection(test::GpuTest& gpu, double centre, bool rawMustSelfIntersect, bool jitter = false) {
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    const double kFar = centre;
    const float kWallZ = float(kFar) - 30.0f;
    const glm::vec3 planeU = glm::normalize(glm::vec3(1.0f, 0.25f, 0.0f));
    const glm::vec3 planeV = glm::normalize(glm::vec3(0.0f, -0.15f, -1.0f));
    const glm::dvec3 planeNormal = glm::normalize(glm::cross(glm::dvec3(planeU), glm::dvec3(planeV)));
    const glm::dvec3 planePoint(kFar, 0.0, kFar);
    scene::Scene s;
    s.name = "far-plane";
    scene::Material plane;
    plane.roughnessFactor = 0.0f;
    plane.metallicFactor = 1.0f;
    // Double-sided: reflection rays cull the backs of single-sided
    // triangles, which would hide the raw origins' self hits this test
    // counts (a double-sided surface has them).
    plane.doubleSided = true;
    scene::Material wall;
    wall.baseColorFactor = {0.7f, 0.7f, 0.7f, 1.0f};
    wall.roughnessFactor = 0.5f;
    wall.metallicFactor = 0.0f;
    s.materials = {plane, wall};
    scene::Mesh mesh;
    mesh.name = "far-plane-and-wall";
    mesh.lods.push_back({{square(glm::vec3(planePoint), planeU, planeV, 80.0f, 0),
                          square({float(kFar), 10.0f, kWallZ}, {1, 0, 0}, {0, 1, 0}, 25.0f, 1)}});
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "far-plane-and-wall";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    scene::Camera camera = test::testCamera({float(kFar), 3.0f, float(kFar)});
    if (jitter) {
        // Frame 1's sub-pixel jitter (Halton (2, 3) index 2: (0, -1/6)
        // pixels): the G-buffer's depth belongs to the jittered samples.
        camera.jitter = true;
        const glm::vec3 eye(float(kFar), 3.0f, float(kFar));
        camera.reset({eye, eye + glm::vec3(0, 0, -1), {0, 1, 0}}, 1);
        REQUIRE(glm::length(camera.jitterPixels) > 0.1f);
    }
    const CpuScene cpu(s);

    // Plane pixels: grazing rays away from the wall (cosine with the normal
    // 1e-3 to 0.05: ray generation's kMinRayCosine and up), and every
    // fifth one aimed at the wall.
    const glm::dvec3 tangent = glm::normalize(glm::cross(planeNormal, glm::dvec3(0, 0, 1)));
    const glm::dvec3 bitangent = glm::cross(planeNormal, tangent);
    REQUIRE(bitangent.z < -0.9);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<ListedRay> rays;
    for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            // Nearer than the wall and within the plane: what the G-buffer
            // shows there.
            const auto origin = pixelOnPlane(camera, {x, y}, planePoint, planeNormal);
            if (!origin || origin->z < kWallZ + 5.0 || std::abs(origin->x - kFar) > 20.0) continue;
            ListedRay r;
            r.pixel = {x, y};
            r.origin = *origin;
            glm::dvec3 dir;
            if (rays.size() % 5 == 4) {
                const glm::dvec3 aim(kFar + 20.0 * (unit(rng) - 0.5), 5.0 + 10.0 * unit(rng), kWallZ);
                dir = glm::normalize(aim - *origin);
                r.aimedAtTarget = true;
            } else {
                const double cosine = 1e-3 + 0.049 * unit(rng) * unit(rng);
                // The bitangent points towards the wall (-z): sin(phi) < 0 leads away.
                const double phi = 3.14159265358979 * (1.1 + 0.8 * unit(rng));
                const double sine = std::sqrt(1.0 - cosine * cosine);
                dir = cosine * planeNormal + sine * (std::cos(phi) * tangent + std::sin(phi) * bitangent);
            }
            r.direction = shader::unpackRayDirection(shader::packRayDirection(glm::vec3(dir)));
            rays.push_back(r);
        }
    }
    REQUIRE(rays.size() > 1000);
    const RayList list = toList(rays);
    shader::SceneLighting lighting = sunAndSky();
    const glm::vec3 sun = glm::normalize(glm::vec3(0.2f, 0.6f, 1.0f));  // behind the camera: the wall is sunlit
    lighting.sunDirection = glm::vec4(sun, 0.0f);

    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        Rig rig(gpu.ctx(), s, camera);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        passes::RtTraceSettings settings = settingsFor(backend);
        const auto selfHitsAt = [&](float scale) {
            settings.originOffsetScale = scale;
            const RtFrame f = rig.trace(pipelines, list, lighting, settings);
            uint32_t n = 0;
            for (const ListedRay& r : rays) {
                if (!r.aimedAtTarget && f.hitDistance[pixelIndex(r.pixel)] != shader::kMissHitDistance) ++n;
            }
            return n;
        };
        // The measurement behind kRtOriginUlps (glint/rt_trace_shared.h):
        // self hits as the offset shrinks.
        for (const float scale : {1.0f / 4.0f, 1.0f / 16.0f, 1.0f / 64.0f}) {
            MESSAGE(name << ": origin offset x " << scale << ": " << selfHitsAt(scale) << " self hits");
        }
        settings.originOffsetScale = 1.0f;
        const RtFrame f = rig.trace(pipelines, list, lighting, settings);
        uint32_t grazing = 0, selfHits = 0, wallHits = 0;
        for (const ListedRay& r : rays) {
            CAPTURE(r.pixel.x);
            CAPTURE(r.pixel.y);
            const size_t i = pixelIndex(r.pixel);
            REQUIRE(f.radiance[i].a == 1.0f);
            if (!r.aimedAtTarget) {
                ++grazing;
                if (f.hitDistance[i] != shader::kMissHitDistance) ++selfHits;
                continue;
            }
            const glm::dvec3 origin = rig.rayOrigin(f, r.pixel, planeNormal);
            const CpuHit h = cpu.trace(origin, glm::dvec3(r.direction), 0.0, 100.0);
            REQUIRE(h.hit);
            ++wallHits;
            // The GPU reconstructs and traces in float: a few ULPs of the
            // coordinates (1e-3 at 1e4) beside the CPU's double.
            CHECK(std::abs(f.hitDistance[i] - h.t) <= 1e-4 * h.t + 5e-7 * centre);
            const glm::vec3 position = glm::vec3(origin + h.t * glm::dvec3(r.direction));
            const CpuSurface surface = hitSurface(h, position, r.direction, true);
            const glm::vec3 lit = shadeSurface(lighting, surface, -r.direction, 1.0f);
            const glm::vec3 dark = shadeSurface(lighting, surface, -r.direction, 0.0f);
            REQUIRE(glm::length(lit - dark) > 0.2f * glm::length(lit));
            CHECK_MESSAGE(near(glm::vec3(f.radiance[i]), lit, 0.01f, 1e-3f),
                          text(glm::vec3(f.radiance[i])) << " vs sunlit " << text(lit) << ", shadowed " << text(dark));
        }
        MESSAGE(name << ": " << grazing << " grazing rays, " << selfHits << " hit their own plane; " << wallHits
                     << " wall hits");
        CHECK(selfHits == 0);
        CHECK(wallHits > 200);

        // Without the offset the same rays hit their own plane (at 1e4 on
        // lavapipe and NVIDIA; near the origin NVIDIA's traversal
        // happens to spare them): the test sees what the offset prevents.
        const uint32_t rawSelfHits = selfHitsAt(0.0f);
        MESSAGE(name << ": without the origin offset " << rawSelfHits << " of " << grazing
                     << " grazing rays hit their own plane");
        if (rawMustSelfIntersect) {
            CHECK(rawSelfHits > grazing / 20);
        }
    }
}

} // namespace

TEST_CASE("rays leaving a plane 10^4 units from the origin do not hit it; its hits are lit, not self-shadowed") {
    test::GpuTest gpu;
    checkNoSelfIntersection(gpu, 1.0e4, true);
}

TEST_CASE("rays leaving a plane at the origin do not hit it; its hits are lit, not self-shadowed") {
    test::GpuTest gpu;
    checkNoSelfIntersection(gpu, 0.0, false);
}

TEST_CASE("with camera jitter the origins still leave the plane: they come from the jittered samples") {
    test::GpuTest gpu;
    checkNoSelfIntersection(gpu, 0.0, false, true);
}

TEST_CASE("only listed rays are traced; entries past the count, without a surface or a ray trace nothing") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    Rig rig(gpu.ctx(), hitScene(), test::testCamera());
    const std::vector<ListedRay> rays = hitTestRays(rig, 7);
    REQUIRE(rays.size() > 20);
    RayList list = toList(rays);
    // Entries that name nothing to trace: no ray, a sky pixel (top right:
    // over the floor's far end and beside the roof), a pixel outside the image.
    list.entries.push_back({shader::kNoRay, 0});
    list.entries.push_back({shader::packRayPixel({60, 0}, false), shader::packRayDirection({0, 1, 0})});
    list.entries.push_back({shader::packRayPixel({kSize + 3, 2}, false), shader::packRayDirection({0, 1, 0})});
    // A follower's entry names its quad leader: the leader's pixel is written.
    list.entries[0].pixelFlags = shader::packRayPixel(rays[0].pixel, true);
    list.count = uint32_t(list.entries.size());
    // Past the count: valid rays for every other floor pixel, which must
    // stay untouched.
    std::vector<bool> listed(size_t(kSize) * kSize, false);
    for (const ListedRay& r : rays) listed[pixelIndex(r.pixel)] = true;
    for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            if (!listed[pixelIndex({x, y})]) {
                list.entries.push_back({shader::packRayPixel({x, y}, false), shader::packRayDirection({0, 1, 0})});
            }
        }
    }

    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        // Cleared first, so that what the trace leaves alone reads zero (the
        // frame itself clears nothing: its readers read listed pixels only).
        passes::RtTraceSettings settings = settingsFor(backend);
        settings.clearUntraced = true;
        const RtFrame f = rig.trace(pipelines, list, sunAndSky(), settings);
        uint32_t traced = 0;
        for (size_t i = 0; i < listed.size(); ++i) {
            CAPTURE(i);
            if (listed[i]) {
                ++traced;
                CHECK(f.radiance[i].a == 1.0f);
                CHECK(f.hitDistance[i] > 0.0f);
            } else {
                CHECK(f.untouched(i));
            }
        }
        CHECK(traced == rays.size());

        // An empty list (args {0, 1, 1, 0, 1, 1}) traces nothing, whatever
        // the list holds.
        RayList empty = list;
        empty.count = 0;
        const RtFrame none = rig.trace(pipelines, empty, sunAndSky(), settings);
        size_t touched = 0;
        for (size_t i = 0; i < listed.size(); ++i) touched += none.untouched(i) ? 0 : 1;
        CHECK(touched == 0);
    }
}

TEST_CASE("an unsupported backend is refused with a clear error") {
    gpu::ContextOptions options;
    options.disableRayQuery = true;
    test::GpuTest gpu(options);
    CHECK_FALSE(passes::RtTracePipelines::supported(gpu.ctx(), passes::RtBackend::RayQuery));
    CHECK_THROWS_WITH_AS(passes::RtTracePipelines(gpu.ctx(), passes::RtBackend::RayQuery),
                         doctest::Contains("has no ray query"), gpu::GpuError);
    // Auto falls back to the ray tracing pipeline (NVIDIA's case).
    passes::RtTracePipelines pipelines(gpu.ctx());
    CHECK((pipelines.backend() == passes::RtBackend::Pipeline));
}

TEST_CASE("an RT hit on an emissive triangle returns its emission: factor x strength x the texture's mean, scaled") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    // The target's left half emits through a 2x2 sRGB texture (the packed
    // primitives cannot carry it, so the hit adds the texture's mean,
    // linear); its right half, a second geometry of the same mesh, is black
    // and emits nothing: the table is read per (instance, geometry).
    scene::Scene s = hitScene();
    scene::Material black;
    black.baseColorFactor = {0.0f, 0.0f, 0.0f, 1.0f};
    s.materials.push_back(black);
    s.meshes[1].lods[0].geometries = {square({-0.5f, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}, 1.0f, 1),
                                      square({0.5f, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}, 1.0f, 3)};
    scene::prepareScene(s);
    scene::Texture texture;
    texture.name = "emissive";
    texture.width = texture.height = 2;
    texture.rgba8 = {255, 0, 0, 255, 0, 128, 0, 255, 0, 0, 64, 255, 200, 200, 200, 255};
    s.textures.push_back(texture);
    scene::Material& target = s.materials[1];
    target.baseColorFactor = {0.0f, 0.0f, 0.0f, 1.0f};
    target.emissiveFactor = {1.0f, 0.5f, 0.25f};
    target.emissiveStrength = 6.0f;
    target.emissiveTexture.texture = 0;
    glm::vec3 mean(0.0f);
    for (size_t t = 0; t < 4; ++t) {
        for (int c = 0; c < 3; ++c) {
            mean[c] += shader::srgbToLinear(float(texture.rgba8[t * 4 + size_t(c)]) / 255.0f) / 4.0f;
        }
    }
    constexpr float kEmissiveScale = 0.75f;
    const glm::vec3 expected = target.emissiveFactor * target.emissiveStrength * mean * kEmissiveScale;
    CHECK(near(scene::meanEmission(s, target), expected / kEmissiveScale, 1e-5f, 1e-6f));

    Rig rig(gpu.ctx(), s, test::testCamera());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    const RayList list = toList(rays);
    // No sun, a black sky: a hit's radiance is its emission alone, a miss's zero.
    shader::SceneLighting dark{};
    dark.sunDirection = glm::vec4(kSun, kEmissiveScale);
    std::vector<RtFrame> frames;
    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        frames.push_back(rig.trace(pipelines, list, dark, settingsFor(backend)));
        const RtFrame& f = frames.back();
        const glm::dmat4 worldToTarget = glm::inverse(glm::dmat4(rig.scene().instances[1].transform));
        uint32_t emissiveHits = 0, darkHits = 0;
        for (const ListedRay& r : rays) {
            const size_t i = pixelIndex(r.pixel);
            const glm::vec3 got(f.radiance[i]);
            if (!r.aimedAtTarget) {
                CHECK(got == glm::vec3(0.0f));
                continue;
            }
            // Which half the ray met, from its hit distance (the origin is
            // within millimetres of the analytic one).
            const glm::dvec3 hit = r.origin + double(f.hitDistance[i]) * glm::dvec3(r.direction);
            const double x = (worldToTarget * glm::dvec4(hit, 1.0)).x;
            if (std::abs(x) < 0.05) continue;
            const glm::vec3 want = x < 0.0 ? expected : glm::vec3(0.0f);
            INFO("pixel " << r.pixel.x << ", " << r.pixel.y << " (x " << x << "): " << text(got) << " vs " << text(want));
            // Half-float output: 2^-11 relative rounding.
            CHECK(near(got, want, 1.0f / 1024.0f, 1e-6f));
            ++(x < 0.0 ? emissiveHits : darkHits);
        }
        CHECK(emissiveHits > 20);
        CHECK(darkHits > 20);
    }
    // Both backends agree bit for bit on the traced pixels (the others are
    // never written: whatever the memory held).
    if (frames.size() == 2) {
        for (const ListedRay& r : rays) {
            const size_t i = pixelIndex(r.pixel);
            CHECK(frames[0].radianceBits[i] == frames[1].radianceBits[i]);
            CHECK(frames[0].hitDistance[i] == frames[1].hitDistance[i]);
        }
    }
}
