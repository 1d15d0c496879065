// relMSE, PSNR and SSIM on images with answers known in closed form.

#include "glint/metrics/pixel_metrics.h"

#include <doctest/doctest.h>
#include <glm/common.hpp>

#include <cmath>
#include <stdexcept>

using namespace glint::metrics;

namespace {

Image linearImage(uint32_t width, uint32_t height, glm::vec3 value, const char* name) {
    return Image{width, height, std::vector<glm::vec3>(size_t(width) * height, value), name};
}

Image srgbImage(uint32_t width, uint32_t height, uint8_t value, const char* name) {
    return imageFromSrgb8(width, height, std::vector<uint8_t>(size_t(width) * height * 3, value), 3, name);
}

// A deterministic texture with every 8-bit level in use.
Image texture(uint32_t width, uint32_t height) {
    std::vector<uint8_t> rgb(size_t(width) * height * 3);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t((i * 2654435761u) >> 13);
    return imageFromSrgb8(width, height, rgb, 3, "texture");
}

} // namespace

TEST_CASE("identical images: relMSE 0, PSNR infinite, SSIM 1") {
    const Image a = texture(32, 24);
    CHECK(relMse(a, a) == 0.0);
    CHECK(std::isinf(psnr(a, a)));
    CHECK(psnr(a, a) > 0.0);
    CHECK(ssim(a, a) == doctest::Approx(1.0).epsilon(1e-12));
}

TEST_CASE("relMSE of a constant offset is (offset^2 / (r^2 + 0.01)) averaged over channels") {
    const glm::vec3 r(0.25f, 0.5f, 1.0f);
    const Image ref = linearImage(7, 5, r, "ref");
    const Image test = linearImage(7, 5, r + 0.25f, "test");
    const double expected = (0.0625 / (0.0625 + 0.01) + 0.0625 / (0.25 + 0.01) + 0.0625 / (1.0 + 0.01)) / 3.0;
    CHECK(relMse(ref, test) == doctest::Approx(expected).epsilon(1e-12));
    CHECK(relMse(ref, test, 1.0) == doctest::Approx((0.0625 / 1.0625 + 0.0625 / 1.25 + 0.0625 / 2.0) / 3.0));
    // Relative: the same offset on a black reference is 1 / 0.01 times its square.
    CHECK(relMse(linearImage(2, 2, glm::vec3(0.0f), "black"), linearImage(2, 2, glm::vec3(0.1f), "dim")) ==
          doctest::Approx(1.0).epsilon(1e-6));
}

TEST_CASE("PSNR of a constant 8-bit offset d is 20 log10(255 / d)") {
    CHECK(psnr(srgbImage(9, 4, 100, "ref"), srgbImage(9, 4, 110, "test")) ==
          doctest::Approx(20.0 * std::log10(255.0 / 10.0)).epsilon(1e-6));
    CHECK(psnr(srgbImage(9, 4, 0, "black"), srgbImage(9, 4, 255, "white")) == doctest::Approx(0.0).scale(1));
    // Half the pixels off by 51: MSE = 0.5 * 0.2^2.
    Image half = srgbImage(4, 4, 51, "half");
    const Image ref = srgbImage(4, 4, 102, "ref");
    for (size_t i = 0; i < 8; ++i) half.linear[i] = ref.linear[i];
    CHECK(psnr(ref, half) == doctest::Approx(-10.0 * std::log10(0.5 * 0.04)).epsilon(1e-6));
}

TEST_CASE("SSIM of two flat images is the luminance term alone") {
    // No variance: SSIM = (2 a b + C1) / (a^2 + b^2 + C1), C1 = 0.0001.
    const double a = 64.0 / 255.0, b = 192.0 / 255.0;
    const double expected = (2.0 * a * b + 1e-4) / (a * a + b * b + 1e-4);
    CHECK(ssim(srgbImage(16, 16, 64, "dark"), srgbImage(16, 16, 192, "light")) ==
          doctest::Approx(expected).epsilon(1e-6));
}

