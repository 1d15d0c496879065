// Screen-space reflections (passes/sslr.h) on a real device behind the real
// G-buffer and ray generation passes, validation on. A mirror floor faces a
// red wall in front of the camera: floor pixels whose reflection meets the
// wall find it within one texel of the analytic hit, with the wall's lit
// colour and full confidence; reflections passing over the wall into the
// sky get zero confidence and go to the RT list, whose length and args
// match a count on the CPU; nothing is NaN.
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

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr float kNear = test::kPassTestNear;
using test::square;
using test::testCamera;
// The wall: the plane z = -kWallDistance, facing the camera, from the
// floor (y = -1) up to y = kWallTop.
constexpr float kWallDistance = 6.0f;
constexpr float kWallTop = 1.0f;

constexpr rg::BoundaryState kHostRead =
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
scene::Scene mirrorScene(float wallRoughness = 1.0f) {
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
glm::vec2 wallHit(uint32_t x, uint32_t y) {
    const glm::vec2 n = test::pixelNdc(x, y);
    return {n.x * kWallDistance, -1.0f + (kWallDistance * n.y - 1.0f)};
}

// The wall point's pixel position (continuous, pixels).
glm::vec2 wallPixel(glm::vec2 hit) {
    const float ndcX = hit.x / kWallDistance;
    const float ndcY = -hit.y / kWallDistance;
    return {(ndcX * 0.5f + 0.5f) * float(kSize), (ndcY * 0.5f + 0.5f) * float(kSize)};
}

// A floor of the given roughness (metallic) facing a wall of vertical red
// and green stripes kStripeWidth wide at the same place as mirrorScene's.
constexpr float kStripeWidth = 0.1f;

scene::Scene stripedScene(float floorRoughness) {
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
        for (glm::vec3& p : g.positions) p.x = (float(i) + 0.5f) * kStripeWidth + (p.x - (float(i) + 0.5f) * kStripeWidth) * kStripeWidth / (2.0f * half);
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

SslrFrame traceScene(test::GpuTest& gpu, const scene::Scene& scene, uint64_t frame, const passes::SslrSettings& settings,
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

SslrFrame trace(test::GpuTest& gpu, uint64_t frame, const passes::SslrSettings& settings = {},
               float wallRoughness = 1.0f) {
    return traceScene(gpu, mirrorScene(wallRoughness), frame, settings);
}

bool finite(glm::vec4 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w); }

} // namespace

TEST_CASE("SSLR finds the wall in a mirror floor within one texel, with its lit colour and full confidence") {
    test::GpuTest gpu;
    const passes::SslrSettings settings;
    for (const uint64_t frame : {0u, 5u}) {
        const SslrFrame f = trace(gpu, frame, settings);
        // The wall's lit colour: flat, one normal, a directional sun, so one
        // value; read where the wall surely is.
        const glm::vec4 wallLit = f.lit[f.at(kSize / 2, kSize / 2)];
        REQUIRE(wallLit.r > 2.0f * wallLit.g);  // red: it is the wall
        uint32_t checkedHits = 0, checkedMisses = 0;
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("frame " << frame << " pixel " << x << ", " << y);
                const size_t i = f.at(x, y);
                REQUIRE(finite(f.radiance[i]));
                REQUIRE(std::isfinite(f.confidence[i]));
                REQUIRE((std::isfinite(f.hit[i].x) && std::isfinite(f.hit[i].y)));
                REQUIRE(f.confidence[i] >= 0.0f);
                REQUIRE(f.confidence[i] <= 1.0f);
                if (f.classes[i] != shader::kPixelHybrid) {
                    // The wall (rough) and the sky trace nothing.
                    REQUIRE(f.confidence[i] == 0.0f);
                    continue;
                }
                const glm::vec2 hit = wallHit(x, y);
                const glm::vec2 expected = wallPixel(hit);
                // Hits well inside the wall and away from the edge fade.
                const float fadePixels = settings.edgeFade * float(kSize);
                const bool onWall = hit.y > -1.0f && hit.y < kWallTop;
                const float wallBottomPixel = wallPixel({0.0f, -1.0f}).y;
                const float wallTopPixel = wallPixel({0.0f, kWallTop}).y;
                const bool clearHit = expected.y > wallTopPixel + 1.5f && expected.y < wallBottomPixel - 1.5f &&
                                      expected.x > fadePixels + 1.0f && expected.x < float(kSize) - fadePixels - 1.0f;
                if (onWall && clearHit) {
                    ++checkedHits;
                    REQUIRE(f.radiance[i].a == 1.0f);
                    const glm::vec2 got = f.hit[i] * float(kSize);
                    // Within one texel of the analytic hit.
                    REQUIRE(std::abs(got.x - expected.x) <= 1.0f);
                    REQUIRE(std::abs(got.y - expected.y) <= 1.0f);
                    REQUIRE(f.confidence[i] > passes::kDefaultConfidenceThreshold);
                    const glm::vec3 rgb = f.radiance[i];
                    REQUIRE(glm::length(rgb - glm::vec3(wallLit)) <= 0.01f * glm::length(glm::vec3(wallLit)));
                } else if (hit.y > kWallTop + 0.5f) {
                    // Over the wall: only sky behind, then off the screen.
                    ++checkedMisses;
                    REQUIRE(f.confidence[i] == 0.0f);
                    REQUIRE(f.radiance[i] == glm::vec4(0.0f));
                }
            }
        }
        CHECK(checkedHits > 200);
        CHECK(checkedMisses > 200);
    }
}

