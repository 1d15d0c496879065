// Integrate (passes/integrate.h) on a real device behind the real G-buffer
// and ray generation passes, validation on (the harness:
// integrate_harness.h). Radiance, hit distance, the debug colour and the
// tile counters are checked against hand-made traces, including with NaN
// and Inf in the traces and with each trace absent.
#include "integrate_harness.h"

using namespace glint;
using namespace glint::integrate_test;

// ---------------------------------------------------------------------------
// GPU: integrate
// ---------------------------------------------------------------------------

TEST_CASE("integrate takes each pixel's reflection from the source its class and confidences call for") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(0, false);
    const Presence all;
    const Frame f = harness.run(testCamera(), 0, traces, all);
    const Coverage cov = checkFrame(f, traces, all, harness.lighting());
    // The first frame carries nothing: the counters hold this frame's counts.
    checkCounters(f, traces, std::vector<uint32_t>(kTiles * kTiles, 0u));
    CHECK(f.reprojected == std::vector<uint32_t>(kTiles * kTiles, 0u));

    // The scene exercised every rule.
    using namespace shader;
    CHECK(cov.count(kPixelSky, kSourceSky) > 0);
    CHECK(cov.count(kPixelEnv, kSourceEnvironment) > 0);
    CHECK(cov.count(kPixelSslr, kSourceSslr) > 0);
    CHECK(cov.count(kPixelSslr, kSourceFallback) > 0);
    CHECK(cov.count(kPixelSslr, kSourceRt) == 0);  // beyond the BVH: RT never answers
    CHECK(cov.count(kPixelHybrid, kSourceSslr) > 0);
    CHECK(cov.count(kPixelHybrid, kSourceRt) > 0);
    CHECK(cov.count(kPixelHybrid, kSourceFallback) > 0);
    CHECK(cov.count(kPixelRt, kSourceRt) > 0);
    CHECK(cov.count(kPixelRt, kSourceFallback) > 0);
    CHECK(cov.count(kPixelRt, kSourceSslr) == 0);
    CHECK(cov.followers > 50);
    CHECK(cov.followerSslr > 0);
    CHECK(cov.followerRt > 0);
    CHECK(cov.sslrHitDistances > 50);
    // Cone traces' hits taken alone are marked noise-free, followers' too.
    CHECK(cov.noiseFree > 20);
}

TEST_CASE("without its debug output integrate writes the same reflections, and no source colours") {
    test::GpuTest gpu;
    const Traces traces = makeTraces(0, false);
    const Presence all;
    Harness with(gpu, floorScene());
    const Frame a = with.run(testCamera(), 0, traces, all);
    RunOptions options;
    options.debugOutputs = false;
    Harness without(gpu, floorScene());
    const Frame b = without.run(testCamera(), 0, traces, all, options);
    REQUIRE(a.source.size() == kPixels);
    CHECK(b.source.empty());
    CHECK(std::memcmp(a.radiance.data(), b.radiance.data(), kPixels * sizeof(glm::vec4)) == 0);
    CHECK(a.hitDistance == b.hitDistance);
    CHECK(a.counters == b.counters);
}

TEST_CASE("integrate lets no NaN or Inf from the traces through; poisoned traces count as misses") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(1, true);
    const Presence all;
    const Frame f = harness.run(testCamera(), 1, traces, all);
    checkFrame(f, traces, all, harness.lighting());
    checkCounters(f, traces, std::vector<uint32_t>(kTiles * kTiles, 0u));
}

TEST_CASE("integrate without RT, without SSLR, without either and without feedback binds only what exists") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(2, false);
    uint64_t frame = 0;
    for (const Presence present : {Presence{true, false, true}, Presence{false, true, true},
                                   Presence{false, false, true}, Presence{true, true, false},
                                   Presence{false, true, false}}) {
        INFO("sslr " << present.sslr << " rt " << present.rt << " feedback " << present.feedback);
        const Frame f = harness.run(testCamera(), frame++, traces, present);
        const Coverage cov = checkFrame(f, traces, present, harness.lighting());
        if (!present.rt) CHECK(cov.count(shader::kPixelRt, shader::kSourceRt) == 0);
        if (!present.sslr) CHECK(cov.count(shader::kPixelHybrid, shader::kSourceSslr) == 0);
        if (present.feedback && !present.sslr) {
            // No SSLR, no counts; the carried counts still rotate.
            for (uint32_t tile = 0; tile < kTiles * kTiles; ++tile) {
                CHECK(f.counters[tile] == shader::rotateFeedback(f.reprojected[tile], 0, 0));
            }
        }
    }
}

TEST_CASE("a probe that renders as rt counts SSLR's hits and takes the ray tracer's reflection") {
    // FeedbackSettings::probesRenderAsRt: SSLR handed every hybrid ray on.
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(0, false);
    Presence countsOnly;
    countsOnly.sslrCountsOnly = true;
    const Frame f = harness.run(testCamera(), 0, traces, countsOnly);
    const Coverage cov = checkFrame(f, traces, countsOnly, harness.lighting());
    // The same counts as a frame that uses SSLR's hits.
    checkCounters(f, traces, std::vector<uint32_t>(kTiles * kTiles, 0u));
    CHECK(f.frameHitsWord > shader::kFeedbackFrameHitsStart);
    using namespace shader;
    CHECK(cov.count(kPixelHybrid, kSourceSslr) == 0);
    CHECK(cov.count(kPixelHybrid, kSourceRt) > 0);
    // Beyond the BVH's reach SSLR still stands alone.
    CHECK(cov.count(kPixelSslr, kSourceSslr) > 0);
}

