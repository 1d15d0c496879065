// The environment prefilter (passes/environment.h) and the one lookup every
// pass uses (glint/environment.glsl) on a real device, validation and
// synchronization validation on: a constant environment stays constant at
// every level with irradiance pi L; a two-hemisphere environment matches a
// CPU quadrature of the same GGX-weighted integral; roughness 0 returns the
// source texels; NaN and Inf texels never reach the output; the procedural
// sky allocates nothing; the G-buffer's sky pixels show the image.
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/environment.h"
#include "glint/passes/gbuffer.h"
#include "glint/scene/image_io.h"
#include "glint/scene/scene.h"

#include "glint/environment_shared.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/packing.hpp>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr float kPi = glm::pi<float>();

// A scene whose environment is an equirectangular RGBA32F image of
// `width` x width/2 texels, texel (x, y) = f(x, y).
scene::Scene environmentScene(uint32_t width, const std::function<glm::vec3(uint32_t, uint32_t)>& f) {
    scene::Scene s;
    s.name = "environment-test";
    s.environment.kind = scene::EnvironmentKind::EquirectangularImage;
    scene::Texture& image = s.environment.image;
    image.name = "test.hdr";
    image.width = width;
    image.height = width / 2;
    image.format = scene::TextureFormat::Rgba32Float;
    image.rgba32f.resize(size_t(image.width) * image.height * 4);
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            const glm::vec3 c = f(x, y);
            float* t = &image.rgba32f[(size_t(y) * image.width + x) * 4];
            t[0] = c.x;
            t[1] = c.y;
            t[2] = c.z;
            t[3] = 1.0f;
        }
    }
    return s;
}

// One level of the prefiltered image, decoded.
std::vector<glm::vec3> readLevel(gpu::Context& ctx, const passes::EnvironmentMap& map, uint32_t level) {
    const std::vector<std::byte> bytes =
        gpu::readbackImage(ctx, map.radiance(), VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, level);
    std::vector<glm::vec3> texels(bytes.size() / 8);
    for (size_t i = 0; i < texels.size(); ++i) {
        uint16_t h[4];
        std::memcpy(h, bytes.data() + i * 8, 8);
        texels[i] = {glm::unpackHalf1x16(h[0]), glm::unpackHalf1x16(h[1]), glm::unpackHalf1x16(h[2])};
    }
    return texels;
}

struct ProbeResult {
    glm::vec3 radiance;
    glm::vec3 irradiance;
};

// environmentRadiance(dir, roughness) and environmentIrradiance(dir) as the
// shaders compute them (shaders/test/environment_probe.comp).
std::vector<ProbeResult> probe(gpu::Context& ctx, const passes::EnvironmentMap& map,
                               const std::vector<glm::vec4>& queries) {
    constexpr VkShaderStageFlags kCs = VK_SHADER_STAGE_COMPUTE_BIT;
    const gpu::Pipeline pipeline = gpu::createComputePipeline(
        ctx, {"test/environment_probe.comp",
              {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kCs},
               {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kCs},
               {2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, kCs},
               {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kCs}},
              4, "environment_test.probe"});
    const gpu::Sampler sampler = passes::createEnvironmentSampler(ctx, "environment_test.sampler");
    const shader::SceneLighting lighting = map.lighting({});
    const gpu::Buffer queryBuffer = gpu::createBufferWithData(
        ctx, {queries.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal,
              "environment_test.queries"},
        queries.data());
    const gpu::Buffer lightingBuffer = gpu::createBufferWithData(
        ctx, {sizeof(lighting), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal,
              "environment_test.lighting"},
        &lighting);
    const gpu::Buffer results(ctx, {queries.size() * 2 * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                    gpu::MemoryUsage::Readback, "environment_test.results"});
    const uint32_t count = uint32_t(queries.size());
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "environment probe", [&](VkCommandBuffer cmd) {
        pipeline.bind(cmd);
        gpu::PushDescriptors(pipeline)
            .storageBuffer(0, queryBuffer)
            .storageBuffer(1, lightingBuffer)
            .sampledImage(2, map.radiance().view(), sampler.handle(), VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL)
            .storageBuffer(3, results)
            .push(ctx, cmd);
        pipeline.pushConstants(cmd, count);
        vkCmdDispatch(cmd, (count + 63) / 64, 1, 1);
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    });
    const auto values = results.mappedSpan<glm::vec4>();
    std::vector<ProbeResult> out(queries.size());
    for (size_t i = 0; i < out.size(); ++i) {
        out[i] = {glm::vec3(values[2 * i]), glm::vec3(values[2 * i + 1])};
    }
    return out;
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

