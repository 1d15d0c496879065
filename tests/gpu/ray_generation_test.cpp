// Ray generation and tile classification (passes/ray_generation.h) on a
// real device behind the real G-buffer pass, validation on: a mirror floor
// gives the analytic reflection in every pixel, rough pixels beyond the
// cutoff and the sky trace nothing, rays never leave below the surface,
// tile lists and indirect args match a count of the classes, and rough
// quads share one ray. The GGX sampler itself (glint/sampling.glsl) is
// checked on the CPU against the analytic visible-normal distribution.
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/ray_generation.h"
#include "glint/scene/animation.h"

#include "glint/feedback_shared.h"
#include "glint/ray_generation_shared.h"
#include "glint/sampling.glsl"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr float kNear = test::kPassTestNear;
using test::square;
using test::testCamera;

constexpr rg::BoundaryState kHostWrite =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
constexpr size_t kReadbacks = 7;  // the last: the class debug image, when the pass writes it

// What the pass wrote in one frame, read back on the host.
struct RayFrame {
    std::vector<shader::PackedRay> rays;
    std::vector<uint32_t> classes;
    std::vector<shader::PackedRay> sslrRays;  // the whole buffer; the args say how much is listed
    std::vector<shader::PackedRay> rtRays;
    std::array<uint32_t, shader::kRayListArgsWords> sslrArgs{};
    std::array<uint32_t, shader::kRayListArgsWords> rtArgs{};
    std::vector<glm::u8vec4> classDebug;  // empty: the pass declared none (RayGenerationInputs::debugOutputs)

    size_t at(uint32_t x, uint32_t y) const { return size_t(y) * kSize + x; }
};

// Copies the pass's buffers into host-visible buffers inside the graph, so
// the test reads them under the graph's own barriers.
class Readback {
public:
    explicit Readback(gpu::Context& ctx) {
        const std::array<uint64_t, kReadbacks> bytes = {kSize * kSize * sizeof(shader::PackedRay),
                                                        kSize * kSize * 4,
                                                        kSize * kSize * sizeof(shader::PackedRay),
                                                        kSize * kSize * sizeof(shader::PackedRay),
                                                        shader::kRayListArgsWords * 4,
                                                        shader::kRayListArgsWords * 4,
                                                        kSize * kSize * 4};
        for (size_t i = 0; i < bytes.size(); ++i) {
            buffers_.emplace_back(ctx, bytes[i], "ray_generation_test.readback" + std::to_string(i));
        }
    }

    void add(rg::Graph& graph, const passes::RayGenerationOutputs& out, rg::FrameResources& frame) {
        const std::array<rg::Buffer, kReadbacks - 1> sources = {out.rays,   out.classes,  out.sslrRays,
                                                                out.rtRays, out.sslrArgs, out.rtArgs};
        for (size_t i = 0; i < sources.size(); ++i) buffers_[i].copy(graph, frame, sources[i]);
        classDebug_ = out.classDebug.valid();
        if (classDebug_) buffers_[kReadbacks - 1].copy(graph, frame, out.classDebug);
    }

    RayFrame decode() const {
        RayFrame f;
        const auto copy = [](auto& vec, const rg::HostReadback& b) {
            vec.resize(b.bytes().size() / sizeof(vec[0]));
            std::memcpy(vec.data(), b.bytes().data(), b.bytes().size());
        };
        copy(f.rays, buffers_[0]);
        copy(f.classes, buffers_[1]);
        copy(f.sslrRays, buffers_[2]);
        copy(f.rtRays, buffers_[3]);
        std::memcpy(f.sslrArgs.data(), buffers_[4].bytes().data(), sizeof(f.sslrArgs));
        std::memcpy(f.rtArgs.data(), buffers_[5].bytes().data(), sizeof(f.rtArgs));
        if (classDebug_) copy(f.classDebug, buffers_[6]);
        return f;
    }

private:
    std::vector<rg::HostReadback> buffers_;
    bool classDebug_ = false;
};

// A floor at y = -1 under a camera at the origin looking down -Z: the lower
// half of the image is floor, the upper half sky, and the floor's rows near
// the horizon are seen at grazing angles.
scene::Scene floorScene(float roughness) {
    scene::Scene s;
    s.name = "ray-generation-test";
    scene::Material material;
    material.roughnessFactor = roughness;
    material.metallicFactor = 1.0f;
    s.materials.push_back(material);
    scene::Mesh mesh;
    mesh.name = "floor";
    mesh.lods.push_back({{square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f)}});
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "floor";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}

