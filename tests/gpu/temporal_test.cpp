// Temporal accumulation (passes/temporal.h) on a real device, validation
// on, behind the real G-buffer, with the reflection radiance and hit
// distance uploaded by the test (so nothing depends on the passes between;
// the rig: temporal_rig.h). Frames run back to back with two in flight;
// every frame has its own upload and readback buffers. Known answers:
// noise around a known mean shrinks like an average; NaN, Inf and 1e30
// never reach a later frame; a disoccluded pixel shows the new surface in
// its first frame; reflection motion equals the closed-form motion of the
// virtual point (and of the surface when rough); a reset forgets. The
// spatial filter has its own file (spatial_filter_test.cpp), as do the
// composite and the debug views (composite_test.cpp).
#include "temporal_rig.h"

#include "glint/gpu/error.h"

#include "glint/integrate_shared.h"
#include "glint/ray_generation_shared.h"
#include "glint/temporal_shared.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace glint;
using namespace glint::temporal_test;

// ---------------------------------------------------------------- temporal

TEST_CASE("noisy reflections of a static mirror converge towards their mean like an average of the frames") {
    scene::Scene scene = wallScene(material(0.05f, 1.0f));
    constexpr uint32_t kFrames = 24;
    const std::vector<FrameInput> frames = noisyFrames(kFrames, 0.3f);
    const std::vector<FrameOutput> out = runTemporal(scene, frames);

    const float single = rmsError(frames[0].radiance);
    // The first frame has no history: it is the input (a mirror: no blur).
    CHECK(rmsError(out[0].resolved) == doctest::Approx(single).epsilon(0.01));
    for (size_t i = 0; i < kPixels; ++i) {
        REQUIRE(out[0].length[i] == 1.0f);
        REQUIRE(out.back().length[i] == float(kFrames));
        REQUIRE(out.back().resolved[i].w == 1.0f);
    }
    // A plain average of 24 frames leaves 1 / sqrt(24) = 0.20 of the noise;
    // the clamp may cost a little of that.
    const float converged = rmsError(out.back().resolved);
    MESSAGE("single-frame rms " << single << ", after " << kFrames << " frames " << converged);
    CHECK(converged < 0.3f * single);
    // Without a bias: the mean error over the image is far below the
    // per-pixel noise left (a history that rounds would drift darker).
    glm::dvec3 bias(0.0);
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            bias += glm::dvec3(glm::vec3(out.back().resolved[at(x, y)]) - glm::vec3(meanRadiance(x, y)));
        }
    }
    bias /= double(kPixels);
    MESSAGE("mean error " << bias.x << " " << bias.y << " " << bias.z);
    CHECK(glm::length(bias) < 0.003);
    // And it shrinks on the way.
    CHECK(rmsError(out[3].resolved) < 0.65f * single);
    CHECK(rmsError(out[11].resolved) < rmsError(out[3].resolved));
}

TEST_CASE("a long history follows a small change of radiance instead of stalling at its half float") {
    // Eight frames of 1.0, then 1.02: with weights down to 1/64 each
    // frame's step, (1.02 - h) / n, is below half a half float's step at 1
    // (2^-11) from the first frame on, so a history rounded to nearest
    // would stay at 1.0 (a 1.8% error); rounded stochastically its mean
    // follows the exact average. The clip is off: the neighbourhood is flat.
    scene::Scene scene = wallScene(material(0.05f, 1.0f));
    constexpr uint32_t kBefore = 8;
    constexpr uint32_t kFrames = 72;
    std::vector<FrameInput> frames(kFrames);
    for (uint32_t f = 0; f < kFrames; ++f) {
        const float c = f < kBefore ? 1.0f : 1.02f;
        std::fill(frames[f].radiance.begin(), frames[f].radiance.end(), glm::vec4(c, c, c, 1.0f));
    }
    passes::TemporalSettings settings;
    settings.neighbourhoodClamp = false;
    const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);
    // The exact average, as the pass weighs it.
    double expected = 0.0;
    for (uint32_t f = 0; f < kFrames; ++f) {
        const double c = f < kBefore ? 1.0 : 1.02;
        const double length = std::min(double(f + 1), double(settings.maxHistoryFrames));
        expected += (c - expected) / length;
    }
    double mean = 0.0;
    for (const glm::vec4& v : out.back().resolved) mean += (v.x + v.y + v.z) / 3.0;
    mean /= double(kPixels);
    MESSAGE("mean " << mean << ", exact average " << expected);
    CHECK(std::abs(mean - expected) < 0.002);
}