TEST_CASE("SSIM of a flat image against a pattern is the contrast term C2 / (var + C2) under each window") {
    // Reference flat at 0.5 (display value 128/255 would not be exact, so
    // build linear values whose encoding is 0.5 +- 0.25 row by row): with
    // stripes along x that alternate by row, every window position sees the
    // same weighted mean and variance, worked out from the 1D Gaussian weights.
    const uint32_t size = 24;
    Image flat = linearImage(size, size, glm::vec3(srgbToLinear(0.5f)), "flat");
    Image stripes = flat;
    stripes.name = "stripes";
    for (uint32_t y = 0; y < size; ++y) {
        const float v = srgbToLinear(y % 2 ? 0.75f : 0.25f);
        for (uint32_t x = 0; x < size; ++x) stripes.linear[y * size + x] = glm::vec3(v);
    }
    // Window rows r = -5..5 with weights w_r; the window's rows alternate in
    // sign s_r = +-1 around 0.5. Mean m = 0.5 + 0.25 S, S = sum w_r s_r;
    // variance 0.0625 (1 - S^2); windows starting on even and odd rows have
    // S of opposite sign and the same |S|.
    double weights[11], total = 0.0;
    for (int r = -5; r <= 5; ++r) total += weights[r + 5] = std::exp(-double(r * r) / 4.5);
    double s = 0.0;
    for (int r = -5; r <= 5; ++r) s += weights[r + 5] / total * (r % 2 ? -1.0 : 1.0);
    const double variance = 0.0625 * (1.0 - s * s);
    const double c1 = 1e-4, c2 = 9e-4;
    const auto windowSsim = [&](double mean) {
        return (2.0 * 0.5 * mean + c1) / (0.25 + mean * mean + c1) * c2 / (variance + c2);
    };
    // Window centres on rows 5..18: half start with sign +, half with -.
    const double expected = 0.5 * (windowSsim(0.5 + 0.25 * s) + windowSsim(0.5 - 0.25 * s));
    CHECK(ssim(flat, stripes) == doctest::Approx(expected).epsilon(1e-5));
    CHECK(ssim(stripes, flat) == doctest::Approx(expected).epsilon(1e-5));
}

TEST_CASE("SSIM falls as noise grows and works on images smaller than its window") {
    const Image ref = texture(40, 30);
    Image slight = ref, strong = ref;
    for (size_t i = 0; i < ref.linear.size(); ++i) {
        const float n = float(int((i * 7919u) % 21u) - 10) / 10.0f;
        slight.linear[i] = glm::clamp(ref.linear[i] + 0.01f * n, 0.0f, 1.0f);
        strong.linear[i] = glm::clamp(ref.linear[i] + 0.2f * n, 0.0f, 1.0f);
    }
    const double a = ssim(ref, slight), b = ssim(ref, strong);
    CHECK(a < 1.0);
    CHECK(b < a);
    CHECK(ssim(texture(5, 3), texture(5, 3)) == doctest::Approx(1.0));
    CHECK(ssim(srgbImage(1, 1, 64, "a"), srgbImage(1, 1, 192, "b")) ==
          doctest::Approx((2.0 * 64 * 192 / 65025.0 + 1e-4) / ((64.0 * 64 + 192.0 * 192) / 65025.0 + 1e-4)).epsilon(1e-6));
}

TEST_CASE("every metric refuses images of different sizes, naming both") {
    const Image a = linearImage(4, 4, glm::vec3(0.5f), "a.png"), b = linearImage(4, 5, glm::vec3(0.5f), "b.png");
    const char* message = "image sizes differ: reference 'a.png' is 4x4, test 'b.png' is 4x5";
    CHECK_THROWS_WITH_AS(relMse(a, b), message, std::invalid_argument);
    CHECK_THROWS_WITH_AS(psnr(a, b), message, std::invalid_argument);
    CHECK_THROWS_WITH_AS(ssim(a, b), message, std::invalid_argument);
}
