// The motion metrics on images whose answer is known: a trail of known
// energy, a known shift, a known shimmer, errors split by roughness band.
#include "glint/metrics/motion_metrics.h"

#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

using namespace glint::metrics;

namespace {

constexpr uint32_t kWidth = 32, kHeight = 16;

Image black(const char* name) {
    return {kWidth, kHeight, std::vector<glm::vec3>(kWidth * kHeight, glm::vec3(0.0f)), name};
}

// A 4x4 block of `value` with its top-left corner at (x, y).
void block(Image& image, uint32_t x, uint32_t y, glm::vec3 value) {
    for (uint32_t row = y; row < y + 4; ++row) {
        for (uint32_t col = x; col < x + 4; ++col) image.linear[size_t(row) * kWidth + col] = value;
    }
}

} // namespace

TEST_CASE("a trail of a quarter of the object's brightness behind it is a ghost energy of 0.25") {
    // A grey background the object's renders share, with a bias of the
    // test renderer's own: comparing contributions leaves the bias out.
    Image without = black("without"), testWithout = black("test without");
    for (glm::vec3& c : without.linear) c = glm::vec3(0.2f);
    for (glm::vec3& c : testWithout.linear) c = glm::vec3(0.3f);
    Image reference = without;
    block(reference, 20, 6, glm::vec3(1.2f));
    const Contribution ref = contribution(reference, without);
    const std::vector<uint8_t> inside = footprint(ref);
    size_t count = 0;
    for (const uint8_t v : inside) count += v;
    CHECK(count == 16);
    // Grown by a pixel each way: 6x6.
    size_t grown = 0;
    for (const uint8_t v : footprint(ref, 1e-3f, 1)) grown += v;
    CHECK(grown == 36);
    // At the image's corner the square is cut off: 5x5 of a block at (0, 0).
    Image corner = without;
    block(corner, 0, 0, glm::vec3(1.2f));
    size_t cut = 0;
    for (const uint8_t v : footprint(contribution(corner, without), 1e-3f, 1)) cut += v;
    CHECK(cut == 25);

    CHECK(ghostEnergy(ref, ref, inside) == doctest::Approx(0.0));
    Image same = testWithout;
    block(same, 20, 6, glm::vec3(1.3f));
    CHECK(ghostEnergy(ref, contribution(same, testWithout), inside) == doctest::Approx(0.0));
    Image trailing = same;
    block(trailing, 10, 6, glm::vec3(0.55f));  // a quarter of the object's 1.0 left behind
    CHECK(ghostEnergy(ref, contribution(trailing, testWithout), inside) == doctest::Approx(0.25));
    // A dark trail (the object hid something) counts by its magnitude.
    Image dark = same;
    block(dark, 10, 6, glm::vec3(0.05f));
    CHECK(ghostEnergy(ref, contribution(dark, testWithout), inside) == doctest::Approx(0.25));

    CHECK_THROWS_WITH_AS(ghostEnergy(ref, ref, std::vector<uint8_t>(kWidth * kHeight, 0)),
                         doctest::Contains("contributes nothing inside the footprint"), std::invalid_argument);
    CHECK_THROWS_AS(ghostEnergy(ref, ref, std::vector<uint8_t>(3, 1)), std::invalid_argument);
    Image small = black("small");
    small.width = 3;
    small.height = 1;
    small.linear.resize(3);
    CHECK_THROWS_AS(contribution(reference, small), std::invalid_argument);
}

TEST_CASE("a reflection three pixels behind lags by three pixels") {
    const Image without = black("without");
    Image reference = black("reference"), late = black("late");
    block(reference, 20, 6, glm::vec3(0.8f, 0.5f, 0.2f));
    block(late, 17, 6, glm::vec3(0.8f, 0.5f, 0.2f));
    const Contribution ref = contribution(reference, without);
    CHECK(lagPixels(ref, ref) == doctest::Approx(0.0));
    CHECK(lagPixels(ref, contribution(late, without)) == doctest::Approx(3.0));
    CHECK_THROWS_WITH_AS(lagPixels(ref, contribution(without, without)), doctest::Contains("zero everywhere"),
                         std::invalid_argument);
}

TEST_CASE("flicker is the mean absolute change between frames: zero when still") {
    Image a = black("a");
    std::vector<Image> still(4, a);
    CHECK(flicker(still) == 0.0);
    Image b = a;
    b.linear[5] = glm::vec3(0.4f, 0.0f, 0.0f);  // one channel of one pixel shimmers by 0.4
    const std::vector<Image> shimmer = {a, b, a, b};
    CHECK(flicker(shimmer) == doctest::Approx(0.4 / (kWidth * kHeight * 3.0)));
    CHECK_THROWS_AS(flicker(std::vector<Image>{a}), std::invalid_argument);
    Image small = a;
    small.linear.resize(3);
    CHECK_THROWS_AS(flicker(std::vector<Image>{a, small}), std::invalid_argument);
}

TEST_CASE("FLIP's error is pooled per roughness band of the reflecting surface") {
    CHECK(roughnessBand(0.0f) == 0);
    CHECK(roughnessBand(0.05f) == 1);
    CHECK(roughnessBand(0.22f) == 2);
    CHECK(roughnessBand(0.5f) == 3);
    CHECK(roughnessBand(1.0f) == 3);
    FlipResult error;
    error.errorMap = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.3f};
    const std::vector<float> roughness = {0.0f, 0.1f, 0.3f, 0.9f, -1.0f, 0.04f};  // -1: sky, left out
    const auto bands = flipByRoughness(error, roughness);
    CHECK(bands[0].pixels == 2);
    CHECK(bands[0].flipMean == doctest::Approx(0.2));
    CHECK(bands[1].flipMean == doctest::Approx(0.2));
    CHECK(bands[2].flipMean == doctest::Approx(0.3));
    CHECK(bands[3].flipMean == doctest::Approx(0.4));
    const auto empty = flipByRoughness(FlipResult{}, {});
    CHECK(std::isnan(empty[0].flipMean));
    CHECK_THROWS_AS(flipByRoughness(error, std::vector<float>(2, 0.0f)), std::invalid_argument);
}
