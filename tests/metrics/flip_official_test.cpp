// Our FLIP against the official NVlabs tool (v1.6): ../shared/flip/EXPECTED.md
// lists what `flip -r reference.png -t posterize3.png [-ppd N]` prints, where
// posterize3 is reference.png with the 5 low bits of every channel cleared.

#include "glint/metrics/flip.h"

#include <doctest/doctest.h>

#include <string>

using namespace glint::metrics;

namespace {

struct PosterisedPair {
    Image reference;
    Image test;
};

const PosterisedPair& posterisedPair() {
    static const PosterisedPair pair = [] {
        uint32_t width = 0, height = 0;
        std::vector<uint8_t> rgb = loadRgb8(std::string(GLINT_FLIP_DIR) + "/reference.png", width, height);
        PosterisedPair p;
        p.reference = imageFromSrgb8(width, height, rgb, 3, "reference.png");
        for (uint8_t& v : rgb) v &= 0xE0;
        p.test = imageFromSrgb8(width, height, rgb, 3, "posterize3");
        return p;
    }();
    return pair;
}

struct Printed {
    double ppd;
    double mean, median, q1, q3, min, max;
};

void checkAgainstTool(const Printed& expected) {
    const PosterisedPair& pair = posterisedPair();
    REQUIRE(pair.reference.width == 1920);
    REQUIRE(pair.reference.height == 1080);
    const FlipStats s = flip(pair.reference, pair.test, expected.ppd).stats;
    MESSAGE("ppd " << expected.ppd << ": mean " << s.mean << " median " << s.weightedMedian << " q1 " << s.weightedQ1
                   << " q3 " << s.weightedQ3 << " min " << s.min << " max " << s.max);
    // The tool prints six decimals; its mean is a float sum, reproduced here.
    CHECK(std::abs(s.mean - expected.mean) < 1e-4);
    CHECK(std::abs(s.weightedMedian - expected.median) < 1e-3);
    CHECK(std::abs(s.weightedQ1 - expected.q1) < 1e-3);
    CHECK(std::abs(s.weightedQ3 - expected.q3) < 1e-3);
    CHECK(std::abs(s.min - expected.min) < 1e-3);
    CHECK(std::abs(s.max - expected.max) < 1e-3);
}

} // namespace

TEST_CASE("FLIP matches the official tool at its default 67.02 pixels per degree") {
    checkAgainstTool({kDefaultPpd, 0.267398, 0.279112, 0.251152, 0.309781, 0.002186, 0.535080});
}

TEST_CASE("FLIP matches the official tool at 30 pixels per degree") {
    checkAgainstTool({30.0, 0.275671, 0.302341, 0.256166, 0.341956, 0.000336, 0.554013});
}

TEST_CASE("FLIP matches the official tool at 100 pixels per degree") {
    checkAgainstTool({100.0, 0.266615, 0.275321, 0.250999, 0.302903, 0.012310, 0.542502});
}