// The unit view ray through a pixel's centre (+y is down the image).
glm::vec3 viewRay(uint32_t x, uint32_t y) {
    const glm::vec2 ndc = test::pixelNdc(x, y);
    return glm::normalize(glm::vec3(ndc.x, -ndc.y, -1.0f));
}

// What the frame hands ray generation besides the G-buffer: its mode and
// the distance from which pixels take SSLR only (the frame's reach).
struct Band {
    passes::ReflectionMode mode = passes::ReflectionMode::Hybrid;
    float sslrMinDistance = scene::kDefaultBvhRadius;
    bool debugOutputs = true;  // RayGenerationInputs::debugOutputs: the class debug image
};

// Renders the G-buffer and the ray generation for each frame index, with
// the given tile modes (u32 per tile, glint/feedback_shared.h) when not empty.
std::vector<RayFrame> generate(test::GpuTest& gpu, const scene::Scene& scene, const std::vector<uint64_t>& frames,
                               const passes::RayGenerationSettings& settings = {}, const Band& band = {},
                               const std::vector<uint32_t>& tileModes = {}) {
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::RayGenerationPipelines pipelines(ctx);
    Readback readback(ctx);
    gpu::Buffer modes;
    if (!tileModes.empty()) {
        modes = gpu::Buffer(ctx, {tileModes.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Upload,
                                  "ray_generation_test.tile_modes"});
        std::memcpy(modes.mapped(), tileModes.data(), tileModes.size() * 4);
    }
    const scene::Camera camera = testCamera();
    std::vector<RayFrame> out;
    for (const uint64_t frame : frames) {
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
        passes::RayGenerationInputs inputs{gbuf, frame, camera};
        inputs.mode = band.mode;
        inputs.sslrMinDistance = band.sslrMinDistance;
        inputs.debugOutputs = band.debugOutputs;
        if (!tileModes.empty()) {
            inputs.tileModes = graph.importBuffer(
                "tile_modes", {{modes.size()}, kHostWrite, rg::BoundaryState::of(rg::Access::StorageRead)});
            resources.bind(inputs.tileModes, modes);
        }
        const passes::RayGenerationOutputs rays = passes::addRayGenerationPass(graph, pipelines, inputs, settings);
        REQUIRE(rays.tilesX == kSize / shader::kTileSize);
        readback.add(graph, rays, resources);
        const rg::Plan plan = graph.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor.run(plan, resources);
        executor.waitIdle();
        out.push_back(readback.decode());
    }
    return out;
}

bool isFloor(uint32_t y) { return float(y) + 0.5f > float(kSize) / 2.0f; }

// Expected value of f(h) over GGX visible normals for view v (tangent
// frame), by quadrature. The substitution u = tan^2 / (alpha^2 + tan^2),
// the inverse CDF of D(h) cos(h), makes D(h) h.z d(omega) = du dphi / 2 pi,
// so the integrand G1(v) max(0, v.h) / (v.z h.z) f(h) is bounded however
// peaked D is, except for a 1 / sqrt(1 - u) growth at the horizon, which
// u = 1 - s^2 (du = 2 s ds) removes.
template <class F> double vndfExpectation(glm::dvec3 v, double alpha, F f) {
    constexpr int kU = 4096, kPhi = 512;
    const double g1 = shader::ggxSmithG1(float(v.z), float(alpha));
    double sum = 0.0;
    for (int i = 0; i < kU; ++i) {
        const double s = (i + 0.5) / kU;
        const double u = 1.0 - s * s;
        const double tanTheta = alpha * std::sqrt(u / (1.0 - u));
        const double cosTheta = 1.0 / std::sqrt(1.0 + tanTheta * tanTheta);
        const double sinTheta = tanTheta * cosTheta;
        for (int j = 0; j < kPhi; ++j) {
            const double phi = (j + 0.5) / kPhi * 2.0 * glm::pi<double>();
            const glm::dvec3 h(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
            sum += 2.0 * s * g1 * std::max(0.0, glm::dot(v, h)) / (v.z * cosTheta) * f(h);
        }
    }
    return sum / (double(kU) * kPhi);
}

} // namespace