TEST_CASE("NaN, Inf and 1e30 injected in one frame leave every later frame finite and bounded") {
    scene::Scene scene = wallScene(material(0.05f, 1.0f));
    constexpr uint32_t kFrames = 10;
    constexpr uint32_t kBad = 4;
    std::vector<FrameInput> frames = noisyFrames(kFrames, 0.3f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    FrameInput& bad = frames[kBad];
    bad.radiance[at(20, 20)] = {nan, nan, nan, 1.0f};
    bad.radiance[at(40, 40)] = {1e30f, 1e30f, 1e30f, 1.0f};
    bad.radiance[at(41, 40)] = {0.5f, -1e30f, 0.5f, 1.0f};
    bad.radiance[at(10, 50)] = {inf, 0.5f, 0.5f, 1.0f};
    bad.radiance[at(50, 10)] = {0.5f, 0.5f, -inf, 1.0f};
    bad.radiance[at(30, 5)] = {0.5f, 0.5f, 0.5f, nan};  // not even the mask is a number
    bad.hitDistance[at(30, 30)] = nan;
    bad.hitDistance[at(31, 30)] = -inf;
    bad.hitDistance[at(32, 30)] = 1e30f;
    // The G-buffer's motion is finite; the pass must not trust that either,
    // but it cannot be injected without editing the G-buffer.
    const std::vector<FrameOutput> out = runTemporal(scene, frames);
    // Every clean input lies below 0.8 + 0.3 = 1.1.
    for (uint32_t f = 0; f < kFrames; ++f) {
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("frame " << f << " pixel " << x << ", " << y);
                const glm::vec4 v = out[f].resolved[at(x, y)];
                REQUIRE(finite(v));
                REQUIRE(std::isfinite(out[f].length[at(x, y)]));
                REQUIRE(std::isfinite(out[f].motion[at(x, y)].x));
                REQUIRE(std::isfinite(out[f].motion[at(x, y)].y));
                REQUIRE(v.x >= 0.0f);
                REQUIRE(v.y >= 0.0f);
                REQUIRE(v.z >= 0.0f);
                if (f > kBad) {
                    // The next frame clips the spike to its neighbourhood.
                    REQUIRE(std::max({v.x, v.y, v.z}) <= 1.2f);
                }
                // From the bad frame on, every pixel is an average of at
                // least five frames near its mean (max error of ~12k
                // samples of sigma 0.17 / sqrt(5): ~0.3), but for the
                // spiked, zeroed and unmasked pixels of the bad frame.
                const bool excused = f == kBad && (at(x, y) == at(40, 40) || at(x, y) == at(41, 40) ||
                                                   at(x, y) == at(30, 5));
                if (f >= kBad && !excused) {
                    const glm::vec3 error = glm::abs(glm::vec3(v) - glm::vec3(meanRadiance(x, y)));
                    REQUIRE(std::max({error.x, error.y, error.z}) < 0.45f);
                }
            }
        }
    }
    // The NaN pixel took its neighbours' mean in the bad frame.
    const glm::vec3 nanPixel = out[kBad].resolved[at(20, 20)];
    CHECK(glm::length(nanPixel - glm::vec3(meanRadiance(20, 20))) < 0.3f);
    // The pixel whose mask was NaN reflects nothing that frame.
    CHECK(out[kBad].resolved[at(30, 5)] == glm::vec4(0.0f));
    CHECK(out[kBad].length[at(30, 5)] == 0.0f);
    // Several frames later the spiked pixel is back near its mean.
    CHECK(glm::length(glm::vec3(out.back().resolved[at(40, 40)]) - glm::vec3(meanRadiance(40, 40))) < 0.3f);
}