// With 8 linear steps, each several pixels long, the binary refinement
// decides which hits count: a hit needs the refined point within the
// thickness behind the wall, and each halving of the crossing's interval
// halves how far behind it may lie. So the accepted hits about double with
// every halving until all are (19, 40, 88, 199, 320 on lavapipe), and
// each lies within a texel of the analytic hit.
TEST_CASE("with a few long steps every refinement halving accepts about twice the hits, each on the wall") {
    test::GpuTest gpu;
    std::vector<uint32_t> hits;
    for (uint32_t refineSteps = 0; refineSteps <= 6; ++refineSteps) {
        passes::SslrSettings settings;
        settings.linearSteps = 8;
        settings.minStepPixels = 0.0f;
        settings.refineSteps = refineSteps;
        const SslrFrame f = trace(gpu, 2, settings);
        double distanceSum = 0.0;
        uint32_t count = 0;
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const size_t i = f.at(x, y);
                const glm::vec2 hit = wallHit(x, y);
                if (f.classes[i] != shader::kPixelHybrid || f.radiance[i].a != 1.0f || !(hit.y > -0.5f) ||
                    !(hit.y < kWallTop - 0.5f)) {
                    continue;
                }
                distanceSum += glm::length(f.hit[i] * float(kSize) - wallPixel(hit));
                ++count;
            }
        }
        hits.push_back(count);
        MESSAGE("refine steps " << refineSteps << ": " << count << " hits, mean distance from the analytic hit "
                                << (count > 0 ? distanceSum / count : 0.0) << " px");
        INFO("refine steps " << refineSteps);
        CHECK(distanceSum <= 0.6 * count);
        if (refineSteps > 0) {
            CHECK(hits[refineSteps] >= hits[refineSteps - 1]);
        }
        if (refineSteps > 0 && refineSteps <= 4) {
            CHECK(hits[refineSteps] > 1.5 * hits[refineSteps - 1]);
        }
    }
    CHECK(hits.back() > 300);
}