TEST_CASE("a lower confidence threshold trusts SSLR alone more often") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(0, false);
    const Presence noFeedback{true, true, false};
    // The same frame index twice: the same classes and rays.
    const Frame strict = harness.run(testCamera(), 0, traces, noFeedback);
    const Coverage strictCov = checkFrame(strict, traces, noFeedback, harness.lighting());
    const Presence all;
    const Frame lax = harness.run(testCamera(), 0, traces, all, {.confidenceThreshold = 0.4f});
    REQUIRE(lax.classes == strict.classes);
    const Coverage laxCov = checkFrame(lax, traces, all, harness.lighting(), 0.4f);
    // The counters count a hit at the same threshold (the first feedback
    // frame: nothing carried).
    checkCounters(lax, traces, std::vector<uint32_t>(kTiles * kTiles, 0u), 0.4f);
    // Hybrid pixels at confidence 0.5 now keep SSLR instead of going to RT.
    CHECK(laxCov.count(shader::kPixelHybrid, shader::kSourceSslr) >
          strictCov.count(shader::kPixelHybrid, shader::kSourceSslr));
    CHECK(laxCov.count(shader::kPixelHybrid, shader::kSourceRt) <
          strictCov.count(shader::kPixelHybrid, shader::kSourceRt));
}

TEST_CASE("behind the real SSLR pass, confident wall hits are SSLR with the wall's distance from the floor") {
    test::GpuTest gpu;
    Harness harness(gpu, mirrorWallScene());
    passes::SslrPipelines sslrPipelines(gpu.ctx());
    RunOptions options;
    options.realSslr = &sslrPipelines;
    options.rays.rtMaxDistance = 0.0f;  // every floor pixel hybrid
    options.sslrMinDistance = 1e9f;
    const Traces none = makeTraces(0, false);  // RT absent: only the SSLR fields matter, and those are replaced
    const Presence ssr{true, false, true};
    const Frame f = harness.run(testCamera(), 4, none, ssr, options);
    uint32_t checked = 0;
    for (uint32_t y = kSize / 2; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const size_t i = at(x, y);
            if (f.classes[i] != shader::kPixelHybrid) continue;
            INFO("pixel " << x << ", " << y);
            const shader::PackedRay& ray = f.rays[i];
            const glm::uvec2 leader = shader::unpackRayPixel(ray.pixelFlags);
            const size_t li = at(leader.x, leader.y);
            const float confidence = f.sslr.sslrConfidence[li];
            REQUIRE(finite(f.radiance[i]));
            REQUIRE(std::isfinite(f.hitDistance[i]));
            if (confidence < 0.9f) continue;
            REQUIRE(f.source[i] == sourceColour(shader::kSourceSslr));
            REQUIRE(glm::vec3(f.radiance[i]) == glm::vec3(f.sslr.sslrRadiance[li]));
            // The wall point at the hit texel's centre (the wall is the
            // plane z = -6), measured from this pixel's floor point...
            const glm::vec2 uv(f.sslr.sslrHit[li]);
            const glm::vec2 texel = glm::vec2(shader::sslrHitTexel(uv, glm::uvec2(kSize))) + 0.5f;
            const glm::vec2 ndc = texel / float(kSize) * 2.0f - 1.0f;
            const glm::vec3 wall(ndc.x * kMirrorWallDistance, -ndc.y * kMirrorWallDistance, -kMirrorWallDistance);
            const float expected = glm::length(wall - floorPoint(x, y));
            REQUIRE(std::abs(f.hitDistance[i] - expected) <= 1e-3f * expected);
            // ... which is the mirror path's length to within the texel's
            // footprint on the wall (6 / 32 units).
            const glm::vec3 p = floorPoint(x, y);
            const glm::vec3 d = glm::normalize(p);
            const glm::vec3 mirrored(d.x, -d.y, d.z);
            const float analytic = (-kMirrorWallDistance - p.z) / mirrored.z;
            const float footprint = 2.0f * kMirrorWallDistance / float(kSize);
            REQUIRE(std::abs(f.hitDistance[i] - analytic) <= footprint + 0.02f * analytic);
            ++checked;
        }
    }
    CHECK(checked > 200);
    checkCounters(f, f.sslr, f.reprojected);
    uint32_t hits = 0;
    for (const uint32_t c : f.counters) hits += shader::feedbackHits(c);
    CHECK(hits > 50);
}

TEST_CASE("integrate refuses an RT radiance without its hit distance") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    passes::IntegratePipelines pipelines(ctx);
    rg::Graph graph;
    passes::IntegrateInputs in;
    in.gbuffer.width = in.gbuffer.height = kSize;
    in.rays.width = in.rays.height = kSize;
    in.rtRadiance =
        graph.createTexture("rt", {.width = kSize, .height = kSize, .format = VK_FORMAT_R16G16B16A16_SFLOAT});
    CHECK_THROWS_WITH_AS(passes::addIntegratePass(graph, pipelines, in), doctest::Contains("hit distance"),
                         gpu::GpuError);
}