TEST_CASE("a disoccluded surface shows its own radiance in its first frame, without a ghost of the occluder") {
    // A small square 4 units in front of the camera covers pixels 24..39 in
    // x and y of a wall at 10 units, then jumps out of view.
    constexpr uint32_t kMoveFrame = 8;
    constexpr uint32_t kFrames = 11;
    const glm::vec4 objectRadiance(1.0f, 0.2f, 0.1f, 1.0f);
    const glm::vec4 wallRadiance(0.1f, 0.3f, 1.0f, 1.0f);
    const auto covered = [](uint32_t x, uint32_t y) { return x >= 24 && x < 40 && y >= 24 && y < 40; };
    for (const bool clamp : {false, true}) {
        CAPTURE(clamp);
        scene::Scene scene = makeScene({square({0, 0, -10}, {1, 0, 0}, {0, 1, 0}, 50.0f, 0),
                                        square({0, 0, -4}, {1, 0, 0}, {0, 1, 0}, 1.0f, 0)},
                                       {material(0.05f, 1.0f)});
        std::vector<FrameInput> frames(kFrames);
        for (uint32_t f = 0; f < kFrames; ++f) {
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    frames[f].radiance[at(x, y)] = f < kMoveFrame && covered(x, y) ? objectRadiance : wallRadiance;
                }
            }
        }
        const glm::mat4 away = glm::translate(glm::mat4(1.0f), glm::vec3(100.0f, 0.0f, 0.0f));
        frames[kMoveFrame].update = [away](scene::Scene& s) {
            s.instances[1].previousTransform = s.instances[1].transform;
            s.instances[1].transform = away;
        };
        frames[kMoveFrame + 1].update = [away](scene::Scene& s) { s.instances[1].previousTransform = away; };
        passes::TemporalSettings settings;
        // Without the clamp only the history rejection can stop the ghost.
        settings.neighbourhoodClamp = clamp;
        const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);

        // Before the move the object's pixels hold the object.
        CHECK(glm::length(glm::vec3(out[kMoveFrame - 1].resolved[at(32, 32)] - objectRadiance)) < 0.01f);
        CHECK(out[kMoveFrame - 1].length[at(32, 32)] == float(kMoveFrame));
        for (uint32_t f = kMoveFrame; f < kFrames; ++f) {
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    INFO("frame " << f << " pixel " << x << ", " << y);
                    const glm::vec4 v = out[f].resolved[at(x, y)];
                    REQUIRE(glm::length(glm::vec3(v - wallRadiance)) < 0.01f);
                    if (covered(x, y)) {
                        // The history was rejected: it starts over.
                        REQUIRE(out[f].length[at(x, y)] == float(f - kMoveFrame + 1));
                    } else {
                        REQUIRE(out[f].length[at(x, y)] == float(f + 1));
                    }
                }
            }
        }
    }
}

TEST_CASE("reflection motion follows the reflected point for a mirror and the surface for a rough wall") {
    // The camera steps 0.5 to the right between two frames. A point at view
    // depth z moves 0.5 * 32 / z pixels to the right on the image (32 pixels
    // per unit at depth 1): last frame's pixel = this frame's + motion.
    // The virtual point of a wall pixel lies hitDistance further along the
    // view ray; a miss (kMissHitDistance) is a point at infinity, which a
    // translation does not move.
    constexpr float kStep = 0.5f;
    constexpr float kHit = 3.0f;
    for (const float roughness : {0.0f, 0.8f}) {
        CAPTURE(roughness);
        scene::Scene scene = wallScene(material(roughness, 1.0f));
        std::vector<FrameInput> frames = cameraStepFrames(kStep);
        for (FrameInput& f : frames) {
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    f.radiance[at(x, y)] = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
                    f.hitDistance[at(x, y)] = x < kSize / 2 ? kHit : shader::kMissHitDistance;
                }
            }
        }
        const std::vector<FrameOutput> out = runTemporal(scene, frames);
        const FrameOutput& f = out[1];
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("pixel " << x << ", " << y);
                const glm::vec2 ndc = test::pixelNdc(x, y);
                // The wall point under the pixel, from the new camera, and the
                // unit view ray's z.
                const glm::vec3 ray = glm::normalize(glm::vec3(ndc.x, -ndc.y, -1.0f));
                const float depth = kWallDistance - kHit * ray.z;  // ray.z < 0: further
                float expected = kStep * 32.0f / kWallDistance;      // the surface
                if (roughness == 0.0f) {
                    expected = x < kSize / 2 ? kStep * 32.0f / depth : 0.0f;
                }
                const glm::vec2 motion = f.motion[at(x, y)];
                REQUIRE(std::abs(motion.x - expected) < 0.02f);
                REQUIRE(std::abs(motion.y) < 0.02f);
                // The history was found wherever last frame saw the point.
                if (x + 4 < kSize) {
                    REQUIRE(f.length[at(x, y)] == 2.0f);
                }
            }
        }
    }
}