TEST_CASE("GGX visible-normal samples match the analytic distribution's moments up to 89.9 degrees") {
    for (const float alpha : {0.05f, 0.2f, 0.5f, 1.0f}) {
        for (const float viewDegrees : {0.0f, 45.0f, 80.0f, 89.9f}) {
            INFO("alpha " << alpha << ", view " << viewDegrees << " degrees");
            const float theta = glm::radians(viewDegrees);
            const glm::vec3 v(std::sin(theta), 0.0f, std::cos(theta));
            constexpr uint32_t kSamples = 1u << 18;
            double meanZ = 0.0, meanX = 0.0, meanZ2 = 0.0;
            for (uint32_t i = 0; i < kSamples; ++i) {
                const glm::vec2 u = shader::ggxNoise({i % 512u, i / 512u}, 7u);
                const glm::vec3 h = shader::sampleGgxVndf(v, alpha, u);
                REQUIRE(std::isfinite(h.x));
                REQUIRE(h.z > 0.0f);
                meanZ += h.z;
                meanZ2 += double(h.z) * h.z;
                meanX += h.x;
            }
            meanZ /= kSamples;
            meanZ2 /= kSamples;
            meanX /= kSamples;
            const glm::dvec3 vd(v);
            const double expectedZ = vndfExpectation(vd, alpha, [](glm::dvec3 h) { return h.z; });
            const double expectedZ2 = vndfExpectation(vd, alpha, [](glm::dvec3 h) { return h.z * h.z; });
            const double expectedX = vndfExpectation(vd, alpha, [](glm::dvec3 h) { return h.x; });
            // The distribution integrates to one (checks the reference).
            CHECK(std::abs(vndfExpectation(vd, alpha, [](glm::dvec3) { return 1.0; }) - 1.0) < 2e-3);
            CHECK(std::abs(meanZ - expectedZ) < 2e-3);
            CHECK(std::abs(meanZ2 - expectedZ2) < 2e-3);
            CHECK(std::abs(meanX - expectedX) < 2e-3);
        }
    }
}

TEST_CASE("GGX samples at normal incidence are uniform in the inverse CDF of D cos (chi-square)") {
    // At v = n the visible normals are distributed as D(h) h.z, whose CDF in
    // t = tan^2 is t / (alpha^2 + t): that value must be uniform on [0, 1).
    for (const float alpha : {0.1f, 0.4f, 1.0f}) {
        INFO("alpha " << alpha);
        constexpr int kBins = 32;
        constexpr uint32_t kSamples = 1u << 16;
        std::array<int, kBins> histogram{};
        for (uint32_t i = 0; i < kSamples; ++i) {
            const glm::vec3 h = shader::sampleGgxVndf({0, 0, 1}, alpha, shader::ggxNoise({i % 256u, i / 256u}, 3u));
            const double t = (double(h.x) * h.x + double(h.y) * h.y) / (double(h.z) * h.z);
            const double cdf = t / (double(alpha) * alpha + t);
            ++histogram[std::min(kBins - 1, int(cdf * kBins))];
        }
        const double expected = double(kSamples) / kBins;
        double chi2 = 0.0;
        for (const int count : histogram) chi2 += (count - expected) * (count - expected) / expected;
        // 31 degrees of freedom: p = 0.001 at 61.1.
        CHECK(chi2 < 61.1);
    }
}

TEST_CASE("reflection sampling is finite and above the surface at roughness 0, 1e-4, 1 and grazing views") {
    uint32_t count = 0;
    for (const float roughness : {0.0f, 1e-4f, 0.01f, 0.22f, 0.5f, 1.0f}) {
        for (uint32_t i = 0; i < 4096; ++i) {
            // Normals and views from the noise; views may face away from
            // the normal (interpolated normals do) or graze it.
            const glm::vec2 a = shader::ggxNoise({i, 1u}, 11u);
            const glm::vec2 b = shader::ggxNoise({i, 2u}, 13u);
            const auto sphere = [](glm::vec2 u) {
                const float z = 1.0f - 2.0f * u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z));
                return glm::vec3(r * std::cos(6.2831853f * u.y), r * std::sin(6.2831853f * u.y), z);
            };
            const glm::vec3 n = sphere(a);
            glm::vec3 v = sphere(b);
            if (i % 4 == 0) v = glm::normalize(v - n * glm::dot(v, n) + n * 1e-5f);  // grazing
            const glm::vec3 l = shader::sampleReflection(n, v, roughness, shader::ggxNoise({i, 3u}, 17u));
            const glm::vec3 packed = shader::unpackRayDirection(shader::packRayDirection(l));
            INFO("roughness " << roughness << ", sample " << i);
            REQUIRE(std::isfinite(l.x));
            REQUIRE(std::isfinite(l.y));
            REQUIRE(std::isfinite(l.z));
            REQUIRE(std::abs(glm::length(l) - 1.0f) < 1e-4f);
            REQUIRE(glm::dot(packed, n) > 0.0f);
            ++count;
        }
    }
    CHECK(count == 6u * 4096u);
}

