// Screen-space reflections (passes/sslr.h) on a real device behind the real
// G-buffer and ray generation passes, validation on. A mirror floor faces a
// red wall in front of the camera: floor pixels whose reflection meets the
// wall find it within one texel of the analytic hit, with the wall's lit
// colour and full confidence; reflections passing over the wall into the
// sky get zero confidence and go to the RT list, whose length and args
// match a count on the CPU; nothing is NaN.
#include "sslr_harness.h"

using namespace glint;
using namespace glint::sslr_test;

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