// A glossy wall (roughness 0.2: halfway between the two motions) that
// reflects nothing (misses: the reflected point is at infinity, which the
// camera's step does not move) while the camera steps 0.5 to the right:
// the surface moved 0.5 * 32 / 5 = 3.2 pixels, the reflected point 0. Last
// frame's radiance is a stripe every fourth column, so looking the history
// up at both motions and blending differs from looking it up once at the
// blended 1.6 pixels. The clip box and the spatial filter are off: the
// result is the average of the history and this frame's 0.5. A mirror and a
// rough wall (one motion each) are the same either way.
TEST_CASE("one history candidate looks a glossy pixel's history up at the blended motion") {
    constexpr float kStep = 0.5f;
    const float surfaceMotion = kStep * 32.0f / kWallDistance;
    const auto stripe = [](int column) { return column % 4 == 0 ? 1.0f : 0.0f; };
    // The shader's bilinear lookup along a row at pixel position x.
    const auto lookup = [&](float x) {
        const float base = std::floor(x - 0.5f);
        const float t = x - 0.5f - base;
        return (1.0f - t) * stripe(int(base)) + t * stripe(int(base) + 1);
    };
    for (const float roughness : {0.2f, 0.0f, 0.5f}) {
        CAPTURE(roughness);
        scene::Scene scene = wallScene(material(roughness, 1.0f));
        std::vector<FrameInput> frames = cameraStepFrames(kStep);
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const float v = stripe(int(x));
                frames[0].radiance[at(x, y)] = glm::vec4(v, v, v, 1.0f);
                frames[1].radiance[at(x, y)] = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
                for (FrameInput& f : frames) f.hitDistance[at(x, y)] = shader::kMissHitDistance;
            }
        }
        passes::TemporalSettings both;
        both.neighbourhoodClamp = false;
        both.spatialRadius = 0;
        both.oneHistoryCandidate = false;
        passes::TemporalSettings one = both;
        one.oneHistoryCandidate = true;
        const std::vector<FrameOutput> outBoth = runTemporal(scene, frames, both);
        const std::vector<FrameOutput> outOne = runTemporal(scene, frames, one);
        if (roughness != 0.2f) {
            CHECK(outOne.back().resolved == outBoth.back().resolved);
            continue;
        }
        uint32_t differing = 0;
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x + 6 < kSize; ++x) {
                INFO("pixel " << x << ", " << y);
                const float centre = float(x) + 0.5f;
                const float blendedHistories = 0.5f * lookup(centre) + 0.5f * lookup(centre + surfaceMotion);
                const float blendedMotion = lookup(centre + 0.5f * surfaceMotion);
                REQUIRE(outBoth.back().length[at(x, y)] == 2.0f);
                REQUIRE(outOne.back().length[at(x, y)] == 2.0f);
                REQUIRE(outBoth.back().resolved[at(x, y)].g ==
                        doctest::Approx(0.5f * blendedHistories + 0.25f).epsilon(0.01));
                REQUIRE(outOne.back().resolved[at(x, y)].g ==
                        doctest::Approx(0.5f * blendedMotion + 0.25f).epsilon(0.01));
                differing += std::abs(blendedHistories - blendedMotion) > 0.1f ? 1u : 0u;
            }
        }
        CHECK(differing > kSize * kSize / 2);
    }
}

TEST_CASE("a jittered camera keeps the history of a grazing floor") {
    // Rasterisation moves by a sub-pixel jitter every frame; positions are
    // reconstructed with the jittered matrices, so a floor seen at grazing
    // angles (depth changing fast across pixels) still lies on its own
    // plane frame after frame.
    constexpr uint32_t kFrames = 8;
    scene::Scene scene = makeScene({square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f, 0)}, {material(0.05f, 1.0f)});
    std::vector<FrameInput> frames(kFrames);
    scene::Camera camera = testCamera();
    camera.jitter = true;
    const scene::CameraPose pose{{0, 0, 0}, {0, 0, -1}, {0, 1, 0}};
    camera.reset(pose, 0);
    for (uint32_t f = 0; f < kFrames; ++f) {
        if (f > 0) camera.advance(pose, f);
        frames[f].camera = camera;
        std::fill(frames[f].radiance.begin(), frames[f].radiance.end(), glm::vec4(0.5f, 0.6f, 0.7f, 1.0f));
    }
    REQUIRE(frames[1].camera.jitterPixels != frames[2].camera.jitterPixels);
    const std::vector<FrameOutput> out = runTemporal(scene, frames);
    // The floor fills the lower half; a few rows below the horizon the
    // floor is still 5-10 units away at angles of a few degrees.
    for (uint32_t y = kSize / 2 + 2; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y);
            REQUIRE(out.back().length[at(x, y)] == float(kFrames));
            REQUIRE(glm::length(glm::vec3(out.back().resolved[at(x, y)]) - glm::vec3(0.5f, 0.6f, 0.7f)) < 2e-3f);
        }
    }
}