float relativeError(glm::vec3 value, glm::vec3 expected) {
    const glm::vec3 e = glm::abs(value - expected) / glm::max(glm::abs(expected), glm::vec3(1e-6f));
    return std::max({e.x, e.y, e.z});
}

// The texel-centre direction of texel (x, y) of a width x height level.
glm::vec3 texelDirection(uint32_t x, uint32_t y, uint32_t width, uint32_t height) {
    return scene::equirectDirection({(float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height)});
}

// The split-sum prefilter's integral for N = V = R, by quadrature around N:
//   int L(l) D(N.h) (N.l) dl / int D(N.h) (N.l) dl,   h = normalize(N + l),
// with l at polar angle t from N (N.h = cos(t / 2)) and azimuth p, for an
// environment of radiance `upper` above the horizon and `lower` below.
glm::dvec3 twoHemisphereReference(glm::dvec3 n, double roughness, glm::dvec3 upper, glm::dvec3 lower) {
    const double alpha = roughness * roughness;
    const double a2 = alpha * alpha;
    const glm::dvec3 ref = std::abs(n.y) < 0.99 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 t = glm::normalize(glm::cross(ref, n));
    const glm::dvec3 b = glm::cross(n, t);
    constexpr int kPolar = 2048;
    constexpr int kAzimuth = 512;
    const double dt = glm::half_pi<double>() / kPolar;
    glm::dvec3 sum(0.0);
    double weight = 0.0;
    for (int i = 0; i < kPolar; ++i) {
        const double theta = (i + 0.5) * dt;
        const double noh = std::cos(0.5 * theta);
        const double d = noh * noh * (a2 - 1.0) + 1.0;
        const double w = a2 / (glm::pi<double>() * d * d) * std::cos(theta) * std::sin(theta);
        // The share of the ring at this polar angle above the horizon.
        int above = 0;
        for (int j = 0; j < kAzimuth; ++j) {
            const double phi = (j + 0.5) * glm::two_pi<double>() / kAzimuth;
            const double y = std::cos(theta) * n.y + std::sin(theta) * (std::cos(phi) * t.y + std::sin(phi) * b.y);
            above += y > 0.0 ? 1 : 0;
        }
        const double share = double(above) / kAzimuth;
        sum += w * (share * upper + (1.0 - share) * lower);
        weight += w;
    }
    return sum / weight;
}

} // namespace

TEST_CASE("a constant environment prefilters to the same constant at every level, with irradiance pi L") {
    test::GpuTest gpu;
    const glm::vec3 radiance(0.5f, 1.25f, 3.0f);
    const scene::Scene scene = environmentScene(128, [&](uint32_t, uint32_t) { return radiance; });
    passes::EnvironmentMap map(gpu.ctx(), scene);
    REQUIRE(map.hasImage());
    const passes::EnvironmentStats& stats = map.stats();
    CHECK(stats.width == 128);
    CHECK(stats.height == 64);
    CHECK(stats.levels == 5);  // 128, 64, 32, 16, 8 texels wide
    for (uint32_t level = 0; level < stats.levels; ++level) {
        const std::vector<glm::vec3> texels = readLevel(gpu.ctx(), map, level);
        REQUIRE(texels.size() == size_t(128 >> level) * (64 >> level));
        float worst = 0.0f;
        for (const glm::vec3& t : texels) worst = std::max(worst, relativeError(t, radiance));
        CHECK_MESSAGE(worst <= 1e-3f, "level " << level << ": worst relative error " << worst);
    }
    std::vector<glm::vec4> queries;
    for (const glm::vec3 d : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(1, 0, 0), glm::vec3(0.3f, 0.4f, -0.8f),
                              glm::vec3(-0.5f, -0.2f, 0.6f)}) {
        for (const float roughness : {0.0f, 0.3f, 0.6f, 1.0f}) {
            queries.emplace_back(glm::normalize(d), roughness);
        }
    }
    const std::vector<ProbeResult> results = probe(gpu.ctx(), map, queries);
    for (size_t i = 0; i < results.size(); ++i) {
        INFO("direction " << queries[i].x << " " << queries[i].y << " " << queries[i].z << ", roughness "
                          << queries[i].w);
        CHECK(relativeError(results[i].radiance, radiance) <= 1e-3f);
        // glint/brdf.glsl's convention: a constant radiance L gives E = pi L.
        CHECK(relativeError(results[i].irradiance, kPi * radiance) <= 1e-3f);
    }
}