TEST_CASE("SSLR lists exactly the hybrid rays below the confidence threshold for RT, with matching args") {
    test::GpuTest gpu;
    const passes::SslrSettings settings;
    const SslrFrame f = trace(gpu, 3, settings);
    std::set<uint32_t> expected;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const size_t i = f.at(x, y);
            const shader::PackedRay& ray = f.rays[i];
            const bool leader = ray.pixelFlags != shader::kNoRay && (ray.pixelFlags & shader::kRayReused) == 0u;
            // Ray generation lists the RT pixels' leaders; SSLR appends its
            // unresolved hybrid ones.
            const bool unresolved = f.confidence[i] < passes::kDefaultConfidenceThreshold;
            if (leader && (f.classes[i] == shader::kPixelRt || (f.classes[i] == shader::kPixelHybrid && unresolved))) {
                expected.insert(ray.pixelFlags);
            }
        }
    }
    const uint32_t count = f.rtArgs[shader::kRayListCountOffset];
    REQUIRE(count == expected.size());
    REQUIRE(count > 0);
    CHECK(f.rtArgs[0] == (count + shader::kRayListGroupSize - 1) / shader::kRayListGroupSize);
    CHECK(f.rtArgs[1] == 1u);
    CHECK(f.rtArgs[2] == 1u);
    CHECK(f.rtArgs[4] == 1u);
    CHECK(f.rtArgs[5] == 1u);
    std::set<uint32_t> listed;
    for (uint32_t k = 0; k < count; ++k) {
        const shader::PackedRay& ray = f.rtRays[k];
        // The entry is the pixel's own ray, unchanged.
        const glm::uvec2 p = shader::unpackRayPixel(ray.pixelFlags);
        REQUIRE(p.x < kSize);
        REQUIRE(p.y < kSize);
        CHECK(ray.direction == f.rays[f.at(p.x, p.y)].direction);
        listed.insert(ray.pixelFlags);
    }
    CHECK(listed == expected);
}

TEST_CASE("the start offsets are deterministic per frame") {
    test::GpuTest gpu;
    const SslrFrame a = trace(gpu, 7);
    const SslrFrame b = trace(gpu, 7);
    CHECK(a.confidence == b.confidence);
    CHECK(std::memcmp(a.hit.data(), b.hit.data(), a.hit.size() * sizeof(glm::vec2)) == 0);
}

// A float as an image of `format` stores it (the float formats a hit image
// could have; anything else fails the test).
float storedAs(VkFormat format, float x) {
    switch (format) {
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_SFLOAT:
        return x;
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SFLOAT:
        return glm::unpackHalf1x16(glm::packHalf1x16(x));
    default:
        FAIL("no rounding known for format " << format);
        return x;
    }
}

TEST_CASE("the hit image gives readers the hit's own texel at every image size up to 8K") {
    // SSLR stores the hit texel's centre as uv (shader::sslrHitUv);
    // integrate and the particle trace find the texel again
    // (shader::sslrHitTexel) to read the hit's depth and motion. In half
    // floats it lands on a neighbour from 2048 pixels across.
    for (const uint32_t size : {1920u, 2048u, 2560u, 3840u, 7680u}) {
        for (uint32_t x = 0; x < size; ++x) {
            const glm::vec2 uv = shader::sslrHitUv({x, 0u}, glm::uvec2(size, 1u));
            const glm::vec2 stored(storedAs(passes::kSslrHitFormat, uv.x), storedAs(passes::kSslrHitFormat, uv.y));
            INFO("size " << size << " texel " << x);
            REQUIRE(shader::sslrHitTexel(stored, glm::uvec2(size, 1u)) == glm::uvec2(x, 0u));
        }
    }
}

TEST_CASE("rays from a mirror wall back toward the camera leave the screen with zero confidence and go to RT") {
    test::GpuTest gpu;
    const passes::SslrSettings settings;
    const SslrFrame f = trace(gpu, 2, settings, 0.0f);
    std::set<uint32_t> listed;
    for (uint32_t k = 0; k < f.rtArgs[shader::kRayListCountOffset]; ++k) listed.insert(f.rtRays[k].pixelFlags);
    uint32_t checked = 0;
    const float wallTopPixel = wallPixel({0.0f, kWallTop}).y;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            // Wall pixels above the image's centre: their reflections climb
            // toward the camera, over the sky and out of the image.
            if (float(y) < wallTopPixel + 1.0f || float(y) + 0.5f > float(kSize) / 2.0f - 1.0f) continue;
            INFO("pixel " << x << ", " << y);
            const size_t i = f.at(x, y);
            REQUIRE(f.classes[i] == shader::kPixelHybrid);
            const glm::vec3 d = shader::unpackRayDirection(f.rays[i].direction);
            REQUIRE(d.z > 0.5f);  // toward the camera (+Z)
            REQUIRE(f.confidence[i] == 0.0f);
            REQUIRE(f.radiance[i].a == 0.0f);
            REQUIRE(listed.count(shader::packRayPixel({x, y}, false)) == 1);
            ++checked;
        }
    }
    CHECK(checked >= 3 * kSize);
}

