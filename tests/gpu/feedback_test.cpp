// The feedback (passes/feedback.h): the counter packing, the mode decision
// and the SSLR gate's rules on the CPU (the shaders' own header,
// glint/feedback_shared.h); on a real device (the harness:
// integrate_harness.h), counters carried by a known camera motion land in
// the expected tiles, off-screen content carries nothing, tile modes follow
// the counts, two frames rotate through the history, and the frame's sum
// of SSLR hits decides whether SSLR is tried.
#include "integrate_harness.h"

using namespace glint;
using namespace glint::integrate_test;

// ---------------------------------------------------------------------------
// CPU: the shared header
// ---------------------------------------------------------------------------

TEST_CASE("feedback counters pack four 8-bit counts and saturate at 255") {
    const uint32_t c = shader::packFeedback(1, 2, 3, 4);
    CHECK(c == 0x04030201u);
    CHECK(shader::feedbackHits(c) == 1u);
    CHECK(shader::feedbackMisses(c) == 2u);
    CHECK(shader::feedbackPreviousHits(c) == 3u);
    CHECK(shader::feedbackPreviousMisses(c) == 4u);
    const uint32_t s = shader::packFeedback(300, 255, 1000, 64);
    CHECK(shader::feedbackHits(s) == 255u);
    CHECK(shader::feedbackMisses(s) == 255u);
    CHECK(shader::feedbackPreviousHits(s) == 255u);
    CHECK(shader::feedbackPreviousMisses(s) == 64u);
    // A tile of 8x8 pixels never saturates in one frame.
    CHECK(shader::kTileSize * shader::kTileSize <= shader::kFeedbackCountMax);
}

TEST_CASE("rotating a counter moves this frame's counts behind the new ones and drops the oldest") {
    const uint32_t lastFrame = shader::packFeedback(10, 20, 30, 40);
    const uint32_t next = shader::rotateFeedback(lastFrame, 5, 6);
    CHECK(next == shader::packFeedback(5, 6, 10, 20));
    // Two rotations forget the first frame entirely.
    CHECK(shader::rotateFeedback(next, 0, 0) == shader::packFeedback(0, 0, 5, 6));
}

TEST_CASE("tile modes: no evidence is hybrid, only hits SSLR, only misses RT, mixed hybrid") {
    using shader::decideTileMode;
    using shader::packFeedback;
    CHECK(decideTileMode(0u, 1, 0.0f, 0.0f) == shader::kTileModeHybrid);
    CHECK(decideTileMode(packFeedback(5, 0, 0, 0), 1, 0.0f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(0, 0, 7, 0), 1, 0.0f, 0.0f) == shader::kTileModeSslr);  // last frame only
    CHECK(decideTileMode(packFeedback(3, 0, 4, 0), 1, 0.0f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(0, 6, 0, 2), 1, 0.0f, 0.0f) == shader::kTileModeRt);
    CHECK(decideTileMode(packFeedback(0, 0, 0, 1), 1, 0.0f, 0.0f) == shader::kTileModeRt);
    CHECK(decideTileMode(packFeedback(4, 1, 0, 0), 1, 0.0f, 0.0f) == shader::kTileModeHybrid);
    // Mixed across the two frames is mixed.
    CHECK(decideTileMode(packFeedback(3, 0, 0, 2), 1, 0.0f, 0.0f) == shader::kTileModeHybrid);
    // The knobs: too few rays is no evidence; a tolerated stray ray.
    CHECK(decideTileMode(packFeedback(2, 0, 1, 0), 4, 0.0f, 0.0f) == shader::kTileModeHybrid);
    CHECK(decideTileMode(packFeedback(2, 0, 2, 0), 4, 0.0f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(19, 1, 0, 0), 1, 0.05f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(18, 2, 0, 0), 1, 0.05f, 0.0f) == shader::kTileModeHybrid);
    CHECK(decideTileMode(packFeedback(1, 19, 0, 0), 1, 0.0f, 0.05f) == shader::kTileModeRt);
}

TEST_CASE("the feedback probe pixel lies in its tile and the image, and moves from frame to frame") {
    const glm::uvec2 size(61, 37);  // partial tiles at the right and bottom
    const glm::uvec2 tiles((size + shader::kTileSize - 1u) / shader::kTileSize);
    for (uint32_t ty = 0; ty < tiles.y; ++ty) {
        for (uint32_t tx = 0; tx < tiles.x; ++tx) {
            std::map<uint32_t, int> seen;
            for (uint32_t frame = 0; frame < 64; ++frame) {
                const glm::uvec2 p = shader::feedbackProbePixel({tx, ty}, frame, size);
                REQUIRE(p.x / shader::kTileSize == tx);
                REQUIRE(p.y / shader::kTileSize == ty);
                REQUIRE(p.x < size.x);
                REQUIRE(p.y < size.y);
                ++seen[p.y * size.x + p.x];
            }
            CHECK(seen.size() > 1);
        }
    }
}

