// The harness of glint_rt_trace_gpu_tests (rt_trace_test.cpp,
// rt_trace_origin_test.cpp): a frame of the real G-buffer, BVH update and
// RT pass over a ray list built by the test, read back (Rig), and the CPU
// reference the hits must match: the scene's triangles in world space,
// traced in double (CpuScene), the surface a hit sees (hitSurface), lit by
// a port of glint/brdf.glsl (shadeSurface), from where the pass starts each
// ray (Rig::rayOrigin: the G-buffer's depth, read back, and the same origin
// offset).
#pragma once

#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/bvh_update.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/rt_trace.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/packed_primitives.h"

#include "glint/packing.h"
#include "glint/ray_generation_shared.h"
#include "glint/rt_trace_shared.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace glint::rt_trace_test {

inline constexpr uint32_t kSize = test::kPassTestSize;
using test::square;

inline constexpr rg::BoundaryState kHostWritten =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

inline size_t pixelIndex(glm::uvec2 p) { return size_t(p.y) * kSize + p.x; }

// ---------------------------------------------------------------------------
// CPU port of glint/brdf.glsl (the formula the hits must reproduce)
// ---------------------------------------------------------------------------

inline constexpr float kPi = 3.14159265358979f;
inline constexpr float kMinRoughness = 0.045f;

struct CpuSurface {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec3 albedo{0.0f};
    float roughness = 0.0f;
    float metallic = 0.0f;
    float reflectance = 0.0f;
};

inline glm::vec3 skyRadiance(const shader::SceneLighting& l, glm::vec3 dir) {
    const float y = std::clamp(dir.y, -1.0f, 1.0f);
    if (y < 0.0f) {
        return glm::mix(glm::vec3(l.skyHorizon), glm::vec3(l.skyGround), std::clamp(-y * 10.0f, 0.0f, 1.0f));
    }
    return glm::mix(glm::vec3(l.skyHorizon), glm::vec3(l.skyZenith), std::sqrt(y));
}

inline glm::vec3 skyIrradiance(const shader::SceneLighting& l, glm::vec3 n) {
    const glm::vec3 up = kPi * glm::mix(glm::vec3(l.skyHorizon), glm::vec3(l.skyZenith), 0.5f);
    const glm::vec3 down = kPi * glm::vec3(l.skyGround);
    return glm::mix(down, up, 0.5f + 0.5f * std::clamp(n.y, -1.0f, 1.0f));
}

inline glm::vec3 environmentRadiance(const shader::SceneLighting& l, glm::vec3 dir, float roughness) {
    const float alpha = std::clamp(roughness * roughness, 0.0f, 1.0f);
    return glm::mix(skyRadiance(l, dir), skyIrradiance(l, dir) / kPi, alpha);
}

inline glm::vec3 shadeSurface(const shader::SceneLighting& l, const CpuSurface& s, glm::vec3 toViewer,
                              float sunVisibility) {
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
inline CpuSurface hitSurface(const CpuHit& h, glm::vec3 position, glm::vec3 rayDir, bool packed) {
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
inline std::optional<glm::dvec3> pixelOnPlane(const scene::Camera& camera, glm::uvec2 p, glm::dvec3 point,
                                              glm::dvec3 normal) {
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

// glint/rt_trace.glsl's rtOffsetOrigin for a ray leaving the G-buffer
// surface at `p` (normal `n`) seen from `camera`, in double.
inline glm::dvec3 offsetOrigin(glm::dvec3 p, glm::dvec3 n, glm::dvec3 camera, double rasterErrorPerDistance) {
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
inline glm::dvec3 gbufferPoint(const scene::Camera& camera, glm::uvec2 p, float depth) {
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
                  const passes::RtTraceSettings& settings, float maxDistance = scene::kDefaultBvhRadius,
                  float shadowDistance = 2.0f * scene::kDefaultBvhRadius) {
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
        inputs.shadowDistance = shadowDistance;
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

inline std::vector<passes::RtBackend> availableBackends(const gpu::Context& ctx) {
    std::vector<passes::RtBackend> out;
    for (const passes::RtBackend b : {passes::RtBackend::RayQuery, passes::RtBackend::Pipeline}) {
        if (passes::RtTracePipelines::supported(ctx, b)) out.push_back(b);
    }
    return out;
}

inline passes::RtTraceSettings settingsFor(passes::RtBackend backend) {
    passes::RtTraceSettings s;
    s.backend = backend;
    // The shadow rays these tests check against the CPU's (the shadow map
    // at hits has a test of its own).
    s.shadowMapAtHits = false;
    return s;
}

// ---------------------------------------------------------------------------
// Lighting, ray lists and comparisons
// ---------------------------------------------------------------------------

// The sun of the tests' lighting: from up, right and behind the camera.
inline const glm::vec3 kSun = glm::normalize(glm::vec3(0.4f, 1.0f, 0.6f));

inline shader::SceneLighting sunAndSky() {
    shader::SceneLighting l{};
    l.sunDirection = glm::vec4(kSun, 0.0f);
    l.sunIrradiance = {3.0f, 2.8f, 2.5f, 0.0f};
    l.skyZenith = {0.2f, 0.35f, 0.65f, 0.0f};
    l.skyHorizon = {0.7f, 0.75f, 0.8f, 0.0f};
    l.skyGround = {0.2f, 0.18f, 0.16f, 0.0f};
    return l;
}

struct ListedRay {
    glm::uvec2 pixel;
    glm::dvec3 origin;    // the analytic surface point the ray is aimed from
    glm::vec3 direction;  // as the GPU unpacks it
    bool aimedAtTarget = false;
};

inline RayList toList(const std::vector<ListedRay>& rays) {
    RayList list;
    for (const ListedRay& r : rays) {
        list.entries.push_back({shader::packRayPixel(r.pixel, false), shader::packRayDirection(r.direction)});
    }
    list.count = uint32_t(list.entries.size());
    return list;
}

// Each channel of `got` within relative * |expected| + absolute of `expected`'s.
inline bool near(glm::vec3 got, glm::vec3 expected, float relative, float absolute) {
    for (int c = 0; c < 3; ++c) {
        if (!(std::abs(got[c] - expected[c]) <= relative * std::abs(expected[c]) + absolute)) return false;
    }
    return true;
}

// A vector for messages.
inline std::string text(glm::vec3 v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

} // namespace glint::rt_trace_test
