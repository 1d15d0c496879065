// FLIP on images small enough to work out by hand, and the pooling rules.

#include "glint/metrics/flip.h"

#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>

using namespace glint::metrics;

namespace {

Image uniform(uint32_t width, uint32_t height, glm::vec3 linear, const char* name) {
    return Image{width, height, std::vector<glm::vec3>(size_t(width) * height, linear), name};
}

// cmax of section 4.1: (HyAB between Hunt-adjusted L*a*b* of linear green
// (0,1,0) and blue (0,0,1))^0.7. With the sRGB primaries and D65 white
// (0.31271, 0.32902): green L*a*b* (87.7362, -86.1787, 83.1826) -> Hunt
// (87.7362, -75.6099, 72.9812); blue (32.2982, 79.1936, -107.8586) -> Hunt
// (32.2982, 25.5781, -34.8364); HyAB = 55.4380 + 147.8636 = 203.3017,
// cmax = 203.3017^0.7 = 41.27610.
constexpr double kCmax = 41.27610;

// The colour error for a colour difference d (HyAB), section 4.1.
double colourError(double hyab) {
    const double e = std::pow(hyab, 0.7);
    return e < 0.4 * kCmax ? 0.95 / 0.4 * e / kCmax : 0.95 + (e - 0.4 * kCmax) / (kCmax - 0.4 * kCmax) * 0.05;
}

} // namespace

TEST_CASE("FLIP of identical images is zero everywhere") {
    Image a = uniform(16, 12, {0.2f, 0.5f, 0.9f}, "a");
    for (size_t i = 0; i < a.linear.size(); ++i) a.linear[i] = glm::vec3(float(i % 7) / 6.0f, 0.3f, float(i % 5) / 4.0f);
    const FlipResult r = flip(a, a);
    for (float e : r.errorMap) REQUIRE(e == 0.0f);
    CHECK(r.stats.mean == 0.0);
    CHECK(r.stats.weightedMedian == 0.0);
    CHECK(r.stats.max == 0.0);
}

TEST_CASE("FLIP of a uniform pair is the colour term alone, worked out by hand") {
    // Uniform images: every normalised filter returns the image unchanged and
    // every edge and point response is zero, so FLIP = colour error^(1 - 0).
    SUBCASE("black against white: L* 0 against 100, HyAB 100, above the knee") {
        // 100^0.7 = 25.1189 >= 0.4 cmax = 16.5104: 0.95 + (25.1189 - 16.5104) / 24.7657 * 0.05
        const double expected = 0.967380;
        CHECK(colourError(100.0) == doctest::Approx(expected).epsilon(1e-6));
        const FlipResult r = flip(uniform(5, 4, glm::vec3(0.0f), "black"), uniform(5, 4, glm::vec3(1.0f), "white"));
        for (float e : r.errorMap) CHECK(e == doctest::Approx(expected).epsilon(1e-5));
        CHECK(r.stats.mean == doctest::Approx(expected).epsilon(1e-5));
    }
    SUBCASE("grey 0.5 against 0.6 linear: neutral, so only L* = 116 Y^(1/3) - 16 differs") {
        // L*(0.5) = 76.06926, L*(0.6) = 81.83819, HyAB 5.76893; 5.76893^0.7 = 3.41010
        // < 16.5104: 0.95 / 0.4 * 3.41010 / 41.27610 = 0.196215
        const double expected = 0.196215;
        CHECK(colourError(81.83819 - 76.06926) == doctest::Approx(expected).epsilon(1e-5));
        const FlipResult r = flip(uniform(3, 7, glm::vec3(0.5f), "grey50"), uniform(3, 7, glm::vec3(0.6f), "grey60"));
        for (float e : r.errorMap) CHECK(e == doctest::Approx(expected).epsilon(1e-4));
    }
    SUBCASE("the most different colours of the gamut, green against blue, give 1") {
        const FlipResult r =
            flip(uniform(4, 4, {0.0f, 1.0f, 0.0f}, "green"), uniform(4, 4, {0.0f, 0.0f, 1.0f}, "blue"));
        for (float e : r.errorMap) CHECK(e == doctest::Approx(1.0).epsilon(1e-5));
    }
}