// A rough green bar across the view in front of mirrorScene's wall, its
// edges on texel edges: image rows kBarFirstRow to kBarLastRow. Its distance
// is chosen so that the mirror reflection of floor row kBelowBarRow, three
// rows below it, enters the bar's rows 1.5% of the bar's distance behind it
// (the ray rises up the image and away from the camera), then climbs on to
// the wall.
constexpr uint32_t kBarFirstRow = 38;
constexpr uint32_t kBarLastRow = 41;
constexpr uint32_t kBelowBarRow = kBarLastRow + 3;
constexpr float kBarGap = 0.015f;

// The image's ndc y at a texel edge (row r's top edge).
float rowEdgeNdc(uint32_t r) { return float(r) / float(kSize) * 2.0f - 1.0f; }

// The view distance at which the reflection of floor row `row` (ndc y n,
// the floor at depth 1 / n) is seen at ndc y `s`: at distance d it is at
// height y = -1 + (d - 1 / n) n, seen at s = -y / d, so d = 2 / (s + n).
float reflectionDistanceAt(uint32_t row, float s) { return 2.0f / (s + test::pixelNdc(0, row).y); }

float barDistance() { return reflectionDistanceAt(kBelowBarRow, rowEdgeNdc(kBarLastRow + 1)) / (1.0f + kBarGap); }

scene::Scene barScene() {
    scene::Scene s = mirrorScene();
    scene::Material bar;
    bar.baseColorFactor = {0.1f, 0.8f, 0.1f, 1.0f};
    bar.roughnessFactor = 1.0f;
    bar.metallicFactor = 0.0f;
    s.materials.push_back(bar);
    const float d = barDistance();
    const float top = -rowEdgeNdc(kBarFirstRow) * d, bottom = -rowEdgeNdc(kBarLastRow + 1) * d;
    scene::Geometry g = square({0.0f, 0.5f * (top + bottom), -d}, {1, 0, 0}, {0, 1, 0}, 0.5f * (top - bottom), 2);
    for (glm::vec3& p : g.positions) p.x *= 40.0f / (0.5f * (top - bottom));  // as wide as the wall
    s.meshes[0].lods[0].geometries.push_back(std::move(g));
    scene::prepareScene(s);
    return s;
}

// A ray that passes behind a thin object is no hit on it. With the default
// thickness, the reflections of the floor rows just below the bar that
// slip behind it (kBelowBarRow's by 1.5% of its distance, the rows above
// by more) march on past it and find the wall: 0.02, the default until
// 2026-12-07, took the bar for kBelowBarRow's hit (at half confidence).
// The rows below, whose reflections meet the bar's face, still find it.
// (The row just below the bar enters the bar's rows within a pixel of its
// origin: the binary search used to follow the ray into its own texel
// there and stop at a hit on itself.)
TEST_CASE("a reflection passing just behind a thin bar is no hit on it: it marches on to the wall") {
    test::GpuTest gpu;
    const passes::SslrSettings settings;
    REQUIRE(settings.thickness < kBarGap);
    const SslrFrame f = traceScene(gpu, barScene(), 4, settings);
    const glm::vec4 wallLit = f.lit[f.at(kSize / 2, kSize / 2 - 4)];
    const glm::vec4 barLit = f.lit[f.at(kSize / 2, (kBarFirstRow + kBarLastRow) / 2)];
    REQUIRE(wallLit.r > 2.0f * wallLit.g);  // red: the wall
    REQUIRE(barLit.g > 2.0f * barLit.r);    // green: the bar
    const float fadePixels = settings.edgeFade * float(kSize);
    uint32_t behind = 0, onBar = 0;
    for (uint32_t y = kBarLastRow + 1; y <= kBelowBarRow + 2; ++y) {
        // Where the reflection first appears in the bar's rows (their
        // bottom edge), it lies behind the bar or in front of it.
        const bool passesBehind = reflectionDistanceAt(y, rowEdgeNdc(kBarLastRow + 1)) > barDistance();
        REQUIRE(passesBehind == (y <= kBelowBarRow));
        const glm::vec4 expected = passesBehind ? wallLit : barLit;
        for (uint32_t x = 0; x < kSize; ++x) {
            if (!(float(x) > fadePixels + 1.0f && float(x) + 1.0f < float(kSize) - fadePixels)) continue;
            const size_t i = f.at(x, y);
            const float hitRow = f.hit[i].y * float(kSize);
            INFO("pixel " << x << ", " << y << ": hit row " << hitRow << ", radiance " << f.radiance[i].r << " "
                          << f.radiance[i].g << " " << f.radiance[i].b);
            REQUIRE(f.classes[i] == shader::kPixelHybrid);
            CHECK(f.radiance[i].a == 1.0f);
            CHECK(f.confidence[i] >= passes::kDefaultConfidenceThreshold);
            CHECK((hitRow >= float(kBarFirstRow) && hitRow < float(kBarLastRow + 1)) == !passesBehind);
            CHECK(glm::length(glm::vec3(f.radiance[i] - expected)) <= 0.01f * glm::length(glm::vec3(expected)));
            ++(passesBehind ? behind : onBar);
        }
    }
    CHECK(behind > 3 * kSize / 2);
    CHECK(onBar > kSize);
}