// ---------------------------------------------------------------------------
// GPU: feedback
// ---------------------------------------------------------------------------

TEST_CASE("two frames rotate the counters through the history: last frame's counts move behind this frame's") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Presence all;
    const scene::Camera camera = testCamera();  // still: every tile carries its own counter
    const Traces first = makeTraces(0, false);
    const Frame f0 = harness.run(camera, 0, first, all, {.followTileModes = true});
    checkCounters(f0, first, std::vector<uint32_t>(kTiles * kTiles, 0u));
    const Traces second = makeTraces(3, false);
    const Frame f1 = harness.run(camera, 1, second, all, {.followTileModes = true});
    CHECK(f1.reprojected == f0.counters);
    checkCounters(f1, second, f0.counters);
    checkFrame(f1, second, all, harness.lighting());
    // And the modes of frame 1 follow frame 0's two frames of counts.
    uint32_t previousHalves = 0;
    for (uint32_t tile = 0; tile < kTiles * kTiles; ++tile) {
        CHECK(f1.tileModes[tile] == shader::decideTileMode(f0.counters[tile], 1, 0.0f, 0.0f));
        const uint32_t c = f1.counters[tile];
        previousHalves += shader::feedbackPreviousHits(c) + shader::feedbackPreviousMisses(c);
    }
    CHECK(previousHalves > 0);
}

TEST_CASE("a known camera motion carries each tile's counter from where its content was; off screen gives 0") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    std::vector<uint32_t> counters(kTiles * kTiles);
    for (uint32_t tile = 0; tile < counters.size(); ++tile) {
        counters[tile] = shader::packFeedback(tile % kTiles, tile / kTiles, 7, tile + 1);
    }
    scene::Camera camera = testCamera();
    harness.runFeedback(camera, 0, counters);
    // Up 1 and right 2: at the wall's distance 4 a world unit is 8 pixels,
    // one tile, so last frame the content of tile (tx, ty) was in tile
    // (tx + 2, ty - 1) whichever pixel of the tile is probed.
    const glm::vec3 moved(2.0f, 1.0f, 0.0f);
    camera.advance({moved, moved + glm::vec3(0, 0, -1), {0, 1, 0}}, 1);
    const auto f = harness.runFeedback(camera, 1, counters);
    for (uint32_t y = 0; y < kSize; y += 5) {
        for (uint32_t x = 0; x < kSize; x += 3) {
            INFO("pixel " << x << ", " << y);
            REQUIRE(std::abs(f.motion[at(x, y)].x - 16.0f) < 1e-2f);
            REQUIRE(std::abs(f.motion[at(x, y)].y + 8.0f) < 1e-2f);
        }
    }
    for (uint32_t ty = 0; ty < kTiles; ++ty) {
        for (uint32_t tx = 0; tx < kTiles; ++tx) {
            INFO("tile " << tx << ", " << ty);
            const bool onScreen = tx + 2 < kTiles && ty >= 1;
            const uint32_t expected = onScreen ? counters[(ty - 1) * kTiles + tx + 2] : 0u;
            CHECK(f.reprojected[ty * kTiles + tx] == expected);
            CHECK(f.tileModes[ty * kTiles + tx] == shader::decideTileMode(expected, 1, 0.0f, 0.0f));
        }
    }
    // The camera stays where it moved: no motion, every tile keeps its own.
    camera.advance({moved, moved + glm::vec3(0, 0, -1), {0, 1, 0}}, 2);
    CHECK(harness.runFeedback(camera, 2, counters).reprojected == counters);
    // A reset (a camera cut) carries nothing: every tile without evidence,
    // hybrid.
    camera.advance({moved, moved + glm::vec3(0, 0, -1), {0, 1, 0}}, 3);
    const auto cut = harness.runFeedback(camera, 3, counters, {}, true);
    CHECK(cut.reprojected == std::vector<uint32_t>(counters.size(), 0u));
    CHECK(cut.tileModes == std::vector<uint32_t>(counters.size(), shader::kTileModeHybrid));
}

