// The harness of glint_sslr_gpu_tests (sslr_test.cpp, sslr_relight_test.cpp):
// a frame of the real G-buffer, ray generation and SSLR passes over a test
// scene, read back (traceScene), and the scenes: a mirror floor facing a
// wall in front of the camera (mirrorScene, with the analytic hit of each
// floor pixel's reflection, wallHit), and a floor facing thin stripes
// (stripedScene).
#pragma once

#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/ray_generation.h"
#include "glint/passes/sslr.h"
#include "glint/scene/animation.h"

#include "glint/ray_generation_shared.h"
#include "glint/sslr_shared.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <vector>

namespace glint::sslr_test {

inline constexpr uint32_t kSize = test::kPassTestSize;
inline constexpr float kNear = test::kPassTestNear;
using test::square;
using test::testCamera;
// The wall: the plane z = -kWallDistance, facing the camera, from the
// floor (y = -1) up to y = kWallTop.
inline constexpr float kWallDistance = 6.0f;
inline constexpr float kWallTop = 1.0f;

inline constexpr rg::BoundaryState kHostRead =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

struct SslrFrame {
    std::vector<shader::PackedRay> rays;
    std::vector<uint32_t> classes;
    std::vector<shader::PackedRay> rtRays;
    std::array<uint32_t, shader::kRayListArgsWords> rtArgs{};
    std::vector<glm::vec4> radiance;
    std::vector<float> confidence;
    std::vector<glm::vec2> hit;
    std::vector<glm::vec4> lit;

    size_t at(uint32_t x, uint32_t y) const { return size_t(y) * kSize + x; }
};

// Copies buffers and images into host-visible buffers inside the graph, so
// the test reads them under the graph's own barriers.
class Readback {
public:
    static constexpr size_t kBuffers = 4;
    static constexpr size_t kTextures = 4;

    explicit Readback(gpu::Context& ctx) {
        const uint64_t pixels = kSize * kSize;
        const std::array<uint64_t, kBuffers + kTextures> bytes = {
            pixels * sizeof(shader::PackedRay), pixels * 4, pixels * sizeof(shader::PackedRay),
            shader::kRayListArgsWords * 4, pixels * 8, pixels * 2, pixels * 8, pixels * 8};
        for (size_t i = 0; i < bytes.size(); ++i) {
            buffers_.emplace_back(ctx, bytes[i], "sslr_test.readback" + std::to_string(i));
        }
    }

    void add(rg::Graph& graph, const passes::RayGenerationOutputs& rays, const passes::SslrOutputs& sslr,
             const passes::GBufferOutputs& gbuf, rg::FrameResources& frame) const {
        const std::array<rg::Buffer, kBuffers> buffers = {rays.rays, rays.classes, sslr.rtRayList, sslr.rtArgs};
        const std::array<rg::Texture, kTextures> textures = {sslr.radiance, sslr.confidence, sslr.hit, gbuf.lit};
        for (size_t i = 0; i < kBuffers; ++i) buffers_[i].copy(graph, frame, buffers[i]);
        for (size_t i = 0; i < kTextures; ++i) buffers_[kBuffers + i].copy(graph, frame, textures[i]);
    }

    SslrFrame decode() const {
        SslrFrame f;
        const size_t n = size_t(kSize) * kSize;
        f.rays.resize(n);
        f.classes.resize(n);
        f.rtRays.resize(n);
        std::memcpy(f.rays.data(), buffers_[0].bytes().data(), n * sizeof(shader::PackedRay));
        std::memcpy(f.classes.data(), buffers_[1].bytes().data(), n * 4);
        std::memcpy(f.rtRays.data(), buffers_[2].bytes().data(), n * sizeof(shader::PackedRay));
        std::memcpy(f.rtArgs.data(), buffers_[3].bytes().data(), sizeof(f.rtArgs));
        const auto halves = [](const rg::HostReadback& b, size_t i, int components) {
            const uint16_t* h = b.as<uint16_t>().data() + i * components;
            glm::vec4 v(0.0f);
            for (int c = 0; c < components; ++c) v[c] = glm::unpackHalf1x16(h[c]);
            return v;
        };
        f.radiance.resize(n);
        f.confidence.resize(n);
        f.hit.resize(n);
        f.lit.resize(n);
        for (size_t i = 0; i < n; ++i) {
            f.lit[i] = halves(buffers_[7], i, 4);
            // SSLR writes its ray leaders' pixels only (SSLR and hybrid
            // pixels with a ray of their own), and nothing clears the rest:
            // those read as zero here, as "no hit" to every reader.
            const uint32_t flags = f.rays[i].pixelFlags;
            const bool leader = flags != shader::kNoRay && (flags & shader::kRayReused) == 0u &&
                                (f.classes[i] == shader::kPixelSslr || f.classes[i] == shader::kPixelHybrid);
            if (!leader) continue;
            f.radiance[i] = halves(buffers_[4], i, 4);
            f.confidence[i] = halves(buffers_[5], i, 1).x;
            std::memcpy(&f.hit[i], buffers_[6].bytes().data() + i * sizeof(glm::vec2), sizeof(glm::vec2));
        }
        return f;
    }

private:
    std::vector<rg::HostReadback> buffers_;
};

// A mirror floor at y = -1 and a rough red wall at z = -6 from the floor
// to y = 1 (wide enough to fill the image), under a camera at the origin
// looking down -Z. A rough wall (the default) traces nothing itself; a
// mirror wall reflects back toward the camera.
inline scene::Scene mirrorScene(float wallRoughness = 1.0f) {
    scene::Scene s;
    s.name = "sslr-test";
    scene::Material mirror;
    mirror.roughnessFactor = 0.0f;
    mirror.metallicFactor = 1.0f;
    scene::Material wall;
    wall.baseColorFactor = {0.8f, 0.1f, 0.1f, 1.0f};
    wall.roughnessFactor = wallRoughness;
    wall.metallicFactor = 0.0f;
    s.materials = {mirror, wall};
    scene::Mesh mesh;
    mesh.name = "floor-and-wall";
    const float half = 0.5f * (kWallTop + 1.0f);
    mesh.lods.push_back({{square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f, 0),
                          square({0, -1 + half, -kWallDistance}, {1, 0, 0}, {0, 1, 0}, half, 1)}});
    // The square is as wide as it is tall: widen it by scaling x.
    for (glm::vec3& p : mesh.lods[0].geometries[1].positions) p.x *= 40.0f;
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "floor-and-wall";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}