TEST_CASE("rough pixels cone-trace: their reflection of thin stripes is the stripes' mean, a mirror's is one stripe") {
    test::GpuTest gpu;
    // The share of confident floor hits whose colour mixes both stripes
    // (the weaker channel at least a quarter of the stronger).
    const auto mixedShare = [](const SslrFrame& f) {
        uint32_t hits = 0, mixed = 0;
        for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const size_t i = f.at(x, y);
                if (f.confidence[i] < 0.9f || f.radiance[i].a < 0.5f) continue;
                const float r = f.radiance[i].r, g = f.radiance[i].g;
                if (std::max(r, g) < 0.02f) continue;  // not the wall
                ++hits;
                mixed += std::min(r, g) >= 0.25f * std::max(r, g) ? 1u : 0u;
            }
        }
        REQUIRE(hits > 10);
        return double(mixed) / double(hits);
    };
    passes::SslrSettings cone;
    passes::SslrSettings noCone;
    noCone.coneTrace = false;
    // Rough (0.4, alpha 0.16, traced: the cutoff is raised for the test):
    // the lobe's footprint on the wall spans several pixels of stripes half
    // a pixel wide, so the cone trace's pyramid sample mixes them, while a
    // stochastic ray reads one texel of one stripe.
    const double coneRough = mixedShare(traceScene(gpu, stripedScene(0.4f), 3, cone, 0.5f));
    const double plainRough = mixedShare(traceScene(gpu, stripedScene(0.4f), 3, noCone, 0.5f));
    // A mirror (below coneRoughness) reads single texels either way.
    const double mirror = mixedShare(traceScene(gpu, stripedScene(0.0f), 3, cone));
    INFO("mixed shares: cone " << coneRough << ", without cone " << plainRough << ", mirror " << mirror);
    CHECK(coneRough > 0.8);
    CHECK(plainRough < 0.4);
    CHECK(mirror < 0.4);
}

