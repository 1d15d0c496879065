// The random numbers of ray generation and SSLR (glint/sampling.glsl, the
// same code the shaders run), from either source: each use draws its own
// dimension, and the dimensions are independent of each other across a
// tile and over frames. And the blue noise itself (sampling/blue_noise.h):
// blue in space and in time, every value once, its file checked.
#include "glint/sampling.glsl"
#include "glint/sampling/blue_noise.h"

#include <doctest/doctest.h>

#include <glm/glm.hpp>

#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <vector>

using namespace glint;

namespace {

// The four numbers a pixel draws in a frame: the GGX sample's two, SSLR's
// start offset, the hybrid share's.
constexpr int kStreams = 4;
const std::array<const char*, kStreams> kStreamNames = {"ggx.x", "ggx.y", "sslr_offset", "rt_to_hybrid"};

enum class Source { Sequence, BlueNoise };

// The build's blue noise as the shaders read it.
const std::vector<uint32_t>& blueNoiseWords() {
    static const std::vector<uint32_t> words = sampling::blueNoiseWords(sampling::readBlueNoise(GLINT_BLUE_NOISE_FILE));
    return words;
}

std::array<float, kStreams> draw(Source source, glm::uvec2 pixel, uint32_t frame) {
    if (source == Source::BlueNoise) {
        const std::vector<uint32_t>& words = blueNoiseWords();
        const uint32_t i = shader::blueNoiseTexel(pixel, frame);
        const glm::uvec2 texel(words.at(2 * i), words.at(2 * i + 1));
        return {shader::blueNoiseChannel(texel, shader::kBlueNoiseGgxX),
                shader::blueNoiseChannel(texel, shader::kBlueNoiseGgxY),
                shader::blueNoiseChannel(texel, shader::kBlueNoiseSslrOffset),
                shader::blueNoiseChannel(texel, shader::kBlueNoiseRtToHybrid)};
    }
    const glm::vec2 ggx = shader::ggxNoise(pixel, frame);
    return {ggx.x, ggx.y, shader::scalarNoise(pixel, frame, shader::kNoiseSslrOffset),
            shader::scalarNoise(pixel, frame, shader::kNoiseRtToHybrid)};
}

std::string sourceName(Source source) { return source == Source::BlueNoise ? "blue noise" : "sequence"; }

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
  for (const Source source : {Source::Sequence, Source::BlueNoise}) {
    CAPTURE(sourceName(source));
    for (int i = 0; i < kStreams; ++i) {
        for (int j = i + 1; j < kStreams; ++j) {
            CAPTURE(std::string(kStreamNames[i]) + " / " + kStreamNames[j]);
            // Across a tile: 16 tiles x 64 frames, 64 pixels each.
            const Correlations tile = correlate(i, j, 16 * 64, 64, [source](int g, int s) {
                const glm::uvec2 origin(8u * uint32_t(g % 16 % 4) + 40u, 8u * uint32_t(g % 16 / 4) + 24u);
                return draw(source, origin + glm::uvec2(uint32_t(s) % 8u, uint32_t(s) / 8u), uint32_t(g / 16));
            });
            // Over frames: 256 pixels, 256 frames each.
            const Correlations frames = correlate(i, j, 256, 256, [source](int g, int s) {
                return draw(source, {uint32_t(g) % 16u + 100u, uint32_t(g) / 16u + 7u}, uint32_t(s) + 1000u);
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
}

TEST_CASE("SSLR's start offset differs from pixel to pixel and from frame to frame, uniform on [0, 1)") {
    for (const Source source : {Source::Sequence, Source::BlueNoise}) {
        CAPTURE(sourceName(source));
        constexpr int kOffset = 2;
        std::set<float> acrossPixels, acrossFrames;
        std::array<int, 16> histogram{};
        for (uint32_t y = 0; y < 64; ++y) {
            for (uint32_t x = 0; x < 64; ++x) {
                acrossPixels.insert(draw(source, {x, y}, 9u)[kOffset]);
            }
        }
        for (uint32_t frame = 0; frame < 4096; ++frame) {
            const float v = draw(source, {17, 3}, frame)[kOffset];
            REQUIRE(v >= 0.0f);
            REQUIRE(v < 1.0f);
            acrossFrames.insert(v);
            ++histogram[size_t(v * 16.0f)];
        }
        CAPTURE(acrossPixels.size());
        CAPTURE(acrossFrames.size());
        // Blue noise values are 16-bit ranks: a few repeat.
        CHECK(acrossPixels.size() > 4000u);
        CHECK(acrossFrames.size() > 3900u);
        // One pixel over frames is uniform: the sequence, low discrepancy,
        // puts every bin within 3 of 256; the blue noise passes
        // chi-square (15 degrees of freedom, p = 0.001 at 37.7).
        double chi2 = 0.0;
        for (const int count : histogram) {
            if (source == Source::Sequence) CHECK(std::abs(count - 256) <= 3);
            chi2 += (count - 256.0) * (count - 256.0) / 256.0;
        }
        CAPTURE(chi2);
        CHECK(chi2 < 37.7);
    }
}

TEST_CASE("the pixels an RT tile keeps hybrid draw their GGX samples from the whole sample space") {
    // The share kept hybrid (RayGenerationSettings::rtToHybridShare's default).
    constexpr float kShare = 1.0f / 16.0f;
    constexpr int kBins = 4;
    for (const Source source : {Source::Sequence, Source::BlueNoise}) {
        CAPTURE(sourceName(source));
        std::array<int, kBins * kBins> histogram{};
        int kept = 0, total = 0;
        for (uint32_t frame = 0; frame < 64; ++frame) {
            for (uint32_t y = 0; y < 64; ++y) {
                for (uint32_t x = 0; x < 64; ++x) {
                    ++total;
                    const auto v = draw(source, {x, y}, frame);
                    if (v[3] >= kShare) continue;
                    ++kept;
                    ++histogram[size_t(int(v[1] * kBins) * kBins + int(v[0] * kBins))];
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
}

namespace {

// Variance of the means of b x b blocks of a slice (space) or of b
// consecutive frames of a pixel (time), against what white noise gives:
// blue noise has little low-frequency energy, so its block means vary less.
double blockMeanVariance(const std::vector<double>& v, sampling::BlueNoiseSize size, bool space, uint32_t b) {
    std::vector<double> means;
    const uint32_t w = size.width, h = size.height, d = size.depth;
    const auto at = [&](uint32_t x, uint32_t y, uint32_t t) { return v[(size_t(t) * h + y) * w + x]; };
    if (space) {
        for (uint32_t t = 0; t < d; ++t)
            for (uint32_t y = 0; y < h; y += b)
                for (uint32_t x = 0; x < w; x += b) {
                    double sum = 0.0;
                    for (uint32_t j = 0; j < b; ++j)
                        for (uint32_t i = 0; i < b; ++i) sum += at(x + i, y + j, t);
                    means.push_back(sum / (b * b));
                }
    } else {
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x)
                for (uint32_t t = 0; t < d; t += b) {
                    double sum = 0.0;
                    for (uint32_t k = 0; k < b; ++k) sum += at(x, y, t + k);
                    means.push_back(sum / b);
                }
    }
    double mean = 0.0, variance = 0.0;
    for (const double m : means) mean += m / means.size();
    for (const double m : means) variance += (m - mean) * (m - mean) / means.size();
    return variance;
}

} // namespace

TEST_CASE("spatiotemporal blue noise: every rank once, blue in every slice and every pixel's frames, deterministic") {
    const sampling::BlueNoiseSize size{32, 32, 16};
    const std::vector<uint32_t> ranks = sampling::spatiotemporalBlueNoise(size, 7);
    REQUIRE(ranks.size() == size.texels());
    std::vector<uint8_t> seen(ranks.size(), 0);
    for (const uint32_t r : ranks) {
        REQUIRE(r < ranks.size());
        CHECK(seen[r] == 0);
        seen[r] = 1;
    }
    std::vector<double> blue(ranks.size()), white(ranks.size());
    std::mt19937 random(3);
    for (size_t i = 0; i < ranks.size(); ++i) {
        blue[i] = (ranks[i] + 0.5) / ranks.size();
        white[i] = std::uniform_real_distribution<double>(0.0, 1.0)(random);
    }
    // White noise: variance 1/12 / 16 for 4x4 blocks and 1/12 / 4 for 4
    // frames. Measured on this generator: 0.21 and 0.19 of white's.
    const double space = blockMeanVariance(blue, size, true, 4) / blockMeanVariance(white, size, true, 4);
    const double time = blockMeanVariance(blue, size, false, 4) / blockMeanVariance(white, size, false, 4);
    CAPTURE(space);
    CAPTURE(time);
    CHECK(space < 0.35);
    CHECK(time < 0.35);
    CHECK(sampling::spatiotemporalBlueNoise(size, 7) == ranks);
    CHECK(sampling::spatiotemporalBlueNoise(size, 8) != ranks);
    CHECK_THROWS_AS(sampling::spatiotemporalBlueNoise({24, 32, 16}, 1), std::invalid_argument);
}

TEST_CASE("the build's blue noise file has the size the shaders read, its channels independent; bad files are refused "
          "by name") {
    const sampling::BlueNoiseTexture texture = sampling::readBlueNoise(GLINT_BLUE_NOISE_FILE);
    CHECK(texture.size.width == shader::kBlueNoiseWidth);
    CHECK(texture.size.height == shader::kBlueNoiseHeight);
    CHECK(texture.size.depth == shader::kBlueNoiseDepth);
    CHECK(texture.channels == shader::kBlueNoiseChannels);

    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "glint_noise_test";
    std::filesystem::create_directories(dir);
    const sampling::BlueNoiseTexture small = sampling::makeBlueNoiseTexture({8, 8, 4}, 3, 11);
    sampling::writeBlueNoise(dir / "small.bin", small);
    const sampling::BlueNoiseTexture back = sampling::readBlueNoise(dir / "small.bin");
    CHECK(back.values == small.values);
    CHECK(back.channels == 3u);
    // Three channels in two words per texel, the third beside a zero.
    const std::vector<uint32_t> words = sampling::blueNoiseWords(small);
    CHECK(words.size() == 2u * 8u * 8u * 4u);
    const uint32_t third = words[1] >> 16, second = words[0] >> 16, first = words[0] & 0xFFFFu;
    CHECK(third == 0u);
    CHECK(first == small.values[0]);
    CHECK(second == small.values[1]);

    const auto refused = [&](const std::string& name, const std::string& bytes) {
        {
            std::ofstream out(dir / name, std::ios::binary);
            out << bytes;
        }
        try {
            sampling::readBlueNoise(dir / name);
            return std::string("accepted");
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
    };
    std::string good;
    {
        std::ifstream in(dir / "small.bin", std::ios::binary);
        good.assign(std::istreambuf_iterator<char>(in), {});
    }
    CHECK(refused("empty.bin", "").find("empty.bin") != std::string::npos);
    CHECK(refused("png.bin", "\x89PNG....................").find("not a Glint blue noise") != std::string::npos);
    CHECK(refused("short.bin", good.substr(0, good.size() - 2)).find("truncated") != std::string::npos);
    CHECK(refused("long.bin", good + "x").find("trailing") != std::string::npos);
    CHECK_THROWS_WITH_AS(sampling::readBlueNoise(dir / "missing.bin"), doctest::Contains("missing.bin"),
                         std::runtime_error);
    std::filesystem::remove_all(dir);
}