TEST_CASE("FLIP is symmetric and an edge missing from the test image shows where the edge was") {
    // Reference: a vertical white line on grey; test: grey only.
    Image ref = uniform(40, 24, glm::vec3(0.3f), "line");
    const Image test = uniform(40, 24, glm::vec3(0.3f), "flat");
    for (uint32_t y = 0; y < ref.height; ++y) ref.linear[y * ref.width + 20] = glm::vec3(1.0f);
    const FlipResult forward = flip(ref, test);
    const FlipResult backward = flip(test, ref);
    for (size_t i = 0; i < forward.errorMap.size(); ++i) {
        CHECK(forward.errorMap[i] == doctest::Approx(backward.errorMap[i]).epsilon(1e-6));
    }
    const float onLine = forward.errorMap[12 * 40 + 20];
    CHECK(onLine == doctest::Approx(forward.stats.max));
    CHECK(onLine > 0.5f);
    CHECK(forward.errorMap[12 * 40 + 2] < 1e-3f);  // far from the line (beyond both filter radii)
    for (uint32_t x = 20; x < 30; ++x) {
        CHECK(forward.errorMap[12 * 40 + x + 1] <= forward.errorMap[12 * 40 + x]);  // falls off with distance
    }
}

TEST_CASE("FLIP filter radii follow the viewing distance") {
    // Colour: 3 sigma of the widest CSF Gaussian, sigma = sqrt(0.04 / (2 pi^2)) degrees:
    // ceil(3 * 0.0450158 * ppd). Features: ceil(3 * 0.5 * 0.082 * ppd).
    CHECK(flipColorFilterRadius(kDefaultPpd) == 10);  // 9.051
    CHECK(flipFeatureFilterRadius(kDefaultPpd) == 9); // 8.244
    CHECK(flipColorFilterRadius(30.0) == 5);          // 4.051
    CHECK(flipFeatureFilterRadius(30.0) == 4);        // 3.69
    CHECK(flipColorFilterRadius(100.0) == 14);        // 13.505
    CHECK(flipFeatureFilterRadius(100.0) == 13);      // 12.3
    CHECK(float(kDefaultPpd) == doctest::Approx(67.020645).epsilon(1e-8));
}

TEST_CASE("FLIP works on images smaller than its filters") {
    const FlipResult r = flip(uniform(1, 1, glm::vec3(0.0f), "a"), uniform(1, 1, glm::vec3(1.0f), "b"), 100.0);
    REQUIRE(r.errorMap.size() == 1);
    CHECK(r.errorMap[0] == doctest::Approx(0.967380).epsilon(1e-5));
}

TEST_CASE("FLIP refuses images of different sizes, naming both") {
    const Image a = uniform(4, 3, glm::vec3(0.5f), "ref.png");
    const Image b = uniform(3, 4, glm::vec3(0.5f), "test.png");
    CHECK_THROWS_WITH_AS(flip(a, b), "image sizes differ: reference 'ref.png' is 4x3, test 'test.png' is 3x4",
                         std::invalid_argument);
    CHECK_THROWS_AS(flip(a, a, 0.0), std::invalid_argument);
}

TEST_CASE("weighted percentiles return the first value whose running sum is strictly greater") {
    // Sorted 0.25 0.25 0.5, running sums 0.25 0.5 1.0 of the total 1.0:
    // the median needs a sum > 0.5, so it is 0.5, not the 0.25 that reaches 0.5 exactly.
    const float errors[] = {0.5f, 0.25f, 0.25f};
    const FlipStats s = poolFlipErrors(errors);
    CHECK(s.weightedQ1 == 0.25);
    CHECK(s.weightedMedian == 0.5);
    CHECK(s.weightedQ3 == 0.5);
    CHECK(s.min == 0.25);
    CHECK(s.max == 0.5);
    CHECK(s.mean == doctest::Approx(1.0 / 3.0));

    const float spread[] = {0.1f, 0.4f, 0.2f, 0.3f};  // running 0.1 0.3 0.6 1.0
    const FlipStats t = poolFlipErrors(spread);
    CHECK(t.weightedQ1 == doctest::Approx(0.2));
    CHECK(t.weightedMedian == doctest::Approx(0.3));
    CHECK(t.weightedQ3 == doctest::Approx(0.4));
}

TEST_CASE("the FLIP mean is a float running sum in row-major order, as the official tool prints it") {
    // 1 followed by 1000 values of 1e-8: each addition to a float 1.0 is lost.
    std::vector<float> errors(1001, 1e-8f);
    errors[0] = 1.0f;
    CHECK(poolFlipErrors(errors).mean == 1.0 / 1001.0);
    // In the other order the small values add up first.
    std::swap(errors[0], errors[1000]);
    CHECK(poolFlipErrors(errors).mean > 1.0 / 1001.0);
    CHECK(poolFlipErrors(std::vector<float>(9, 0.0f)).weightedMedian == 0.0);
}