TEST_CASE("tile modes follow the carried counts and the feedback settings") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    using shader::packFeedback;
    const std::array<uint32_t, 9> cases = {0u,
                                           packFeedback(5, 0, 0, 0),
                                           packFeedback(3, 0, 4, 0),
                                           packFeedback(0, 6, 0, 2),
                                           packFeedback(4, 1, 0, 0),
                                           packFeedback(3, 0, 0, 2),
                                           packFeedback(0, 0, 7, 0),
                                           packFeedback(19, 1, 0, 0),
                                           packFeedback(1, 19, 0, 0)};
    std::vector<uint32_t> counters(kTiles * kTiles);
    for (uint32_t tile = 0; tile < counters.size(); ++tile) counters[tile] = cases[(tile * 5) % cases.size()];
    const scene::Camera camera = testCamera();
    harness.runFeedback(camera, 0, counters);
    passes::FeedbackSettings strict;
    passes::FeedbackSettings tolerant;
    tolerant.minRays = 6;
    tolerant.sslrMissFraction = 0.05f;
    tolerant.rtHitFraction = 0.05f;
    passes::FeedbackSettings off;
    off.adaptive = false;
    uint64_t frame = 1;
    for (const passes::FeedbackSettings& settings : {strict, tolerant, off}) {
        const auto f = harness.runFeedback(camera, frame++, counters, settings);
        CHECK(f.reprojected == counters);
        std::map<uint32_t, int> modes;
        for (uint32_t tile = 0; tile < counters.size(); ++tile) {
            INFO("tile " << tile << " counter " << counters[tile] << " minRays " << settings.minRays);
            const uint32_t expected =
                settings.adaptive ? shader::decideTileMode(counters[tile], settings.minRays,
                                                           settings.sslrMissFraction, settings.rtHitFraction)
                                  : shader::kTileModeHybrid;
            CHECK(f.tileModes[tile] == expected);
            ++modes[f.tileModes[tile]];
        }
        if (settings.adaptive) {
            CHECK(modes.size() == 3);  // every mode occurs
        } else {
            CHECK(modes.size() == 1);
        }
    }
}

TEST_CASE("SSLR probe frames: one per block of the interval, on both parities, at most 2 x interval - 1 apart") {
    for (const uint32_t interval : {2u, 8u, 13u}) {
        INFO("interval " << interval);
        std::optional<uint32_t> last;
        std::array<uint32_t, 2> parity{};
        std::set<uint32_t> offsets;
        for (uint32_t block = 0; block < 200; ++block) {
            uint32_t probes = 0;
            for (uint32_t k = 0; k < interval; ++k) {
                const uint32_t frame = block * interval + k;
                if (!shader::feedbackProbeFrame(frame, interval)) continue;
                ++probes;
                ++parity[frame % 2];
                offsets.insert(k);
                if (last) CHECK(frame - *last <= 2 * interval - 1);
                last = frame;
            }
            CHECK(probes == 1);
        }
        // Not tied to the frame's parity (the samples time alternate
        // frames) nor to one place in the block.
        CHECK(parity[0] > 20);
        CHECK(parity[1] > 20);
        CHECK(offsets.size() == interval);
    }
    for (uint32_t frame = 0; frame < 16; ++frame) CHECK(shader::feedbackProbeFrame(frame, 1));
}

TEST_CASE("SSLR pays with enough of last frame's hits, on probe frames, and without evidence") {
    const uint32_t start = shader::kFeedbackFrameHitsStart;
    CHECK(shader::sslrPays(0u, 100u, false, false));  // a new pair: no frame wrote the word
    CHECK(!shader::sslrPays(start + 99u, 100u, false, false));
    CHECK(shader::sslrPays(start + 100u, 100u, false, false));
    CHECK(shader::sslrPays(start, 100u, true, false));   // a probe frame
    CHECK(shader::sslrPays(start, 100u, false, true));   // a reset
    CHECK(shader::sslrPays(start, 0u, false, false));    // the gate off
}