namespace {

// The colour pyramid of one frame, every level read back (levels[m] the
// chain's level m + 1: the image's mip m), with the lit colour it was
// built from and the SSLR list's args.
struct PyramidFrame {
    glm::uvec2 size{0};
    std::vector<glm::vec4> lit;
    std::vector<std::vector<glm::vec4>> levels;
    std::array<uint32_t, shader::kSslrArgsWords> sslrArgs{};
};

PyramidFrame buildPyramid(test::GpuTest& gpu, const scene::Scene& scene, glm::uvec2 size) {
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::RayGenerationPipelines rayPipelines(ctx);
    passes::SslrPipelines sslrPipelines(ctx);
    scene::Camera camera = testCamera();
    camera.resolution = size;
    camera.reset({glm::vec3(0.0f), glm::vec3(0, 0, -1), {0, 1, 0}}, 0);
    passes::RayGenerationSettings raySettings;
    raySettings.rtMaxDistance = 0.0f;
    raySettings.roughnessCutoff = 0.5f;
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    const passes::RayGenerationOutputs rays =
        passes::addRayGenerationPass(graph, rayPipelines,
                                     {gbuf, 1, camera, {}, passes::ReflectionMode::Hybrid, 1e9f}, raySettings);
    const passes::SslrOutputs sslr =
        passes::addSslrPass(graph, sslrPipelines, {gbuf, rays, 1, camera.view, camera.projection}, {});
    REQUIRE(sslr.litPyramid.valid());

    PyramidFrame out;
    out.size = size;
    // The mips the pass declared its image with (the test case checks
    // their number); each the chain's level m + 1 (level 0, the lit
    // colour, is not in the image).
    const rg::TextureDesc& desc = graph.declaration().resources[sslr.litPyramid.index].texture;
    REQUIRE(glm::uvec2(desc.width, desc.height) == shader::sslrMipSize(size, 1));
    const uint32_t mips = desc.mips;
    uint64_t texels = 0;
    for (uint32_t m = 0; m < mips; ++m) {
        const glm::uvec2 s = shader::sslrMipSize(size, m + 1);
        texels += uint64_t(s.x) * s.y;
    }
    const uint64_t pixels = uint64_t(size.x) * size.y;
    gpu::Buffer pyramid(ctx, {texels * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback, "pyramid"});
    gpu::Buffer lit(ctx, {pixels * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback, "lit"});
    gpu::Buffer args(ctx, {shader::kSslrArgsWords * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback,
                           "sslr_args"});
    const rg::BoundaryState copy = rg::BoundaryState::of(rg::Access::TransferDst);
    const std::array<rg::Buffer, 3> targets = {graph.importBuffer("pyramid", {{pyramid.size()}, copy, kHostRead}),
                                               graph.importBuffer("lit", {{lit.size()}, copy, kHostRead}),
                                               graph.importBuffer("args", {{args.size()}, copy, kHostRead})};
    resources.bind(targets[0], pyramid);
    resources.bind(targets[1], lit);
    resources.bind(targets[2], args);
    struct Data {
        rg::Texture pyramid, lit;
        rg::Buffer args;
        std::array<rg::Buffer, 3> targets;
    };
    const Data& data = graph.addPass<Data>(
        "readback", rg::Queue::Graphics,
        [&](rg::Builder& b, Data& d) {
            d.pyramid = b.read(sslr.litPyramid, rg::Access::TransferSrc);
            d.lit = b.read(gbuf.lit, rg::Access::TransferSrc);
            d.args = b.read(rays.sslrArgs, rg::Access::TransferSrc);
            for (size_t i = 0; i < targets.size(); ++i) d.targets[i] = b.write(targets[i], rg::Access::TransferDst);
        },
        [size, mips](const Data& d, rg::PassContext& pc) {
            std::vector<VkBufferImageCopy> regions;
            VkDeviceSize offset = 0;
            for (uint32_t m = 0; m < mips; ++m) {
                const glm::uvec2 s = shader::sslrMipSize(size, m + 1);
                VkBufferImageCopy region{};
                region.bufferOffset = offset;
                region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
                region.imageExtent = {s.x, s.y, 1};
                regions.push_back(region);
                offset += VkDeviceSize(s.x) * s.y * 8;
            }
            vkCmdCopyImageToBuffer(pc.cmd(), pc.image(d.pyramid).handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.buffer(d.targets[0]).handle(), uint32_t(regions.size()), regions.data());
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {size.x, size.y, 1};
            vkCmdCopyImageToBuffer(pc.cmd(), pc.image(d.lit).handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.buffer(d.targets[1]).handle(), 1, &region);
            const VkBufferCopy words{0, 0, shader::kSslrArgsWords * 4};
            vkCmdCopyBuffer(pc.cmd(), pc.buffer(d.args).handle(), pc.buffer(d.targets[2]).handle(), 1, &words);
        });
    for (const rg::Buffer& written : data.targets) graph.markOutput(written);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const auto report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    executor.run(plan, resources);
    executor.waitIdle();

    const auto unpack = [](const gpu::Buffer& b, uint64_t first, uint64_t count) {
        std::vector<glm::vec4> v(count);
        const uint16_t* h = reinterpret_cast<const uint16_t*>(b.mapped()) + first * 4;
        for (uint64_t i = 0; i < count; ++i) {
            for (int c = 0; c < 4; ++c) v[i][c] = glm::unpackHalf1x16(h[i * 4 + c]);
        }
        return v;
    };
    out.lit = unpack(lit, 0, pixels);
    uint64_t first = 0;
    for (uint32_t m = 0; m < mips; ++m) {
        const glm::uvec2 s = shader::sslrMipSize(size, m + 1);
        out.levels.push_back(unpack(pyramid, first, uint64_t(s.x) * s.y));
        first += uint64_t(s.x) * s.y;
    }
    std::memcpy(out.sslrArgs.data(), args.mapped(), sizeof(out.sslrArgs));
    return out;
}

} // namespace

