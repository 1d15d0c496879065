// The packed primitive layout and octahedral normals of glint/packing.h, run
// through the same code the compute and hit shaders compile.

#include "glint/packing.h"

#include <doctest/doctest.h>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <random>

using namespace glint::shader;

namespace {

// In double, and through atan2: acos of a dot product near 1 cannot
// resolve the small angles measured here.
double angleDegrees(const glm::vec3& a, const glm::vec3& b) {
    const glm::dvec3 da = glm::normalize(glm::dvec3(a));
    const glm::dvec3 db = glm::normalize(glm::dvec3(b));
    return std::atan2(glm::length(glm::cross(da, db)), glm::dot(da, db)) * 180.0 / glm::pi<double>();
}

// 1M directions: a Fibonacci lattice (even coverage, both poles and the
// octahedron's folds included) plus random ones, with a fixed seed.
std::vector<glm::vec3> testDirections() {
    std::vector<glm::vec3> dirs;
    const int lattice = 500000;
    const double golden = glm::pi<double>() * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < lattice; ++i) {
        const double y = 1.0 - 2.0 * (i + 0.5) / lattice;
        const double r = std::sqrt(1.0 - y * y);
        dirs.emplace_back(float(r * std::cos(golden * i)), float(y), float(r * std::sin(golden * i)));
    }
    std::mt19937 rng(42);
    std::normal_distribution<float> normal;
    while (dirs.size() < 1000000) {
        const glm::vec3 v(normal(rng), normal(rng), normal(rng));
        if (glm::length(v) > 1e-3f) {
            dirs.push_back(glm::normalize(v));
        }
    }
    for (float s : {-1.0f, 1.0f}) {  // the axes and the fold diagonals exactly
        dirs.emplace_back(s, 0.0f, 0.0f);
        dirs.emplace_back(0.0f, s, 0.0f);
        dirs.emplace_back(0.0f, 0.0f, s);
        dirs.push_back(glm::normalize(glm::vec3(s, s, -1.0f)));
        dirs.push_back(glm::normalize(glm::vec3(s, -s, -1.0f)));
    }
    return dirs;
}

} // namespace

TEST_CASE(
    "octahedral normals in 16 bits stay within 1 degree with rounding and 0.65 degrees with the precise encoder") {
    double maxRounded = 0.0, maxPrecise = 0.0;
    size_t preciseWorse = 0;
    for (const glm::vec3& n : testDirections()) {
        const double rounded = angleDegrees(unpackOctNormal(packOctNormal(n)), n);
        const double precise = angleDegrees(unpackOctNormal(packOctNormalPrecise(n)), n);
        maxRounded = std::max(maxRounded, rounded);
        maxPrecise = std::max(maxPrecise, precise);
        preciseWorse += precise > rounded + 1e-6 ? 1 : 0;
    }
    MESSAGE("max error: rounded " << maxRounded << " deg, precise " << maxPrecise << " deg");
    CHECK(maxRounded <= 1.0);
    CHECK(maxPrecise <= 0.65);
    CHECK(preciseWorse == 0);
}

TEST_CASE("octahedral decode of any 16-bit code is a unit vector") {
    for (uint32_t code = 0; code < 65536; ++code) {
        const glm::vec3 n = unpackOctNormal(code);
        REQUIRE(std::abs(glm::length(n) - 1.0f) < 1e-5f);
    }
}

TEST_CASE("axis normals survive octahedral quantisation exactly") {
    for (const glm::vec3& axis : {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, -1, 0),
                                  glm::vec3(0, 0, 1), glm::vec3(0, 0, -1)}) {
        CHECK(unpackOctNormal(packOctNormal(axis)) == axis);
        CHECK(unpackOctNormal(packOctNormalPrecise(axis)) == axis);
    }
}

TEST_CASE("8-bit unorm and snorm codes round-trip, and -128 decodes like -127") {
    for (uint32_t code = 0; code < 256; ++code) {
        CHECK(encodeUnorm8(decodeUnorm8(code)) == code);
        if (code != 0x80) {
            CHECK(encodeSnorm8(decodeSnorm8(code)) == code);
        }
    }
    CHECK(decodeSnorm8(0x80) == -1.0f);
    CHECK(decodeSnorm8(0x81) == -1.0f);
    CHECK(encodeUnorm8(-3.0f) == 0);
    CHECK(encodeUnorm8(7.0f) == 255);
    CHECK(encodeSnorm8(-7.0f) == 0x81);
}