TEST_CASE("the noise is deterministic and walks a different sample every frame") {
    CHECK(shader::ggxNoise({3, 5}, 9) == shader::ggxNoise({3, 5}, 9));
    CHECK(shader::ggxNoise({3, 5}, 9) != shader::ggxNoise({3, 5}, 10));
    CHECK(shader::ggxNoise({3, 5}, 9) != shader::ggxNoise({5, 3}, 9));
}

TEST_CASE("appenders that open a group set the list's group count, in any order and for any range sizes") {
    // Appenders of 0 to 100 slots reserve their ranges in turn; only those
    // whose range holds a group's first slot raise the count
    // (rayListOpensGroup). A maximum does not depend on the order the
    // atomics land in.
    std::mt19937 rng(7);
    for (int trial = 0; trial < 2000; ++trial) {
        const int appenders = 1 + int(rng() % 40);
        uint32_t total = 0;
        std::vector<uint32_t> raises;
        for (int a = 0; a < appenders; ++a) {
            const uint32_t count = rng() % 101;
            const uint32_t begin = total;
            total += count;
            if (count != 0 && shader::rayListOpensGroup(begin, total)) {
                raises.push_back((total + shader::kRayListGroupSize - 1) / shader::kRayListGroupSize);
            }
        }
        uint32_t groups = 0;
        for (uint32_t r : raises) groups = std::max(groups, r);
        REQUIRE(groups == (total + shader::kRayListGroupSize - 1) / shader::kRayListGroupSize);
    }
    CHECK(shader::rayListOpensGroup(0, 1));
    CHECK(!shader::rayListOpensGroup(1, 64));
    CHECK(shader::rayListOpensGroup(63, 65));
    CHECK(!shader::rayListOpensGroup(64, 64));
}

TEST_CASE("a mirror floor (roughness 0) gives exactly the reflected view direction in every floor pixel") {
    test::GpuTest gpu;
    const std::vector<RayFrame> frames = generate(gpu, floorScene(0.0f), {0, 1});
    for (const RayFrame& f : frames) {
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("pixel " << x << ", " << y);
                const size_t i = f.at(x, y);
                if (!isFloor(y)) {
                    REQUIRE(f.classes[i] == shader::kPixelSky);
                    REQUIRE(f.rays[i].pixelFlags == shader::kNoRay);
                    continue;
                }
                REQUIRE(f.classes[i] >= shader::kPixelSslr);
                REQUIRE(f.rays[i].pixelFlags == shader::packRayPixel({x, y}, false));  // mirrors never share
                const glm::vec3 d = viewRay(x, y);
                const glm::vec3 expected(d.x, -d.y, d.z);  // reflected about the floor's normal +Y
                const glm::vec3 got = shader::unpackRayDirection(f.rays[i].direction);
                // 16-bit octahedral packing: ~5e-5 rad.
                REQUIRE(glm::length(got - expected) < 2e-4f);
            }
        }
    }
}

TEST_CASE("roughness above the cutoff gives no ray, and no tile is listed") {
    test::GpuTest gpu;
    const RayFrame f = generate(gpu, floorScene(0.5f), {0}).front();
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y);
            const size_t i = f.at(x, y);
            REQUIRE(f.classes[i] == (isFloor(y) ? shader::kPixelEnv : shader::kPixelSky));
            REQUIRE(f.rays[i].pixelFlags == shader::kNoRay);
        }
    }
    CHECK(f.sslrArgs == std::array<uint32_t, 6>{0, 1, 1, 0, 1, 1});
    CHECK(f.rtArgs == std::array<uint32_t, 6>{0, 1, 1, 0, 1, 1});
}