TEST_CASE("a camera moving down a street keeps the history of the floor and the wall beside it") {
    // Each frame the camera moves half a unit forward between a floor (1
    // below it) and a wall (2 to its left): their points move up to ~10
    // pixels a frame, down the floor and left along the wall. A history
    // texel far from the pixel must still be found on the pixel's plane
    // (the plane test's gradient across the image, in y on the floor and in
    // x on the wall).
    constexpr uint32_t kFrames = 8;
    scene::Scene scene = makeScene({square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f, 0),
                                    square({-2, 0, -500}, {0, 0, -1}, {0, 1, 0}, 500.0f, 0)},
                                   {material(0.5f, 1.0f)});
    std::vector<FrameInput> frames(kFrames);
    scene::Camera camera = testCamera();
    for (uint32_t f = 0; f < kFrames; ++f) {
        const glm::vec3 position(0.0f, 0.0f, -0.5f * float(f));
        const scene::CameraPose pose{position, position + glm::vec3(0, 0, -1), {0, 1, 0}};
        if (f == 0) {
            camera.reset(pose, 0);
        } else {
            camera.advance(pose, f);
        }
        frames[f].camera = camera;
        std::fill(frames[f].radiance.begin(), frames[f].radiance.end(), glm::vec4(0.5f, 0.6f, 0.7f, 1.0f));
    }
    const std::vector<FrameOutput> out = runTemporal(scene, frames);
    // Every surface point seen now was on screen last frame (moving
    // forward, points move away from the image's centre).
    uint32_t floorPixels = 0, wallPixels = 0;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            if (!(out.back().length[at(x, y)] > 0.0f)) continue;
            INFO("pixel " << x << ", " << y);
            REQUIRE(out.back().length[at(x, y)] == float(kFrames));
            REQUIRE(glm::length(glm::vec3(out.back().resolved[at(x, y)]) - glm::vec3(0.5f, 0.6f, 0.7f)) < 2e-3f);
            floorPixels += y >= kSize * 3 / 4 ? 1 : 0;              // the floor alone
            wallPixels += x < kSize / 8 && y < kSize / 2 ? 1 : 0;  // the wall alone
        }
    }
    // Both surfaces are in view there.
    CHECK(floorPixels == kSize * kSize / 4);
    CHECK(wallPixels == kSize * kSize / 16);
}

TEST_CASE("a reset discards the history; without it the history lingers") {
    constexpr uint32_t kFrames = 6;
    const glm::vec4 before(1.0f, 0.0f, 0.0f, 1.0f);
    const glm::vec4 after(0.0f, 0.0f, 1.0f, 1.0f);
    for (const bool reset : {true, false}) {
        CAPTURE(reset);
        scene::Scene scene = wallScene(material(0.05f, 1.0f));
        std::vector<FrameInput> frames(kFrames);
        for (uint32_t f = 0; f < kFrames; ++f) {
            std::fill(frames[f].radiance.begin(), frames[f].radiance.end(), f + 1 < kFrames ? before : after);
        }
        frames.back().reset = reset;
        passes::TemporalSettings settings;
        settings.neighbourhoodClamp = false;
        const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);
        const glm::vec4 v = out.back().resolved[at(32, 32)];
        if (reset) {
            CHECK(glm::length(glm::vec3(v - after)) < 1e-3f);
            CHECK(out.back().length[at(32, 32)] == 1.0f);
        } else {
            // One new frame of six.
            CHECK(glm::length(glm::vec3(v) - glm::mix(glm::vec3(before), glm::vec3(after), 1.0f / 6.0f)) < 2e-3f);
            CHECK(out.back().length[at(32, 32)] == 6.0f);
        }
    }
}