TEST_CASE("sRGB transfer functions are inverses and match the standard's break points") {
    for (int i = 0; i <= 1000; ++i) {
        const float x = float(i) / 1000.0f;
        CHECK(srgbToLinear(linearToSrgb(x)) == doctest::Approx(x).epsilon(1e-4));
    }
    CHECK(linearToSrgb(0.0031308f) == doctest::Approx(0.04045f).epsilon(1e-3));
    CHECK(srgbToLinear(0.5f) == doctest::Approx(0.21404f).epsilon(1e-4));
}

TEST_CASE("a packed vertex has the documented bit layout") {
    SurfaceVertex s;
    s.albedo = {1.0f, 0.0f, 0.0f};
    s.roughness = 0.0f;             // smoothness 255
    s.normal = {0.0f, 0.0f, 1.0f};  // octahedral (0, 0)
    s.metallic = 1.0f;
    s.reflectance = 0.5f;  // 0.5 * 255 + 0.5 = 128
    const PackedVertex p = packVertex(s);
    CHECK(p.albedoSmoothness == 0xFF0000FFu);
    CHECK(p.normalMetallicReflectance == ((128u << 24) | (255u << 16)));
    static_assert(sizeof(PackedPrimitive) == 24 && sizeof(PackedVertex) == 8);
    CHECK(reflectanceToF0(kDefaultReflectance) == doctest::Approx(0.04f));
}

TEST_CASE("packed vertices round-trip within 8-bit quantisation") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> normal;
    // Half a code of the 8-bit encoding, measured where it is quantised.
    const float halfCode = 0.5f / 255.0f + 1e-6f;
    for (int i = 0; i < 100000; ++i) {
        SurfaceVertex s;
        s.albedo = {unit(rng), unit(rng), unit(rng)};
        s.roughness = unit(rng);
        s.normal = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)) + glm::vec3(1e-6f));
        s.metallic = unit(rng);
        s.reflectance = unit(rng);
        const SurfaceVertex r = unpackVertex(packVertex(s));
        for (int c = 0; c < 3; ++c) {
            REQUIRE(std::abs(linearToSrgb(r.albedo[c]) - linearToSrgb(s.albedo[c])) <= halfCode + 1e-5f);
        }
        REQUIRE(std::abs(r.roughness - s.roughness) <= halfCode);
        REQUIRE(std::abs(r.metallic - s.metallic) <= halfCode);
        REQUIRE(std::abs(r.reflectance - s.reflectance) <= halfCode);
        REQUIRE(angleDegrees(r.normal, s.normal) <= 0.65);
    }
}

TEST_CASE("interpolating a packed primitive weights its vertices by the barycentrics") {
    PackedPrimitive prim;
    const glm::vec3 normals[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int k = 0; k < 3; ++k) {
        SurfaceVertex s;
        s.albedo = glm::vec3(0.0f);
        s.albedo[k] = 1.0f;
        s.roughness = 0.2f * float(k + 1);
        s.normal = normals[k];
        s.metallic = k == 2 ? 1.0f : 0.0f;
        s.reflectance = 0.5f;
        prim.vertices[k] = packVertex(s);
    }
    const SurfaceVertex at1 = interpolateSurface(prim, {1.0f, 0.0f});
    CHECK(at1.albedo.g == doctest::Approx(1.0f));
    CHECK(at1.roughness == doctest::Approx(0.4f).epsilon(0.01));
    CHECK(at1.normal.y == doctest::Approx(1.0f));
    const SurfaceVertex mid = interpolateSurface(prim, {1.0f / 3.0f, 1.0f / 3.0f});
    CHECK(mid.albedo.r == doctest::Approx(1.0f / 3.0f).epsilon(0.01));
    CHECK(mid.metallic == doctest::Approx(1.0f / 3.0f).epsilon(0.01));
    CHECK(mid.roughness == doctest::Approx(0.4f).epsilon(0.01));
    CHECK(angleDegrees(mid.normal, glm::vec3(1.0f)) < 0.7);
    CHECK(primitiveOffsetSlot(10u, 3u) == 13u);
}
