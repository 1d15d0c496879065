// The composite and the debug views (passes/composite.h) on a real device,
// validation on, behind the real G-buffer, with the reflections and the
// views' sources uploaded by the test (the harness: temporal_harness.h).
// Known answers: the composite matches a CPU reference of the documented
// maths (the environment BRDF, exposure, the tonemaps and sRGB); debug
// views map known values to known colours and refuse sources they cannot
// show. A skipped case times temporal and composite at 1920x1080.
#include "support/gpu_test.h"
#include "temporal_harness.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/verify.h"
#include "glint/passes/composite.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/temporal.h"

#include <glm/gtc/type_precision.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

using namespace glint;
using namespace glint::temporal_test;

// ---------------------------------------------------------------- composite

namespace {

std::vector<glm::u8vec4> bytes4(const gpu::Buffer& b) {
    std::vector<glm::u8vec4> out(kPixels);
    std::memcpy(out.data(), b.mapped(), kPixels * 4);
    return out;
}

// Independent CPU versions of the documented maths (passes/composite.h).
float srgbEncode(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

float srgbDecode(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

glm::vec3 khronosPbrNeutral(glm::vec3 c) {
    const float x = std::min({c.r, c.g, c.b});
    const float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
    c -= offset;
    const float peak = std::max({c.r, c.g, c.b});
    const float start = 0.76f;
    if (peak < start) return c;
    const float d = 1.0f - start;
    const float newPeak = 1.0f - d * d / (peak + d - start);
    c *= newPeak / peak;
    const float g = 1.0f - 1.0f / (0.15f * (peak - newPeak) + 1.0f);
    return glm::mix(c, glm::vec3(newPeak), g);
}

glm::vec3 acesFitted(glm::vec3 x) {
    return glm::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

glm::vec3 tonemap(glm::vec3 c, passes::Tonemap op) {
    c = glm::max(c, glm::vec3(0.0f));
    switch (op) {
    case passes::Tonemap::AcesFitted: return acesFitted(c);
    case passes::Tonemap::Clamp: return glm::clamp(c, 0.0f, 1.0f);
    default: return glm::clamp(khronosPbrNeutral(c), 0.0f, 1.0f);
    }
}

glm::ivec3 toBytes(glm::vec3 display) {
    return {int(std::lround(255.0f * srgbEncode(display.r))), int(std::lround(255.0f * srgbEncode(display.g))),
            int(std::lround(255.0f * srgbEncode(display.b)))};
}

// Karis 2014, EnvBRDFApprox.
glm::vec3 envBrdf(glm::vec3 f0, float roughness, float NoV) {
    const glm::vec4 r =
        roughness * glm::vec4(-1.0f, -0.0275f, -0.572f, 0.022f) + glm::vec4(1.0f, 0.0425f, 1.04f, -0.04f);
    const float a004 = std::min(r.x * r.x, std::exp2(-9.28f * NoV)) * r.x + r.y;
    const float scale = -1.04f * a004 + r.z;
    const float bias = 1.04f * a004 + r.w;
    return f0 * scale + bias;
}

bool near(glm::u8vec4 got, glm::ivec3 expected, int tolerance = 1) {
    return std::abs(int(got.r) - expected.r) <= tolerance && std::abs(int(got.g) - expected.g) <= tolerance &&
           std::abs(int(got.b) - expected.b) <= tolerance && got.a == 255;
}

// One composite per settings, with and without reflections, all in one
// graph over one G-buffer.
struct CompositeRun {
    std::vector<std::vector<glm::u8vec4>> withReflections;     // per settings
    std::vector<std::vector<glm::u8vec4>> withoutReflections;  // per settings
    std::vector<glm::vec4> lit;
    std::vector<glm::u8vec4> albedo;
    std::vector<glm::u8vec4> roughnessMetal;
};

CompositeRun runComposite(const scene::Scene& scene, const std::vector<glm::vec4>& reflections,
                          const std::vector<passes::CompositeSettings>& settings) {
    test::GpuTest gpu;  // one device per run, as runTemporal
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::CompositePipelines pipelines(ctx);
    Staging staging(ctx);
    const scene::Camera camera = testCamera();
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    const rg::Texture refl = uploadTexture(graph, resources, staging, "test.reflections",
                                           VK_FORMAT_R32G32B32A32_SFLOAT, reflections.data());
    std::vector<const gpu::Buffer*> with, without;
    for (size_t i = 0; i < settings.size(); ++i) {
        const passes::CompositeOutputs a =
            passes::addCompositePass(graph, pipelines, {gbuf, refl, camera}, settings[i]);
        const passes::CompositeOutputs b = passes::addCompositePass(graph, pipelines, {gbuf, {}, camera}, settings[i]);
        REQUIRE(a.width == kSize);
        with.push_back(&readTexture(graph, resources, staging, a.color, passes::kCompositeFormat,
                                    "with" + std::to_string(i)));
        without.push_back(&readTexture(graph, resources, staging, b.color, passes::kCompositeFormat,
                                       "without" + std::to_string(i)));
    }
    const gpu::Buffer& lit = readTexture(graph, resources, staging, gbuf.lit, passes::kGBufferLitFormat, "lit");
    const gpu::Buffer& albedo =
        readTexture(graph, resources, staging, gbuf.albedo, passes::kGBufferAlbedoFormat, "albedo");
    const gpu::Buffer& rm = readTexture(graph, resources, staging, gbuf.roughnessMetal,
                                        passes::kGBufferRoughnessMetalFormat, "roughness_metal");
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const auto report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    executor.run(plan, resources);
    executor.waitIdle();
    CompositeRun run{{}, {}, halves(lit, 4), bytes4(albedo), bytes4(rm)};
    for (const gpu::Buffer* b : with) run.withReflections.push_back(bytes4(*b));
    for (const gpu::Buffer* b : without) run.withoutReflections.push_back(bytes4(*b));
    return run;
}

} // namespace

TEST_CASE("the composite adds the reflection times the environment BRDF, then exposure, tonemap and sRGB") {
    const scene::Scene scene = wallScene(material(0.4f, 0.3f, {0.8f, 0.5f, 0.2f}));
    // Reflections everywhere but the left quarter (a = 0 there: lit only).
    std::vector<glm::vec4> reflections(kPixels);
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            reflections[at(x, y)] = x < kSize / 4 ? glm::vec4(5.0f, 5.0f, 5.0f, 0.0f)
                                                  : glm::vec4(0.6f + 0.02f * float(y), 0.9f, 1.2f, 1.0f);
        }
    }
    std::vector<passes::CompositeSettings> settings;
    for (const passes::Tonemap op :
         {passes::Tonemap::KhronosPbrNeutral, passes::Tonemap::AcesFitted, passes::Tonemap::Clamp}) {
        for (const float exposure : {1.0f, 3.0f}) settings.push_back({exposure, op});
    }
    const CompositeRun run = runComposite(scene, reflections, settings);
    for (size_t k = 0; k < settings.size(); ++k) {
        CAPTURE(int(settings[k].tonemap));
        CAPTURE(settings[k].exposure);
        for (const bool withReflections : {true, false}) {
            CAPTURE(withReflections);
            const std::vector<glm::u8vec4>& image =
                withReflections ? run.withReflections[k] : run.withoutReflections[k];
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    INFO("pixel " << x << ", " << y);
                    const size_t i = at(x, y);
                    glm::vec3 color = run.lit[i];
                    if (withReflections && reflections[i].w > 0.0f) {
                        // The wall point under the pixel, seen from the origin.
                        const glm::vec2 ndc = test::pixelNdc(x, y);
                        const glm::vec3 p(ndc.x * kWallDistance, -ndc.y * kWallDistance, -kWallDistance);
                        const float NoV = glm::dot(glm::vec3(0, 0, 1), glm::normalize(-p));
                        const glm::vec3 albedo(srgbDecode(run.albedo[i].r / 255.0f),
                                               srgbDecode(run.albedo[i].g / 255.0f),
                                               srgbDecode(run.albedo[i].b / 255.0f));
                        const float roughness = run.roughnessMetal[i].r / 255.0f;
                        const float metallic = run.roughnessMetal[i].g / 255.0f;
                        const float reflectance = run.roughnessMetal[i].b / 255.0f;
                        const glm::vec3 f0 = glm::mix(glm::vec3(0.16f * reflectance * reflectance), albedo, metallic);
                        color += glm::vec3(reflections[i]) * envBrdf(f0, roughness, NoV);
                    }
                    const glm::ivec3 expected = toBytes(tonemap(color * settings[k].exposure, settings[k].tonemap));
                    REQUIRE_MESSAGE(near(image[i], expected),
                                    "got " << int(image[i].r) << " " << int(image[i].g) << " " << int(image[i].b)
                                           << ", expected " << expected.r << " " << expected.g << " "
                                           << expected.b);
                }
            }
        }
    }
}