// Where the mirror reflection of the view ray through a floor pixel meets
// the wall's plane, in world units. The view ray (ndcX, -ndcY, -1) meets
// the floor at depth 1 / ndcY; the reflection keeps x / z and climbs at the
// slope it fell, so at z = -kWallDistance it is at
// y = -1 + (kWallDistance - 1 / ndcY) ndcY and x = ndcX kWallDistance.
inline glm::vec2 wallHit(uint32_t x, uint32_t y) {
    const glm::vec2 n = test::pixelNdc(x, y);
    return {n.x * kWallDistance, -1.0f + (kWallDistance * n.y - 1.0f)};
}

// The wall point's pixel position (continuous, pixels).
inline glm::vec2 wallPixel(glm::vec2 hit) {
    const float ndcX = hit.x / kWallDistance;
    const float ndcY = -hit.y / kWallDistance;
    return {(ndcX * 0.5f + 0.5f) * float(kSize), (ndcY * 0.5f + 0.5f) * float(kSize)};
}

// A floor of the given roughness (metallic) facing a wall of vertical red
// and green stripes kStripeWidth wide at the same place as mirrorScene's.
inline constexpr float kStripeWidth = 0.1f;

inline scene::Scene stripedScene(float floorRoughness) {
    scene::Scene s;
    s.name = "sslr-cone-test";
    scene::Material floor;
    floor.roughnessFactor = floorRoughness;
    floor.metallicFactor = 1.0f;
    scene::Material red, green;
    red.baseColorFactor = {0.9f, 0.0f, 0.0f, 1.0f};
    green.baseColorFactor = {0.0f, 0.9f, 0.0f, 1.0f};
    red.roughnessFactor = green.roughnessFactor = 1.0f;
    red.metallicFactor = green.metallicFactor = 0.0f;
    s.materials = {floor, red, green};
    scene::Mesh mesh;
    mesh.name = "floor-and-stripes";
    scene::MeshLod lod;
    lod.geometries.push_back(square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f, 0));
    const float half = 0.5f * (kWallTop + 1.0f);
    for (int i = -120; i < 120; ++i) {
        scene::Geometry g = square({(float(i) + 0.5f) * kStripeWidth, -1 + half, -kWallDistance}, {1, 0, 0}, {0, 1, 0},
                                   half, i % 2 == 0 ? 1u : 2u);
        // Squeeze the square to a stripe around its centre.
        const float centre = (float(i) + 0.5f) * kStripeWidth;
        for (glm::vec3& p : g.positions) p.x = centre + (p.x - centre) * kStripeWidth / (2.0f * half);
        lod.geometries.push_back(std::move(g));
    }
    mesh.lods.push_back(std::move(lod));
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "floor-and-stripes";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}

inline SslrFrame traceScene(test::GpuTest& gpu, const scene::Scene& scene, uint64_t frame,
                            const passes::SslrSettings& settings,
                            float roughnessCutoff = passes::RayGenerationSettings{}.roughnessCutoff) {
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::RayGenerationPipelines rayPipelines(ctx);
    passes::SslrPipelines sslrPipelines(ctx);
    Readback readback(ctx);
    const scene::Camera camera = testCamera();
    // Every floor pixel is hybrid: SSLR first, RT for what it misses.
    passes::RayGenerationSettings raySettings;
    raySettings.rtMaxDistance = 0.0f;
    raySettings.roughnessCutoff = roughnessCutoff;
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    const passes::RayGenerationOutputs rays =
        passes::addRayGenerationPass(graph, rayPipelines,
                                     {gbuf, frame, camera, {}, passes::ReflectionMode::Hybrid, 1e9f}, raySettings);
    const passes::SslrOutputs sslr =
        passes::addSslrPass(graph, sslrPipelines, {gbuf, rays, frame, camera.view, camera.projection}, settings);
    readback.add(graph, rays, sslr, gbuf, resources);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const auto report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    executor.run(plan, resources);
    executor.waitIdle();
    return readback.decode();
}

inline SslrFrame trace(test::GpuTest& gpu, uint64_t frame, const passes::SslrSettings& settings = {},
               float wallRoughness = 1.0f) {
    return traceScene(gpu, mirrorScene(wallRoughness), frame, settings);
}

inline bool finite(glm::vec4 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

} // namespace glint::sslr_test