TEST_CASE("the clip box spans 5x5 where rays are shared, 3x3 where each pixel has its own or none") {
    // A history of 0.5; then a frame of 0.1 in the 3x3 around the centre
    // and 0.9 beyond. The 3x3 box holds only 0.1: the history is clipped to
    // it. The 5x5 box also holds sixteen 0.9s, wide enough for 0.5 to
    // stand: the new frame takes half (two frames of history). A pixel
    // that takes the environment alone shares no rays, whatever its
    // roughness: 3x3.
    constexpr uint32_t kCentre = 32;
    for (const bool shared : {false, true}) {
      for (const bool environment : {false, true}) {
        CAPTURE(shared);
        CAPTURE(environment);
        scene::Scene scene = wallScene(material(0.05f, 1.0f));
        std::vector<FrameInput> frames(2);
        std::fill(frames[0].radiance.begin(), frames[0].radiance.end(), glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const bool inner = std::max(std::abs(int(x) - int(kCentre)), std::abs(int(y) - int(kCentre))) <= 1;
                const float v = inner ? 0.1f : 0.9f;
                frames[1].radiance[at(x, y)] = glm::vec4(v, v, v, 1.0f);
            }
        }
        for (FrameInput& f : frames) {
            f.sharedRayRoughness = shared ? 0.0f : 2.0f;
            f.environmentRoughness = environment ? 0.01f : 2.0f;
        }
        passes::TemporalSettings settings;
        settings.clampRadius = 2;
        const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);
        const float v = out.back().resolved[at(kCentre, kCentre)].g;
        CHECK(out.back().length[at(kCentre, kCentre)] == 2.0f);
        if (shared && !environment) {
            CHECK(v == doctest::Approx(0.3f).epsilon(0.01));
        } else {
            CHECK(v == doctest::Approx(0.1f).epsilon(0.01));
        }
      }
    }
}

TEST_CASE("without its debug outputs the pass resolves the same image and hands out no motion or length") {
    scene::Scene scene = wallScene(material(0.3f, 1.0f));
    std::vector<FrameInput> frames = noisyFrames(3, 0.3f);
    const std::vector<FrameOutput> with = runTemporal(scene, frames);
    for (FrameInput& f : frames) f.debugOutputs = false;
    const std::vector<FrameOutput> without = runTemporal(scene, frames);
    for (size_t f = 0; f < frames.size(); ++f) {
        CHECK(without[f].motion.empty());
        CHECK(with[f].resolved == without[f].resolved);
    }
}

TEST_CASE("a pixel that takes the environment alone keeps its history where the surface tests reject it") {
    // A rough wall that steps a unit back after two frames: every pixel
    // fails the plane test (1 unit against 2% of 5). Where the wall traces
    // rays its history starts over; where it takes the environment alone
    // (noise-free, following its normal) the history stays, and the frame,
    // the same radiance, changes nothing.
    const glm::vec4 radiance(0.2f, 0.4f, 0.6f, 1.0f);
    for (const bool environment : {false, true}) {
        CAPTURE(environment);
        scene::Scene scene = wallScene(material(0.5f, 1.0f));
        std::vector<FrameInput> frames(3);
        for (FrameInput& f : frames) {
            std::fill(f.radiance.begin(), f.radiance.end(), radiance);
            f.environmentRoughness = environment ? 0.4f : 2.0f;
        }
        const glm::mat4 back = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -1.0f));
        frames[2].update = [back](scene::Scene& s) {
            s.instances[0].previousTransform = s.instances[0].transform;
            s.instances[0].transform = back;
        };
        const std::vector<FrameOutput> out = runTemporal(scene, frames);
        // (Near the image's edge last frame saw these points off screen.)
        for (const uint32_t y : {12u, 32u, 52u}) {
            for (const uint32_t x : {12u, 32u, 52u}) {
                INFO("pixel " << x << ", " << y);
                CHECK(out[1].length[at(x, y)] == 2.0f);
                CHECK(out[2].length[at(x, y)] == (environment ? 3.0f : 1.0f));
                CHECK(glm::length(glm::vec3(out[2].resolved[at(x, y)] - radiance)) < 2e-3f);
            }
        }
    }
}

TEST_CASE("temporal settings out of range are an error naming the pass") {
    test::GpuTest gpu;
    passes::TemporalPipelines pipelines(gpu.ctx());
    rg::Graph graph;
    passes::GBufferOutputs gbuf;
    gbuf.width = kSize;
    gbuf.height = kSize;
    const rg::Texture fake = graph.createTexture("fake", {.width = kSize, .height = kSize,
                                                          .format = VK_FORMAT_R16G16B16A16_SFLOAT});
    passes::TemporalSettings settings;
    settings.maxHistoryFrames = 0.0f;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("addTemporalPass"), gpu::GpuError);
    settings = {};
    settings.spatialRadius = 9;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("addTemporalPass"), gpu::GpuError);
    settings = {};
    settings.spatialNoiseFreeRadius = shader::kTemporalMaxSpatialRadius + 1;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("spatialNoiseFreeRadius"), gpu::GpuError);
    settings = {};
    settings.clampRadius = shader::kTemporalMaxClampRadius + 1;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("clampRadius <= 3"), gpu::GpuError);
}