TEST_CASE("rough rays stay in the upper hemisphere of the normal over many frames, grazing rows included") {
    test::GpuTest gpu;
    passes::RayGenerationSettings settings;
    settings.reuse = false;  // every pixel samples its own direction
    std::vector<uint64_t> frameIndices;
    for (uint64_t i = 0; i < 16; ++i) frameIndices.push_back(i * 977);
    const std::vector<RayFrame> frames = generate(gpu, floorScene(0.2f), frameIndices, settings);
    uint32_t rays = 0;
    double meanCosine = 0.0;
    for (const RayFrame& f : frames) {
        for (uint32_t y = kSize / 2; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const shader::PackedRay& ray = f.rays[f.at(x, y)];
                INFO("pixel " << x << ", " << y);
                REQUIRE(ray.pixelFlags == shader::packRayPixel({x, y}, false));
                const glm::vec3 l = shader::unpackRayDirection(ray.direction);
                REQUIRE(l.y > 0.0f);
                meanCosine += l.y;
                ++rays;
            }
        }
    }
    CHECK(rays == 16u * kSize * kSize / 2);
    // The rays are rough, not mirrors: successive frames differ.
    CHECK(frames[0].rays[frames[0].at(10, 50)].direction != frames[1].rays[frames[1].at(10, 50)].direction);
    CHECK(meanCosine / rays > 0.0);
}

TEST_CASE("the class colours are written only for their debug view, and the rays are the same without them") {
    test::GpuTest gpu;
    const scene::Scene scene = floorScene(0.15f);
    const RayFrame with = generate(gpu, scene, {3})[0];
    Band band;
    band.debugOutputs = false;
    const RayFrame without = generate(gpu, scene, {3}, {}, band)[0];
    CHECK(without.classDebug.empty());
    REQUIRE(with.classDebug.size() == size_t(kSize) * kSize);
    // A colour per class (shaders/ray_generation/classify.comp's table,
    // stored as UNORM8: within one step of the value x 255).
    const std::array<glm::vec3, 5> colours = {glm::vec3(0.0f), glm::vec3(0.5f), glm::vec3(0.1f, 0.3f, 1.0f),
                                              glm::vec3(0.7f, 0.2f, 0.9f), glm::vec3(1.0f, 0.15f, 0.1f)};
    std::set<uint32_t> seen;
    for (size_t i = 0; i < with.classDebug.size(); ++i) {
        INFO("pixel " << i << " class " << with.classes[i]);
        REQUIRE(with.classes[i] < colours.size());
        const glm::vec3 got = glm::vec3(glm::vec3(with.classDebug[i])) / 255.0f;
        REQUIRE(glm::all(glm::lessThanEqual(glm::abs(got - colours[with.classes[i]]), glm::vec3(1.0f / 255.0f))));
        REQUIRE(with.classDebug[i].a == 255);
        seen.insert(with.classes[i]);
    }
    // The sky, the floor's hybrid band and its near RT rows.
    CHECK(seen.count(shader::kPixelSky) == 1);
    CHECK(seen.count(shader::kPixelHybrid) == 1);
    CHECK(seen.count(shader::kPixelRt) == 1);
    CHECK(with.classes == without.classes);
    for (size_t i = 0; i < with.rays.size(); ++i) {
        REQUIRE(with.rays[i].pixelFlags == without.rays[i].pixelFlags);
        REQUIRE(with.rays[i].direction == without.rays[i].direction);
    }
    CHECK(with.sslrArgs == without.sslrArgs);
    CHECK(with.rtArgs == without.rtArgs);
}

TEST_CASE("the same frame index gives the same rays") {
    test::GpuTest gpu;
    const std::vector<RayFrame> frames = generate(gpu, floorScene(0.15f), {5, 5});
    for (size_t i = 0; i < frames[0].rays.size(); ++i) {
        REQUIRE(frames[0].rays[i].pixelFlags == frames[1].rays[i].pixelFlags);
        REQUIRE(frames[0].rays[i].direction == frames[1].rays[i].direction);
    }
}