TEST_CASE("a two-hemisphere environment prefilters to the GGX-weighted integral of a CPU quadrature") {
    test::GpuTest gpu;
    const glm::vec3 upper(2.0f, 1.0f, 0.5f);
    const glm::vec3 lower(0.1f, 0.2f, 0.4f);
    const uint32_t width = 256;
    const scene::Scene scene =
        environmentScene(width, [&](uint32_t, uint32_t y) { return y < width / 4 ? upper : lower; });
    passes::EnvironmentMap map(gpu.ctx(), scene);
    const uint32_t levels = map.stats().levels;
    REQUIRE(levels == 6);  // 256 .. 8 texels wide: roughness 0, 0.2, .., 1
    const float maxLod = float(levels - 1);
    // Errors are measured against the step between the hemispheres, which
    // is what the prefilter spreads. Filtered importance sampling reads
    // box-filtered mips as wide as each sample's share of the lobe (plus
    // Krivanek and Colbert's one level of bias), so the edge is blurred by
    // about a sample's footprint beyond the exact lobe (measured: 2.6% of
    // the step at worst, at roughness 0.8-1 near the horizon).
    constexpr float kTolerance = 0.04f;
    const float step = glm::length(upper - lower);
    float worst = 0.0f;
    for (uint32_t level = 1; level < levels; ++level) {
        const uint32_t w = width >> level;
        const uint32_t h = w / 2;
        const std::vector<glm::vec3> texels = readLevel(gpu.ctx(), map, level);
        const double roughness = shader::environmentRoughnessOfLevel(float(level), maxLod);
        // Rows from the zenith to the nadir, at two longitudes.
        for (const uint32_t y : {0u, h / 8, h / 4, h / 2 - 1, h / 2, h / 2 + 1, 3 * h / 4, h - 1}) {
            for (const uint32_t x : {0u, w / 3}) {
                const glm::vec3 n = texelDirection(x, y, w, h);
                const glm::vec3 expected =
                    glm::vec3(twoHemisphereReference(glm::dvec3(n), roughness, glm::dvec3(upper), glm::dvec3(lower)));
                const glm::vec3 got = texels[size_t(y) * w + x];
                const float error = glm::length(got - expected) / step;
                worst = std::max(worst, error);
                CHECK_MESSAGE(error <= kTolerance, "level " << level << " (roughness " << roughness << ") texel " << x
                                                            << "," << y << " n.y " << n.y << ": got " << got.x << " "
                                                            << got.y << " " << got.z << ", expected " << expected.x
                                                            << " " << expected.y << " " << expected.z);
            }
        }
    }
    MESSAGE("two hemispheres: worst error " << worst << " of the step");
    // Irradiance: facing up the cosine lobe sees only the upper hemisphere
    // (E = pi A), facing down only the lower (pi B), facing the horizon half
    // of each (pi (A + B) / 2). Nine SH bands cannot hold the step exactly:
    // they ring by up to a tenth of it.
    const std::vector<glm::vec4> queries = {{0, 1, 0, 0}, {0, -1, 0, 0}, {1, 0, 0, 0}, {0, 0, -1, 0}};
    const std::vector<ProbeResult> results = probe(gpu.ctx(), map, queries);
    const glm::vec3 expected[4] = {kPi * upper, kPi * lower, kPi * 0.5f * (upper + lower),
                                   kPi * 0.5f * (upper + lower)};
    for (size_t i = 0; i < results.size(); ++i) {
        const float error = glm::length(results[i].irradiance - expected[i]) / (kPi * step);
        CHECK_MESSAGE(error <= 0.1f, "irradiance " << i << ": " << error << " of the step");
    }
}