TEST_CASE("the environment BRDF fit gives the split-sum values it is known for") {
    // Sanity of the CPU reference itself: at normal incidence a smooth
    // surface reflects F0 (scale ~1, bias ~0), at grazing angles it tends
    // to 1, and a rough surface reflects less at grazing angles.
    const glm::vec3 f0(0.04f);
    CHECK(envBrdf(f0, 0.0f, 1.0f).x == doctest::Approx(0.04f).epsilon(0.1));
    CHECK(envBrdf(f0, 0.0f, 0.0f).x > 0.9f);
    CHECK(envBrdf(f0, 1.0f, 0.0f).x < envBrdf(f0, 0.0f, 0.0f).x);
}

// ---------------------------------------------------------------- debug views

namespace {

struct DebugViewJob {
    VkFormat format;
    const void* texels;
    passes::DebugViewSettings settings;
    uint32_t side = kSize;  // the source's; the view is kSize x kSize
};

// Every job's source uploaded and shown, all in one graph.
std::vector<std::vector<glm::u8vec4>> runDebugViews(const std::vector<DebugViewJob>& jobs) {
    test::GpuTest gpu;  // one device per run, as runTemporal
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::CompositePipelines pipelines(ctx);
    Staging staging(ctx);
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    std::vector<const gpu::Buffer*> colors;
    for (size_t i = 0; i < jobs.size(); ++i) {
        const std::string name = "test.source" + std::to_string(i);
        const rg::Texture source =
            uploadTexture(graph, resources, staging, name, jobs[i].format, jobs[i].texels, jobs[i].side);
        const passes::CompositeOutputs out =
            passes::addDebugViewPass(graph, pipelines, source, kSize, kSize, jobs[i].settings);
        colors.push_back(&readTexture(graph, resources, staging, out.color, passes::kCompositeFormat,
                                      "color" + std::to_string(i)));
    }
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const auto report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    executor.run(plan, resources);
    executor.waitIdle();
    std::vector<std::vector<glm::u8vec4>> out;
    for (const gpu::Buffer* c : colors) out.push_back(bytes4(*c));
    return out;
}

std::vector<glm::u8vec4> runDebugView(VkFormat format, const void* texels, const passes::DebugViewSettings& settings) {
    return runDebugViews({{format, texels, settings}}).front();
}

// The viridis stops of passes/composite.h, as bytes.
const std::array<glm::ivec3, 5> kViridis = {glm::ivec3(68, 1, 84), glm::ivec3(59, 82, 139), glm::ivec3(33, 145, 140),
                                            glm::ivec3(94, 201, 98), glm::ivec3(253, 231, 37)};

glm::ivec3 viridis(float t) {
    const float s = std::clamp(t, 0.0f, 1.0f) * 4.0f;
    const int i = std::min(int(std::floor(s)), 3);
    const glm::vec3 c = glm::mix(glm::vec3(kViridis[i]), glm::vec3(kViridis[i + 1]), s - float(i));
    return {int(std::lround(c.r)), int(std::lround(c.g)), int(std::lround(c.b))};
}

} // namespace