TEST_CASE("the distance split classes pixels, and ray lists and indirect args agree with a CPU count") {
    test::GpuTest gpu;
    passes::RayGenerationSettings settings;
    Band band;
    settings.rtMaxDistance = 3.0f;
    band.sslrMinDistance = 8.0f;
    const RayFrame f = generate(gpu, floorScene(0.05f), {0}, settings, band).front();
    constexpr uint32_t kTiles = kSize / shader::kTileSize;
    std::set<uint32_t> sslrLeaders, rtLeaders;
    std::array<uint32_t, shader::kPixelClassCount> counts{};
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const uint32_t c = f.classes[f.at(x, y)];
            REQUIRE(c < shader::kPixelClassCount);
            ++counts[c];
            const shader::PackedRay& ray = f.rays[f.at(x, y)];
            if (ray.pixelFlags == shader::packRayPixel({x, y}, false)) {
                if (c == shader::kPixelRt) rtLeaders.insert(ray.pixelFlags);
                if (c == shader::kPixelSslr || c == shader::kPixelHybrid) sslrLeaders.insert(ray.pixelFlags);
            }
            if (!isFloor(y)) continue;
            // The floor y = -1 along view ray d is at distance 1 / -d.y.
            const float distance = 1.0f / -viewRay(x, y).y;
            INFO("pixel " << x << ", " << y << " at distance " << distance);
            if (distance < 0.99f * 3.0f) REQUIRE(c == shader::kPixelRt);
            if (distance > 1.01f * 3.0f && distance < 0.99f * 8.0f) REQUIRE(c == shader::kPixelHybrid);
            if (distance > 1.01f * 8.0f) REQUIRE(c == shader::kPixelSslr);
        }
    }
    // All three ray classes occur, so the lists are really exercised.
    CHECK(counts[shader::kPixelRt] > 0);
    CHECK(counts[shader::kPixelHybrid] > 0);
    CHECK(counts[shader::kPixelSslr] > 0);
    CHECK(counts[shader::kPixelSky] == kSize * kSize / 2);
    CHECK(sslrLeaders.size() < kTiles * kTiles * shader::kTileSize * shader::kTileSize);
    // Each list holds each of its ray leaders once, with its own ray; the
    // dispatch covers it in 64-wide groups and the trace-rays command is
    // {count, 1, 1}.
    const auto checkList = [&](const char* what, const std::array<uint32_t, shader::kRayListArgsWords>& args,
                               const std::vector<shader::PackedRay>& list, const std::set<uint32_t>& leaders,
                               bool coneMarks) {
        INFO(what << " list");
        const uint32_t count = args[shader::kRayListCountOffset];
        REQUIRE(count == leaders.size());
        CHECK(args[0] == (count + shader::kRayListGroupSize - 1) / shader::kRayListGroupSize);
        CHECK(args[1] == 1);
        CHECK(args[2] == 1);
        CHECK(args[4] == 1);
        CHECK(args[5] == 1);
        std::set<uint32_t> listed;
        for (uint32_t k = 0; k < count; ++k) {
            const shader::PackedRay& entry = list[k];
            // SSLR entries of pixels at least RayGenerationSettings::coneRoughness
            // rough carry kRayCone; RT entries never do.
            if (!coneMarks) REQUIRE((entry.pixelFlags & shader::kRayCone) == 0u);
            listed.insert(entry.pixelFlags & ~shader::kRayCone);
            const glm::uvec2 p = shader::unpackRayPixel(entry.pixelFlags);
            REQUIRE(entry.direction == f.rays[f.at(p.x, p.y)].direction);
        }
        CHECK(listed == leaders);  // and, being sets of the listed size, no duplicates
    };
    checkList("SSLR", f.sslrArgs, f.sslrRays, sslrLeaders, true);
    checkList("RT", f.rtArgs, f.rtRays, rtLeaders, false);
}