TEST_CASE("the cone pyramid is the lit colour's 2x2 means level by level, built only when a listed ray cone-traces") {
    test::GpuTest gpu;
    for (const glm::uvec2 size : {glm::uvec2(64, 64), glm::uvec2(150, 40)}) {
        CAPTURE(size.x);
        CAPTURE(size.y);
        // A rough floor (0.4, traced: the cutoff is raised) cone-traces.
        const PyramidFrame f = buildPyramid(gpu, stripedScene(0.4f), size);
        for (uint32_t pass = 0; pass < 2; ++pass) {
            const glm::uvec2 groups = shader::sslrPyramidGroups(size, pass);
            const uint32_t* command = &f.sslrArgs[shader::kSslrArgsPyramidOffset + 3 * pass];
            CHECK(command[0] == groups.x);
            CHECK(command[1] == groups.y);
            CHECK(command[2] == 1u);  // open: the floor's rays cone-trace
        }
        // The expectation on the CPU: level 0 is the lit colour (not in the
        // pyramid, which starts at level 1 at half size); each next level's
        // texel the mean of its 2x2 children in the level above, clamped to
        // that level (a level one texel across halves to itself).
        const uint32_t chain = std::min(shader::kSslrPyramidMaxMips, uint32_t(std::bit_width(std::max(size.x, size.y))));
        REQUIRE(f.levels.size() == chain - 1);
        std::vector<glm::vec3> above(f.lit.size());
        for (size_t i = 0; i < above.size(); ++i) above[i] = glm::vec3(f.lit[i]);
        glm::uvec2 aboveSize = size;
        for (uint32_t m = 1; m <= f.levels.size(); ++m) {
            CAPTURE(m);
            const glm::uvec2 s = shader::sslrMipSize(size, m);
            std::vector<glm::vec3> expected(size_t(s.x) * s.y);
            for (uint32_t y = 0; y < s.y; ++y) {
                for (uint32_t x = 0; x < s.x; ++x) {
                    glm::vec3 sum(0.0f);
                    for (uint32_t dy = 0; dy < 2; ++dy) {
                        for (uint32_t dx = 0; dx < 2; ++dx) {
                            const uint32_t cx = std::min(2 * x + dx, aboveSize.x - 1);
                            const uint32_t cy = std::min(2 * y + dy, aboveSize.y - 1);
                            sum += above[size_t(cy) * aboveSize.x + cx];
                        }
                    }
                    expected[size_t(y) * s.x + x] = 0.25f * sum;
                }
            }
            uint32_t wrong = 0;
            for (size_t i = 0; i < expected.size(); ++i) {
                const glm::vec3 got(f.levels[m - 1][i]);
                // Half floats per stored level (levels 1-5 are reduced in
                // fp32 by one pass, 6 on from the stored level 5).
                const float tolerance = 2e-3f * glm::length(expected[i]) + 1e-4f;
                if (glm::length(got - expected[i]) > tolerance || f.levels[m - 1][i].a != 1.0f) ++wrong;
            }
            CHECK(wrong == 0u);
            above = expected;
            aboveSize = s;
        }
    }
    // A mirror floor (below the cone roughness): no listed ray cone-traces,
    // so the pyramid's passes run no groups.
    const PyramidFrame mirror = buildPyramid(gpu, stripedScene(0.0f), {64, 64});
    CHECK(mirror.sslrArgs[shader::kSslrArgsPyramidOffset + 2] == 0u);
    CHECK(mirror.sslrArgs[shader::kSslrArgsPyramidOffset + 5] == 0u);
}