TEST_CASE("a mirror lookup returns the source texel") {
    test::GpuTest gpu;
    const auto texel = [](uint32_t x, uint32_t y) {
        const uint32_t h = (x * 73856093u) ^ (y * 19349663u);
        return glm::vec3(float(h % 97) / 8.0f, float((h / 97) % 89) / 16.0f + 0.01f, float((h / 8633) % 83) * 4.0f);
    };
    const scene::Scene scene = environmentScene(64, texel);
    passes::EnvironmentMap map(gpu.ctx(), scene);
    const std::vector<glm::vec3> level0 = readLevel(gpu.ctx(), map, 0);
    REQUIRE(level0.size() == 64 * 32);
    std::vector<glm::vec4> queries;
    float worst = 0.0f;
    for (uint32_t y = 0; y < 32; ++y) {
        for (uint32_t x = 0; x < 64; ++x) {
            worst = std::max(worst, relativeError(level0[y * 64 + x], texel(x, y)));
            if ((x * 7 + y * 3) % 11 == 0) queries.emplace_back(texelDirection(x, y, 64, 32), 0.0f);
        }
    }
    // Half floats keep 11 bits: 2^-11 relative.
    CHECK_MESSAGE(worst <= 1e-3f, "level 0 against the source: " << worst);
    // The lookup at roughness 0 in a texel's direction is that texel: half
    // precision (2e-3 of its brightest channel) plus the bilinear weight its
    // neighbours get from the float error of the direction's round trip
    // through uv (below 1e-4 of the brightest neighbour).
    const std::vector<ProbeResult> results = probe(gpu.ctx(), map, queries);
    size_t q = 0;
    for (uint32_t y = 0; y < 32; ++y) {
        for (uint32_t x = 0; x < 64; ++x) {
            if ((x * 7 + y * 3) % 11 != 0) continue;
            const glm::vec3 expected = texel(x, y);
            const glm::vec3 error = glm::abs(results[q].radiance - expected);
            const float brightest = std::max({expected.x, expected.y, expected.z});
            float neighbours = 0.0f;
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    const glm::vec3 n = texel(uint32_t(int(x) + dx + 64) % 64, uint32_t(std::clamp(int(y) + dy, 0, 31)));
                    neighbours = std::max({neighbours, n.x, n.y, n.z});
                }
            }
            CHECK_MESSAGE(std::max({error.x, error.y, error.z}) <= 2e-3f * brightest + 1e-4f * neighbours,
                          "texel " << x << "," << y << ": " << results[q].radiance.x << " " << results[q].radiance.y
                                   << " " << results[q].radiance.z << ", expected " << expected.x << " " << expected.y
                                   << " " << expected.z);
            ++q;
        }
    }
}

TEST_CASE("NaN and Inf texels in the source do not make the prefiltered environment non-finite") {
    test::GpuTest gpu;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const scene::Scene scene = environmentScene(64, [&](uint32_t x, uint32_t y) {
        if (x == 10 && y == 5) return glm::vec3(nan, 1.0f, 1.0f);
        if (x == 40 && y == 20) return glm::vec3(inf, -inf, 1.0f);
        if (x == 20 && y == 16) return glm::vec3(1e30f, 1.0f, -5.0f);  // beyond half floats, negative
        if (y == 0) return glm::vec3(nan);                              // a whole row at the pole
        return glm::vec3(0.5f);
    });
    passes::EnvironmentMap map(gpu.ctx(), scene);
    for (uint32_t level = 0; level < map.stats().levels; ++level) {
        const std::vector<glm::vec3> texels = readLevel(gpu.ctx(), map, level);
        size_t bad = 0;
        for (const glm::vec3& t : texels) {
            bad += finite(t) && glm::all(glm::greaterThanEqual(t, glm::vec3(0.0f))) ? 0 : 1;
        }
        CHECK_MESSAGE(bad == 0, "level " << level << ": " << bad << " non-finite or negative texels");
    }
    const std::vector<glm::vec3> level0 = readLevel(gpu.ctx(), map, 0);
    CHECK(level0[5 * 64 + 10] == glm::vec3(0.0f, 1.0f, 1.0f));
    CHECK(level0[20 * 64 + 40] == glm::vec3(0.0f, 0.0f, 1.0f));
    CHECK(level0[16 * 64 + 20] == glm::vec3(65504.0f, 1.0f, 0.0f));
    for (const glm::vec4& sh : map.irradianceSh()) CHECK(finite(glm::vec3(sh)));
    const std::vector<ProbeResult> results =
        probe(gpu.ctx(), map, {{0, 1, 0, 0.5f}, {0, -1, 0, 1.0f}, {0.6f, 0, 0.8f, 0.2f}, {-0.6f, 0.8f, 0, 0.0f}});
    for (const ProbeResult& r : results) {
        CHECK(finite(r.radiance));
        CHECK(finite(r.irradiance));
    }
}