TEST_CASE("rough 2x2 quads share their leader's ray, and the leader rotates with the frame") {
    test::GpuTest gpu;
    passes::RayGenerationSettings settings;
    Band band;
    band.sslrMinDistance = 1e9f;  // RT and hybrid only
    const std::vector<RayFrame> frames = generate(gpu, floorScene(0.2f), {0, 1, 2, 3}, settings, band);
    for (uint32_t frame = 0; frame < frames.size(); ++frame) {
        const RayFrame& f = frames[frame];
        const uint32_t lx = frame & 1u, ly = frame >> 1u;
        uint32_t sharedQuads = 0;
        for (uint32_t qy = kSize / 2; qy < kSize; qy += 2) {
            for (uint32_t qx = 0; qx < kSize; qx += 2) {
                const uint32_t c = f.classes[f.at(qx, qy)];
                bool sameClass = true;
                for (uint32_t k = 0; k < 4; ++k) sameClass &= f.classes[f.at(qx + (k & 1), qy + (k >> 1))] == c;
                if (!sameClass) continue;
                INFO("frame " << frame << ", quad " << qx << ", " << qy);
                const shader::PackedRay& leader = f.rays[f.at(qx + lx, qy + ly)];
                REQUIRE(leader.pixelFlags == shader::packRayPixel({qx + lx, qy + ly}, false));
                for (uint32_t k = 0; k < 4; ++k) {
                    const uint32_t x = qx + (k & 1), y = qy + (k >> 1);
                    if (x == qx + lx && y == qy + ly) continue;
                    const shader::PackedRay& ray = f.rays[f.at(x, y)];
                    REQUIRE(ray.pixelFlags == shader::packRayPixel({qx + lx, qy + ly}, true));
                    REQUIRE(ray.direction == leader.direction);
                }
                ++sharedQuads;
            }
        }
        CHECK(sharedQuads > kSize * kSize / 4 / 2 - 2 * kSize);
    }
}

TEST_CASE("below the reuse roughness every pixel keeps its own ray") {
    test::GpuTest gpu;
    const RayFrame f = generate(gpu, floorScene(0.05f), {0}).front();
    for (uint32_t y = kSize / 2; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            REQUIRE(f.rays[f.at(x, y)].pixelFlags == shader::packRayPixel({x, y}, false));
        }
    }
}

TEST_CASE("the checkerboard halves the smooth hybrid and RT rays: off squares share their row neighbour's ray") {
    test::GpuTest gpu;
    passes::RayGenerationSettings settings;
    Band band;
    settings.checkerboard = true;
    band.sslrMinDistance = 1e9f;  // RT and hybrid only
    const std::vector<RayFrame> frames = generate(gpu, floorScene(0.05f), {4, 5}, settings, band);
    const std::vector<RayFrame> plainFrames = generate(gpu, floorScene(0.05f), {4, 5});
    for (uint32_t k = 0; k < frames.size(); ++k) {
        const RayFrame& f = frames[k];
        const RayFrame& plain = plainFrames[k];
        const uint32_t frame = 4 + k;
        uint32_t leaders = 0, followers = 0;
        for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("frame " << frame << ", pixel " << x << ", " << y);
                const uint32_t c = f.classes[f.at(x, y)];
                REQUIRE((c == shader::kPixelHybrid || c == shader::kPixelRt));
                const shader::PackedRay& ray = f.rays[f.at(x, y)];
                const uint32_t nx = x ^ 1u;
                if (((x + y + frame) & 1u) == 0u || f.classes[f.at(nx, y)] != c) {
                    // An on square (or a neighbour of another class): its own ray, as without.
                    REQUIRE(ray.pixelFlags == shader::packRayPixel({x, y}, false));
                    REQUIRE(ray.direction == plain.rays[plain.at(x, y)].direction);
                    ++leaders;
                } else {
                    REQUIRE(ray.pixelFlags == shader::packRayPixel({nx, y}, true));
                    REQUIRE(ray.direction == f.rays[f.at(nx, y)].direction);
                    ++followers;
                }
            }
        }
        // About half the rays; the lists hold the leaders only.
        CHECK(followers > leaders / 2);
        CHECK(f.sslrArgs[shader::kRayListCountOffset] + f.rtArgs[shader::kRayListCountOffset] <
              plain.sslrArgs[shader::kRayListCountOffset] + plain.rtArgs[shader::kRayListCountOffset] * 3 / 4 + 1);
    }
    // The squares swap: a pixel that followed in one frame leads in the next.
    CHECK(frames[0].rays[frames[0].at(1, kSize - 2)].pixelFlags != frames[1].rays[frames[1].at(1, kSize - 2)].pixelFlags);
}