TEST_CASE("a scalar debug view maps values through viridis over [min, max], and NaN and Inf to magenta") {
    constexpr float kMin = 2.0f, kMax = 10.0f;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<float> values(kPixels);
    std::vector<glm::ivec3> expected(kPixels);
    const std::array<float, 9> probes = {kMin - 5.0f, kMin, 3.0f, 4.0f, 6.0f, 8.5f, kMax, kMax + 100.0f, 7.3f};
    for (size_t i = 0; i < kPixels; ++i) {
        const float v = probes[i % probes.size()];
        values[i] = v;
        expected[i] = viridis((v - kMin) / (kMax - kMin));
    }
    values[100] = nan;
    values[101] = inf;
    values[102] = -inf;
    for (const size_t i : {100, 101, 102}) expected[i] = {255, 0, 255};
    passes::DebugViewSettings settings;
    settings.kind = passes::DebugViewKind::Scalar;
    settings.minValue = kMin;
    settings.maxValue = kMax;
    const std::vector<glm::u8vec4> out = runDebugView(VK_FORMAT_R32_SFLOAT, values.data(), settings);
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i << " value " << values[i]);
        REQUIRE(near(out[i], expected[i]));
    }
    // The stops themselves, exactly.
    CHECK(near(out[1], kViridis[0], 0));
    CHECK(near(out[3], kViridis[1], 0));
    CHECK(near(out[4], kViridis[2], 0));
    CHECK(near(out[6], kViridis[4], 0));
}

