// PNG input as the official FLIP tool decodes it, and error maps out.

#include "glint/metrics/error_map.h"
#include "glint/metrics/image.h"

#include <doctest/doctest.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

using namespace glint::metrics;

namespace {
std::filesystem::path outputDir() {
    const std::filesystem::path dir = GLINT_TEST_OUTPUT_DIR;
    std::filesystem::create_directories(dir);
    return dir;
}
} // namespace

TEST_CASE("8-bit values are sRGB, linearised with the piecewise curve") {
    const uint8_t rgb[] = {0, 10, 255, 128, 64, 200};
    const Image image = imageFromSrgb8(2, 1, rgb, 3, "pixels");
    CHECK(image.linear[0].x == 0.0f);
    CHECK(image.linear[0].y == doctest::Approx(10.0 / 255.0 / 12.92).epsilon(1e-6));  // linear segment
    CHECK(image.linear[0].z == 1.0f);
    CHECK(image.linear[1].x == doctest::Approx(std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4)).epsilon(1e-6));
    CHECK(image.linear[1].y == doctest::Approx(0.0512695).epsilon(1e-5));
    const uint8_t rgba[] = {255, 0, 128, 7};  // a fourth channel is ignored
    CHECK(imageFromSrgb8(1, 1, rgba, 4, "rgba").linear[0] == glm::vec3(1.0f, 0.0f, image.linear[1].x));
    CHECK_THROWS_AS(imageFromSrgb8(2, 2, rgba, 4, "short"), std::invalid_argument);
    for (int v = 0; v < 256; ++v) {
        CHECK(std::lround(linearToSrgb(srgbToLinear(float(v) / 255.0f)) * 255.0f) == v);
    }
}

TEST_CASE("a PNG's alpha is dropped, not composited") {
    const std::filesystem::path path = outputDir() / "rgba.png";
    const uint8_t rgba[] = {255, 0, 0, 0, 0, 255, 0, 128};  // transparent red, half-transparent green
    REQUIRE(stbi_write_png(path.string().c_str(), 2, 1, 4, rgba, 8));
    const Image image = loadPng(path);
    CHECK(image.width == 2);
    CHECK(image.height == 1);
    CHECK(image.name == path.string());
    CHECK(image.linear[0] == glm::vec3(1.0f, 0.0f, 0.0f));
    CHECK(image.linear[1] == glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST_CASE("loading a missing or broken image names the file") {
    CHECK_THROWS_WITH_AS(loadPng("/nonexistent/ref.png"),
                         doctest::Contains("cannot read image '/nonexistent/ref.png'"), std::runtime_error);
    const std::filesystem::path broken = outputDir() / "broken.png";
    std::FILE* f = std::fopen(broken.string().c_str(), "wb");
    REQUIRE(f);
    std::fputs("not a png", f);
    std::fclose(f);
    CHECK_THROWS_WITH_AS(loadPng(broken), doctest::Contains("broken.png"), std::runtime_error);
}

TEST_CASE("the error map goes through magma, dark for no error and pale yellow for the largest") {
    // matplotlib's magma: 0 -> (0.001462, 0.000466, 0.013866), 1 -> (0.987053, 0.991438, 0.749504).
    const glm::vec3 low = magma(0.0f), high = magma(1.0f);
    CHECK(low.x == doctest::Approx(0.001462).epsilon(0.02).scale(1));
    CHECK(low.z == doctest::Approx(0.013866).epsilon(0.02).scale(1));
    CHECK(high.x == doctest::Approx(0.987053).epsilon(0.02).scale(1));
    CHECK(high.y == doctest::Approx(0.991438).epsilon(0.02).scale(1));
    CHECK(high.z == doctest::Approx(0.749504).epsilon(0.02).scale(1));
    float previous = -1.0f;
    for (int i = 0; i <= 100; ++i) {  // lightness rises monotonically along the ramp
        const glm::vec3 c = magma(float(i) / 100.0f);
        const float luma = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
        CHECK(luma > previous);
        previous = luma;
    }

    const std::filesystem::path path = outputDir() / "error_map.png";
    const float errors[] = {0.0f, 0.5f, 1.0f, 2.0f, -1.0f, std::numeric_limits<float>::quiet_NaN()};
    writeErrorMap(path, errors, 3, 2);
    int w = 0, h = 0, comp = 0;
    stbi_uc* pixels = stbi_load(path.string().c_str(), &w, &h, &comp, 3);
    REQUIRE(pixels);
    CHECK(w == 3);
    CHECK(h == 2);
    CHECK(pixels[0 * 3 + 2] < 8);      // 0: nearly black
    CHECK(pixels[2 * 3 + 0] > 245);    // 1: pale yellow
    CHECK(pixels[3 * 3 + 0] == pixels[2 * 3 + 0]);  // above 1 clamps
    CHECK(pixels[4 * 3 + 0] == pixels[0 * 3 + 0]);  // below 0 clamps
    stbi_image_free(pixels);
    CHECK_THROWS_AS(writeErrorMap(path, errors, 4, 2), std::invalid_argument);
}