TEST_CASE("the ssr and rt modes send every traced pixel one way, and the RT list holds exactly the RT leaders") {
    test::GpuTest gpu;
    passes::RayGenerationSettings settings;
    Band band;
    settings.rtMaxDistance = 3.0f;
    band.sslrMinDistance = 8.0f;
    for (const passes::ReflectionMode mode : {passes::ReflectionMode::Ssr, passes::ReflectionMode::Rt}) {
        band.mode = mode;
        const uint32_t expected = mode == passes::ReflectionMode::Ssr ? shader::kPixelSslr : shader::kPixelRt;
        const RayFrame f = generate(gpu, floorScene(0.05f), {0}, settings, band).front();
        uint32_t traced = 0, leaders = 0;
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const uint32_t c = f.classes[f.at(x, y)];
                INFO("mode " << int(mode) << ", pixel " << x << ", " << y);
                if (!isFloor(y)) {
                    REQUIRE(c == shader::kPixelSky);
                    continue;
                }
                REQUIRE(c == expected);
                ++traced;
                leaders += f.rays[f.at(x, y)].pixelFlags == shader::packRayPixel({x, y}, false) ? 1u : 0u;
            }
        }
        CHECK(traced == kSize * kSize / 2);
        const uint32_t count = f.rtArgs[shader::kRayListCountOffset];
        if (mode == passes::ReflectionMode::Ssr) {
            CHECK(count == 0);
            CHECK(f.rtArgs[0] == 0);
            CHECK(f.sslrArgs[shader::kRayListCountOffset] == leaders);
        } else {
            CHECK(count == leaders);
            CHECK(f.rtArgs[0] == (count + shader::kRayListGroupSize - 1) / shader::kRayListGroupSize);
            CHECK(f.sslrArgs[shader::kRayListCountOffset] == 0);
        }
    }
}

TEST_CASE("hybrid pixels follow their tile's mode, an RT tile keeps the configured share hybrid, an RT-only tile none") {
    test::GpuTest gpu;
    passes::RayGenerationSettings settings;
    Band band;
    settings.rtMaxDistance = 0.0f;    // no RT band
    band.sslrMinDistance = 1e9f;  // no SSLR band: every floor pixel is hybrid before the feedback
    settings.rtToHybridShare = 0.25f;
    constexpr uint32_t kTiles = kSize / shader::kTileSize;
    // Columns of tiles: SSLR, hybrid, RT, RT-only, repeating.
    std::vector<uint32_t> modes(kTiles * kTiles);
    for (uint32_t t = 0; t < modes.size(); ++t) {
        modes[t] = std::array{shader::kTileModeSslr, shader::kTileModeHybrid, shader::kTileModeRt,
                              shader::kTileModeRtOnly}[(t % kTiles) % 4];
    }
    uint64_t rtTilePixels = 0, keptHybrid = 0, rtOnlyPixels = 0;
    const std::vector<RayFrame> frames =
        generate(gpu, floorScene(0.05f), {0, 1, 2, 3, 4, 5, 6, 7}, settings, band, modes);
    for (const RayFrame& f : frames) {
        for (uint32_t y = kSize / 2; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const uint32_t mode = modes[(y / shader::kTileSize) * kTiles + x / shader::kTileSize];
                const uint32_t c = f.classes[f.at(x, y)];
                INFO("pixel " << x << ", " << y << ", tile mode " << mode);
                if (mode == shader::kTileModeSslr) {
                    REQUIRE(c == shader::kPixelSslr);
                } else if (mode == shader::kTileModeHybrid) {
                    REQUIRE(c == shader::kPixelHybrid);
                } else if (mode == shader::kTileModeRtOnly) {
                    // The frame's SSLR does not pay: nothing stays hybrid.
                    REQUIRE(c == shader::kPixelRt);
                    ++rtOnlyPixels;
                } else {
                    REQUIRE((c == shader::kPixelRt || c == shader::kPixelHybrid));
                    ++rtTilePixels;
                    keptHybrid += c == shader::kPixelHybrid ? 1u : 0u;
                }
            }
        }
    }
    // 8 frames x 512 pixels of the RT columns' floor: the binomial standard
    // deviation of the share is ~0.007, so 0.03 is a four-sigma bound.
    REQUIRE(rtTilePixels > 3000);
    REQUIRE(rtOnlyPixels > 3000);
    const double share = double(keptHybrid) / double(rtTilePixels);
    CHECK(std::abs(share - 0.25) < 0.03);
}