TEST_CASE("an unsigned-integer texture shows through the scalar view") {
    std::vector<uint32_t> values(kPixels);
    for (size_t i = 0; i < kPixels; ++i) values[i] = uint32_t(i % 5);
    passes::DebugViewSettings settings;
    settings.kind = passes::DebugViewKind::Scalar;
    settings.minValue = 0.0f;
    settings.maxValue = 4.0f;
    const std::vector<glm::u8vec4> out = runDebugView(VK_FORMAT_R32_UINT, values.data(), settings);
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i);
        REQUIRE(near(out[i], kViridis[values[i]], 0));
    }
}

TEST_CASE("a colour debug view tonemaps HDR values; a raw view passes display colours through") {
    std::vector<glm::vec4> hdr(kPixels);
    for (size_t i = 0; i < kPixels; ++i) {
        hdr[i] = glm::vec4(0.05f + 0.01f * float(i % 97), 0.3f, 4.0f * float(i % 7) / 7.0f, 1.0f);
    }
    std::vector<glm::u8vec4> classes(kPixels);
    for (size_t i = 0; i < kPixels; ++i) {
        classes[i] = glm::u8vec4(uint8_t(i * 7), uint8_t(255 - i), uint8_t(i / 16), 200);
    }
    const std::array<passes::Tonemap, 2> ops = {passes::Tonemap::KhronosPbrNeutral, passes::Tonemap::AcesFitted};
    std::vector<DebugViewJob> jobs;
    for (const passes::Tonemap op : ops) {
        passes::DebugViewSettings settings;
        settings.kind = passes::DebugViewKind::Color;
        settings.exposure = 2.0f;
        settings.tonemap = op;
        jobs.push_back({VK_FORMAT_R32G32B32A32_SFLOAT, hdr.data(), settings});
    }
    passes::DebugViewSettings raw;
    raw.kind = passes::DebugViewKind::Raw;
    jobs.push_back({VK_FORMAT_R8G8B8A8_UNORM, classes.data(), raw});
    const std::vector<std::vector<glm::u8vec4>> out = runDebugViews(jobs);
    for (size_t k = 0; k < ops.size(); ++k) {
        for (size_t i = 0; i < kPixels; ++i) {
            INFO("tonemap " << int(ops[k]) << " texel " << i);
            REQUIRE(near(out[k][i], toBytes(tonemap(glm::vec3(hdr[i]) * 2.0f, ops[k]))));
        }
    }
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i);
        REQUIRE(near(out[2][i], glm::ivec3(classes[i].r, classes[i].g, classes[i].b), 0));
    }
}

TEST_CASE("a source of half the view's size shows each texel as 2x2 pixels") {
    // As the SSLR pyramid's first level (half the lit colour's size) shows.
    constexpr uint32_t kHalf = kSize / 2;
    std::vector<glm::u8vec4> texels(size_t(kHalf) * kHalf);
    for (size_t i = 0; i < texels.size(); ++i) {
        texels[i] = glm::u8vec4(uint8_t(i * 7), uint8_t(255 - i), uint8_t(i / 16), 255);
    }
    passes::DebugViewSettings raw;
    raw.kind = passes::DebugViewKind::Raw;
    const std::vector<glm::u8vec4> out = runDebugViews({{VK_FORMAT_R8G8B8A8_UNORM, texels.data(), raw, kHalf}}).front();
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y);
            const glm::u8vec4 t = texels[size_t(y / 2) * kHalf + x / 2];
            REQUIRE(near(out[at(x, y)], glm::ivec3(t.r, t.g, t.b), 0));
        }
    }
}

TEST_CASE("the G-buffer's depth shows through the scalar view") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const scene::Scene scene = wallScene(material(0.5f, 0.0f));
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::CompositePipelines pipelines(ctx);
    Staging staging(ctx);
    const scene::Camera camera = testCamera();
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    passes::DebugViewSettings settings;
    settings.kind = passes::DebugViewKind::Scalar;
    settings.maxValue = 0.1f;
    const passes::CompositeOutputs out = passes::addDebugViewPass(graph, pipelines, gbuf.depth, kSize, kSize, settings);
    const gpu::Buffer& color = readTexture(graph, resources, staging, out.color, passes::kCompositeFormat, "color");
    executor.run(graph.compile(executor.compileOptions()), resources);
    executor.waitIdle();
    const std::vector<glm::u8vec4> bytes = bytes4(color);
    // Reversed Z with an infinite far plane: depth = near / view depth, so
    // the wall is at 0.1 / 5 = 0.02, a fifth of the range.
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i);
        REQUIRE(near(bytes[i], viridis(0.2f)));
    }
}

