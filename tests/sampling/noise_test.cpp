// The random numbers of ray generation and SSLR (glint/sampling.glsl, the
// same code the shaders run): each use draws its own dimension, and the
// dimensions are independent of each other across a tile and over frames.
#include "glint/sampling.glsl"

#include <doctest/doctest.h>

#include <glm/glm.hpp>

#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <string>
#include <vector>

using namespace glint;

namespace {

// The four numbers a pixel draws in a frame: the GGX sample's two, SSLR's
// start offset, the hybrid share's.
constexpr int kStreams = 4;
const std::array<const char*, kStreams> kStreamNames = {"ggx.x", "ggx.y", "sslr_offset", "rt_to_hybrid"};

std::array<float, kStreams> draw(glm::uvec2 pixel, uint32_t frame) {
    const glm::vec2 ggx = shader::ggxNoise(pixel, frame);
    return {ggx.x, ggx.y, shader::scalarNoise(pixel, frame, shader::kNoiseSslrOffset),
            shader::scalarNoise(pixel, frame, shader::kNoiseRtToHybrid)};
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
    const double n = double(a.size());
    double ma = 0.0, mb = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        ma += a[i];
        mb += b[i];
    }
    ma /= n;
    mb /= n;
    double sab = 0.0, saa = 0.0, sbb = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / std::sqrt(saa * sbb);
}

struct Correlations {
    double mean = 0.0;          // signed, averaged over the groups
    double meanMagnitude = 0.0;  // |r| averaged over the groups
};

// Correlation of streams i and j within each group of samples, averaged
// over the groups.
Correlations correlate(int i, int j, int groups, int samples,
                       const std::function<std::array<float, kStreams>(int group, int sample)>& at) {
    Correlations c;
    for (int g = 0; g < groups; ++g) {
        std::vector<double> a, b;
        for (int s = 0; s < samples; ++s) {
            const auto v = at(g, s);
            a.push_back(v[i]);
            b.push_back(v[j]);
        }
        const double r = correlation(a, b);
        c.mean += r / groups;
        c.meanMagnitude += std::abs(r) / groups;
    }
    return c;
}

} // namespace

TEST_CASE("every pair of noise streams is uncorrelated across an 8x8 tile and over a pixel's frames") {
    for (int i = 0; i < kStreams; ++i) {
        for (int j = i + 1; j < kStreams; ++j) {
            CAPTURE(std::string(kStreamNames[i]) + " / " + kStreamNames[j]);
            // Across a tile: 16 tiles x 64 frames, 64 pixels each.
            const Correlations tile = correlate(i, j, 16 * 64, 64, [](int g, int s) {
                const glm::uvec2 origin(8u * uint32_t(g % 16 % 4) + 40u, 8u * uint32_t(g % 16 / 4) + 24u);
                return draw(origin + glm::uvec2(uint32_t(s) % 8u, uint32_t(s) / 8u), uint32_t(g / 16));
            });
            // Over frames: 256 pixels, 256 frames each.
            const Correlations frames = correlate(i, j, 256, 256, [](int g, int s) {
                return draw({uint32_t(g) % 16u + 100u, uint32_t(g) / 16u + 7u}, uint32_t(s) + 1000u);
            });
            CAPTURE(tile.mean);
            CAPTURE(tile.meanMagnitude);
            CAPTURE(frames.mean);
            CAPTURE(frames.meanMagnitude);
            CHECK(std::abs(tile.mean) < 0.02);
            CHECK(std::abs(frames.mean) < 0.02);
            // Not a shifted copy per pixel either, whose correlation
            // 1 - 6 d (1 - d) for a shift d averages to 0 over random
            // shifts but not in magnitude (0.38): independent streams of
            // 64 and 256 samples average about 0.1 and 0.05.
            CHECK(tile.meanMagnitude < 0.15);
            CHECK(frames.meanMagnitude < 0.08);
        }
    }
}

TEST_CASE("SSLR's start offset differs from pixel to pixel and from frame to frame, uniform on [0, 1)") {
    std::set<float> acrossPixels, acrossFrames;
    std::array<int, 16> histogram{};
    for (uint32_t y = 0; y < 64; ++y) {
        for (uint32_t x = 0; x < 64; ++x) {
            acrossPixels.insert(shader::scalarNoise({x, y}, 9u, shader::kNoiseSslrOffset));
        }
    }
    for (uint32_t frame = 0; frame < 4096; ++frame) {
        const float v = shader::scalarNoise({17, 3}, frame, shader::kNoiseSslrOffset);
        REQUIRE(v >= 0.0f);
        REQUIRE(v < 1.0f);
        acrossFrames.insert(v);
        ++histogram[size_t(v * 16.0f)];
    }
    CHECK(acrossPixels.size() > 4000u);
    CHECK(acrossFrames.size() == 4096u);
    // One pixel over frames: a low-discrepancy sequence, every bin within
    // a few samples of 256 (a random one would stray by about 16).
    for (const int count : histogram) CHECK(std::abs(count - 256) <= 3);
}

TEST_CASE("the pixels an RT tile keeps hybrid draw their GGX samples from the whole sample space") {
    // The share kept hybrid (RayGenerationSettings::rtToHybridShare's default).
    constexpr float kShare = 1.0f / 16.0f;
    constexpr int kBins = 4;
    std::array<int, kBins * kBins> histogram{};
    int kept = 0, total = 0;
    for (uint32_t frame = 0; frame < 64; ++frame) {
        for (uint32_t y = 0; y < 64; ++y) {
            for (uint32_t x = 0; x < 64; ++x) {
                ++total;
                if (shader::scalarNoise({x, y}, frame, shader::kNoiseRtToHybrid) >= kShare) continue;
                ++kept;
                const glm::vec2 u = shader::ggxNoise({x, y}, frame);
                ++histogram[size_t(int(u.y * kBins) * kBins + int(u.x * kBins))];
            }
        }
    }
    CHECK(std::abs(double(kept) / total - kShare) < 0.002);
    const double expected = double(kept) / histogram.size();
    double chi2 = 0.0;
    for (const int count : histogram) chi2 += (count - expected) * (count - expected) / expected;
    CAPTURE(kept);
    CAPTURE(chi2);
    // 15 degrees of freedom: p = 0.001 at 37.7.
    CHECK(chi2 < 37.7);
}