TEST_CASE("a frame after one whose SSLR hits fell short sends every tile RT-only, except on probe frames") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    const scene::Camera camera = testCamera();  // still: every tile carries its own counter
    // Every tile's own counts say SSLR; only the frame's sum decides.
    const std::vector<uint32_t> tiles(kTiles * kTiles, shader::packFeedback(5, 0, 0, 0));
    const passes::FeedbackSettings settings;
    const uint32_t minHits = uint32_t(std::ceil(double(settings.sslrMinHitShare) * kSize * kSize));
    REQUIRE(minHits > 1);
    const auto withHits = [&](uint32_t hits) {
        std::vector<uint32_t> c = tiles;
        c.push_back(shader::kFeedbackFrameHitsStart + hits);
        return c;
    };
    std::vector<uint64_t> probes, others;
    for (uint64_t frame = 1; probes.size() < 2 || others.size() < 6; ++frame) {
        (shader::feedbackProbeFrame(uint32_t(frame), settings.sslrProbeInterval) ? probes : others).push_back(frame);
    }
    const auto all = [&](uint32_t mode) { return std::vector<uint32_t>(tiles.size(), mode); };
    // Each call's modes follow what the call before it left as last frame's counters.
    harness.runFeedback(camera, 0, withHits(minHits - 1), settings);
    CHECK(harness.runFeedback(camera, others[0], withHits(minHits), settings).tileModes ==
          all(shader::kTileModeRtOnly));
    CHECK(harness.runFeedback(camera, others[1], withHits(minHits - 1), settings).tileModes ==
          all(shader::kTileModeSslr));
    CHECK(harness.runFeedback(camera, probes[0], withHits(0), settings).tileModes == all(shader::kTileModeSslr));
    CHECK(harness.runFeedback(camera, others[2], withHits(minHits - 1), settings).tileModes ==
          all(shader::kTileModeRtOnly));
    // A reset carries no counters and no evidence: hybrid, not RT.
    CHECK(harness.runFeedback(camera, others[3], withHits(minHits - 1), settings, true).tileModes ==
          all(shader::kTileModeHybrid));
    // The gate off (share 0), and the feedback off.
    passes::FeedbackSettings always = settings;
    always.sslrMinHitShare = 0.0f;
    CHECK(harness.runFeedback(camera, others[4], withHits(minHits - 1), always).tileModes ==
          all(shader::kTileModeSslr));
    passes::FeedbackSettings off = settings;
    off.adaptive = false;
    CHECK(harness.runFeedback(camera, others[5], withHits(0), off).tileModes == all(shader::kTileModeHybrid));
}

TEST_CASE("integrate sums the frame's SSLR hits after the tiles' counters, up to what decides") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Presence all;
    const scene::Camera camera = testCamera();
    const Traces traces = makeTraces(0, false);
    const auto hitsOf = [](const Frame& f) {
        uint32_t hits = 0;
        for (const uint32_t c : f.counters) hits += shader::feedbackHits(c);
        return hits;
    };
    // A share of 1 decides only at every pixel: the whole sum.
    RunOptions whole;
    whole.feedback.sslrMinHitShare = 1.0f;
    const Frame f = harness.run(camera, 0, traces, all, whole);
    const uint32_t hits = hitsOf(f);
    REQUIRE(hits > 50);
    CHECK(f.frameHitsWord == shader::kFeedbackFrameHitsStart + hits);
    // A small share: the tiles stop adding once the sum decides (the
    // atomics of tiles already past the test still land).
    RunOptions small;
    small.feedback.sslrMinHitShare = 10.0f / float(kSize * kSize);
    const Frame g = harness.run(camera, 1, traces, all, small);
    CHECK(g.frameHitsWord >= shader::kFeedbackFrameHitsStart + 10);
    CHECK(g.frameHitsWord <= shader::kFeedbackFrameHitsStart + hitsOf(g));
    // The gate off: the word stays where the feedback pass started it.
    RunOptions off;
    off.feedback.sslrMinHitShare = 0.0f;
    CHECK(harness.run(camera, 2, traces, all, off).frameHitsWord == shader::kFeedbackFrameHitsStart);
}

TEST_CASE("feedback refuses hit and miss fractions outside [0, 1]") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    const std::vector<uint32_t> counters(kTiles * kTiles, 0u);
    passes::FeedbackSettings settings;
    settings.rtHitFraction = 1.5f;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("rtHitFraction must lie in [0, 1]"), gpu::GpuError);
    settings.rtHitFraction = 0.0f;
    settings.sslrMissFraction = -0.1f;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("(got -0.1"), gpu::GpuError);
    settings.sslrMissFraction = 0.0f;
    settings.sslrMinHitShare = 2.0f;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("sslrMinHitShare must lie in [0, 1]"), gpu::GpuError);
    settings.sslrMinHitShare = 0.02f;
    settings.sslrProbeInterval = 0;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("sslrProbeInterval be at least 1"), gpu::GpuError);
    settings.sslrProbeInterval = 8;
    settings.sslrProbeIntervalMax = 4;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("sslrProbeIntervalMax (4) must be at least sslrProbeInterval (8)"),
                         gpu::GpuError);
}