TEST_CASE("a debug view refuses sources it cannot show, naming them") {
    test::GpuTest gpu;
    passes::CompositePipelines pipelines(gpu.ctx());
    rg::Graph graph;
    const rg::Texture ids = graph.createTexture("signed_ids", {.width = kSize, .height = kSize,
                                                               .format = VK_FORMAT_R32_SINT});
    CHECK_THROWS_WITH_AS(passes::addDebugViewPass(graph, pipelines, ids, kSize, kSize),
                         doctest::Contains("signed_ids"), gpu::GpuError);
    const rg::Texture small = graph.createTexture("small", {.width = 4, .height = 4,
                                                            .format = VK_FORMAT_R32_SFLOAT});
    CHECK_THROWS_WITH_AS(passes::addDebugViewPass(graph, pipelines, small, kSize, kSize),
                         doctest::Contains("small"), gpu::GpuError);
    // Half the view's size on one side only is neither.
    const rg::Texture narrow = graph.createTexture("narrow", {.width = kSize / 2, .height = kSize,
                                                              .format = VK_FORMAT_R32_SFLOAT});
    CHECK_THROWS_WITH_AS(passes::addDebugViewPass(graph, pipelines, narrow, kSize, kSize),
                         doctest::Contains("narrow"), gpu::GpuError);
    rg::Graph other;
    CHECK_THROWS_AS(passes::addDebugViewPass(other, pipelines, small, 4, 4), gpu::GpuError);
}

// Not a check: GPU times of the passes at 1920x1080 on a wall of roughness
// 0.15 (both reprojections and the spatial filter active) under a moving
// camera. Run with --no-skip.
TEST_CASE("GPU time of temporal and composite at 1920x1080" * doctest::skip()) {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    scene::Scene scene = wallScene(material(0.15f, 1.0f));
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::TemporalPipelines temporal(ctx);
    passes::CompositePipelines composite(ctx);
    scene::Camera camera = testCamera();
    camera.resolution = {1920, 1080};
    camera.reset({{0, 0, 0}, {0, 0, -1}, {0, 1, 0}}, 0);
    for (uint64_t frame = 0; frame < 16; ++frame) {
        if (frame > 0) camera.advance({{0.01f * float(frame), 0, 0}, {0.01f * float(frame), 0, -1}, {0, 1, 0}}, frame);
        rg::Graph graph(executor.queueCaps());
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
        struct Fill {
            rg::Texture radiance, hit;
        };
        const Fill& fill = graph.addPass<Fill>(
            "fill", rg::Queue::Graphics,
            [&](rg::Builder& b, Fill& d) {
                const auto make = [&](const char* name, VkFormat format) {
                    return b.write(b.createTexture(name, {.width = 1920, .height = 1080, .format = format}),
                                   rg::Access::TransferDst);
                };
                d.radiance = make("radiance", VK_FORMAT_R16G16B16A16_SFLOAT);
                d.hit = make("hit", VK_FORMAT_R32_SFLOAT);
            },
            [](const Fill& d, rg::PassContext& pc) {
                const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                const VkClearColorValue radiance{{0.5f, 0.6f, 0.7f, 1.0f}};
                const VkClearColorValue hit{{2.0f, 0.0f, 0.0f, 0.0f}};
                vkCmdClearColorImage(pc.cmd(), pc.image(d.radiance).handle(), pc.layout(d.radiance), &radiance, 1,
                                     &range);
                vkCmdClearColorImage(pc.cmd(), pc.image(d.hit).handle(), pc.layout(d.hit), &hit, 1, &range);
            });
        const passes::TemporalOutputs stable =
            passes::addTemporalPass(graph, temporal, {gbuf, fill.radiance, fill.hit, camera, frame});
        const passes::CompositeOutputs image =
            passes::addCompositePass(graph, composite, {gbuf, stable.resolved, camera});
        graph.markOutput(image.color);
        executor.run(graph.compile(executor.compileOptions()));
    }
    executor.waitIdle();
    for (const rg::PassTiming& t : executor.timings()) {
        MESSAGE(t.name << ": " << (t.milliseconds ? *t.milliseconds : -1.0) << " ms");
    }
}