TEST_CASE("the procedural sky allocates no environment image and keeps its analytic lighting") {
    test::GpuTest gpu;
    scene::Scene scene;
    scene.environment.intensity = 1.5f;
    passes::EnvironmentMap map(gpu.ctx(), scene);
    CHECK_FALSE(map.hasImage());
    CHECK(map.stats().levels == 0);
    CHECK_THROWS(map.radiance());
    const shader::SceneLighting lighting = map.lighting({});
    const shader::SceneLighting direct = passes::sceneLighting(scene, passes::LightingSettings{});
    CHECK(std::memcmp(&lighting, &direct, sizeof(lighting)) == 0);
    CHECK(lighting.environment.x == 0.0f);
    rg::Graph graph;
    CHECK_FALSE(passes::importEnvironment(graph, map).valid());
    CHECK_FALSE(map.update());
    // A new image is seen and prefiltered; going back to the sky frees it.
    scene = environmentScene(32, [](uint32_t, uint32_t) { return glm::vec3(1.0f); });
    CHECK(map.update());
    CHECK(map.hasImage());
    CHECK(map.stats().prefilters == 1);
    CHECK_FALSE(map.update());
    scene.environment.kind = scene::EnvironmentKind::ProceduralSky;
    CHECK(map.update());
    CHECK_FALSE(map.hasImage());
}

TEST_CASE("a 512x256 environment prefilters in seconds at most") {
    test::GpuTest gpu;
    const scene::Scene scene = environmentScene(512, [](uint32_t x, uint32_t y) {
        return glm::vec3(float(x % 17) * 0.3f, float(y % 13) * 0.2f, x == 100 && y == 40 ? 5000.0f : 0.5f);
    });
    passes::EnvironmentMap map(gpu.ctx(), scene);
    MESSAGE("512x256 prefilter: " << map.stats().prefilterMs << " ms, " << map.stats().levels << " levels");
    CHECK(map.stats().prefilterMs < 5000.0);
}

TEST_CASE("the G-buffer's sky pixels show an environment loaded from an .hdr file") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    // Upper hemisphere one colour, lower another (RGBE holds these
    // exactly); a scene with no geometry.
    const glm::vec3 upper(0.25f, 0.5f, 1.0f);
    const glm::vec3 lower(0.5f, 0.25f, 0.125f);
    std::vector<float> rgb;
    for (uint32_t y = 0; y < 32; ++y) {
        for (uint32_t x = 0; x < 64; ++x) {
            const glm::vec3 c = y < 16 ? upper : lower;
            rgb.insert(rgb.end(), {c.x, c.y, c.z});
        }
    }
    const std::filesystem::path dir = std::filesystem::path(GLINT_TEST_OUT_DIR);
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "two_hemispheres.hdr").string();
    REQUIRE(stbi_write_hdr(path.c_str(), 64, 32, 3, rgb.data()));
    scene::Scene scene;
    scene.environment = scene::loadEquirectangularEnvironment(path);
    scene.environment.intensity = 2.0f;
    passes::EnvironmentMap map(ctx, scene);
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    const scene::Camera camera = test::testCamera();
    const uint32_t size = camera.resolution.x;
    const rg::HostReadback readback(ctx, VkDeviceSize(size) * size * 8, "environment_test.lit");
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const rg::Texture env = passes::importEnvironment(graph, map);
    REQUIRE(env.valid());
    map.bind(resources, env);
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera, map.lighting({}), env}, {});
    readback.copy(graph, resources, gbuf.lit);
    executor.run(graph.compile(executor.compileOptions()), resources);
    executor.waitIdle();
    const uint16_t* halves = readback.as<uint16_t>().data();
    const auto lit = [&](uint32_t x, uint32_t y) {
        const uint16_t* h = halves + (size_t(y) * size + x) * 4;
        return glm::vec3(glm::unpackHalf1x16(h[0]), glm::unpackHalf1x16(h[1]), glm::unpackHalf1x16(h[2]));
    };
    // The camera looks along -Z with a 90-degree field: the top rows see
    // the upper hemisphere, the bottom rows the lower, times the intensity.
    size_t nonFinite = 0;
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) nonFinite += finite(lit(x, y)) ? 0 : 1;
    }
    CHECK(nonFinite == 0);
    for (const uint32_t x : {0u, size / 2, size - 1}) {
        CHECK(relativeError(lit(x, 2), 2.0f * upper) <= 2e-3f);
        CHECK(relativeError(lit(x, size - 3), 2.0f * lower) <= 2e-3f);
    }
}
