#include "glint/scene/camera.h"

#include <doctest/doctest.h>

#include <glm/gtc/constants.hpp>

#include <array>
#include <cmath>

using namespace glint::scene;

namespace {

glm::vec3 toNdc(const glm::mat4& projection, const glm::vec3& view) {
    const glm::vec4 clip = projection * glm::vec4(view, 1.0f);
    return glm::vec3(clip) / clip.w;
}

} // namespace

TEST_CASE("reversed-Z projection puts the near plane at depth 1 and the far plane at depth 0") {
    const glm::mat4 p = perspectiveReversedZ(glm::radians(60.0f), 16.0f / 9.0f, 0.1f, 1000.0f);
    CHECK(toNdc(p, {0, 0, -0.1f}).z == doctest::Approx(1.0f));
    CHECK(toNdc(p, {0, 0, -1000.0f}).z == doctest::Approx(0.0f).epsilon(1e-6));
    float previous = 2.0f;
    for (float d = 0.1f; d <= 1000.0f; d *= 1.5f) {
        const float depth = toNdc(p, {0.3f, -0.2f, -d}).z;
        CHECK(depth < previous);  // strictly decreasing with distance
        CHECK(depth >= 0.0f);
        CHECK(depth <= 1.0f);
        previous = depth;
    }
}

TEST_CASE("infinite reversed-Z keeps the near plane at 1 and falls towards 0 without reaching below it") {
    const glm::mat4 p = perspectiveReversedZ(glm::radians(70.0f), 1.0f, 0.01f, kInfiniteFar);
    CHECK(toNdc(p, {0, 0, -0.01f}).z == doctest::Approx(1.0f));
    CHECK(toNdc(p, {0, 0, -1.0e4f}).z == doctest::Approx(1.0e-6f).epsilon(1e-3));
    const float veryFar = toNdc(p, {0, 0, -1.0e30f}).z;
    CHECK(veryFar >= 0.0f);
    CHECK(veryFar < 1e-20f);
}

TEST_CASE("projection maps view-space up to the top of a Vulkan image and respects the aspect ratio") {
    const glm::mat4 p = perspectiveReversedZ(glm::half_pi<float>(), 2.0f, 0.1f, 100.0f);
    CHECK(toNdc(p, {0, 1, -5}).y < 0.0f);  // Vulkan NDC: -1 is the top row
    CHECK(toNdc(p, {1, 0, -1}).x == doctest::Approx(0.5f));
    CHECK(toNdc(p, {0, 1, -1}).y == doctest::Approx(-1.0f));
}

TEST_CASE("jitter follows the Halton(2,3) sequence of FidelityFX FSR 2 and repeats after its phases") {
    CHECK(halton(1, 2) == doctest::Approx(0.5f));
    CHECK(halton(2, 2) == doctest::Approx(0.25f));
    CHECK(halton(3, 2) == doctest::Approx(0.75f));
    CHECK(halton(1, 3) == doctest::Approx(1.0f / 3.0f));
    CHECK(halton(5, 3) == doctest::Approx(7.0f / 9.0f));
    const std::array<glm::vec2, 8> expected = {
        glm::vec2{0.0f, -1.0f / 6.0f}, {-0.25f, 1.0f / 6.0f},
        {0.25f, 1.0f / 9.0f - 0.5f},   {-0.375f, 4.0f / 9.0f - 0.5f},
        {0.125f, 7.0f / 9.0f - 0.5f},  {-0.125f, 2.0f / 9.0f - 0.5f},
        {0.375f, 5.0f / 9.0f - 0.5f},  {1.0f / 16.0f - 0.5f, 8.0f / 9.0f - 0.5f}};
    glm::vec2 mean(0.0f);
    for (uint64_t frame = 0; frame < 8; ++frame) {
        const glm::vec2 j = jitterOffset(frame);
        CHECK(j.x == doctest::Approx(expected[frame].x));
        CHECK(j.y == doctest::Approx(expected[frame].y));
        CHECK(j.x >= -0.5f);
        CHECK(j.x < 0.5f);
        CHECK(j.y >= -0.5f);
        CHECK(j.y < 0.5f);
        CHECK(jitterOffset(frame + 8) == j);
        mean += j / 8.0f;
    }
    CHECK(std::abs(mean.x) < 0.07f);
    CHECK(std::abs(mean.y) < 0.07f);
    CHECK(jitterOffset(3, 1) == jitterOffset(0, 1));
}

TEST_CASE("a jittered projection moves every point by the jitter in pixels") {
    const glm::uvec2 size{1280, 720};
    const glm::mat4 p = perspectiveReversedZ(glm::radians(60.0f), 1280.0f / 720.0f, 0.1f, kInfiniteFar);
    const glm::vec2 jitter{0.25f, -0.375f};
    const glm::mat4 pj = jitterProjection(p, jitter, size);
    for (const glm::vec3& v : {glm::vec3(0, 0, -1), glm::vec3(3, -2, -10), glm::vec3(-50, 20, -400)}) {
        const glm::vec3 a = toNdc(p, v);
        const glm::vec3 b = toNdc(pj, v);
        CHECK((b.x - a.x) * 0.5f * float(size.x) == doctest::Approx(jitter.x).epsilon(1e-3));
        CHECK((b.y - a.y) * 0.5f * float(size.y) == doctest::Approx(jitter.y).epsilon(1e-3));
        CHECK(b.z == doctest::Approx(a.z));
    }
}

TEST_CASE("advancing the camera keeps last frame's matrices and jitter") {
    Camera camera;
    camera.resolution = {640, 360};
    const CameraPose a{{0, 1, 5}, {0, 1, 0}, {0, 1, 0}};
    const CameraPose b{{1, 1, 4}, {0, 0, 0}, {0, 1, 0}};
    camera.reset(a, 10);
    CHECK(camera.previousView == camera.view);
    CHECK(camera.previousJitterPixels == camera.jitterPixels);
    const glm::mat4 viewA = camera.view;
    camera.advance(b, 11);
    CHECK(camera.previousView == viewA);
    CHECK(camera.view == viewMatrix(b));
    CHECK(camera.previousJitterPixels == jitterOffset(10));
    CHECK(camera.jitterPixels == jitterOffset(11));
    CHECK(camera.previousPosition == a.position);
    CHECK(camera.position == b.position);
    CHECK(camera.jitteredProjection == jitterProjection(camera.projection, camera.jitterPixels, camera.resolution));
    // The view matrix takes the eye to the origin and the target onto -Z.
    const glm::vec4 target = camera.view * glm::vec4(b.target, 1.0f);
    CHECK(target.x == doctest::Approx(0.0f).epsilon(1e-5));
    CHECK(target.y == doctest::Approx(0.0f).epsilon(1e-5));
    CHECK(target.z < 0.0f);
}

TEST_CASE("a camera path passes through its keys and clamps outside them") {
    CameraPath path;
    path.keys = {{0.0f, {0, 0, 0}, {0, 0, -1}}, {1.0f, {1, 0, 0}, {1, 0, -1}}, {3.0f, {1, 2, 0}, {1, 2, -1}}};
    CHECK(path.duration() == 3.0f);
    for (const CameraPathKey& k : path.keys) {
        const CameraPose pose = path.evaluate(k.time);
        CHECK(glm::length(pose.position - k.position) < 1e-5f);
        CHECK(glm::length(pose.target - k.target) < 1e-5f);
    }
    CHECK(path.evaluate(-5.0f).position == path.keys.front().position);
    CHECK(path.evaluate(50.0f).position == path.keys.back().position);
    CHECK(path.atFrame(0, 100).position == path.keys.front().position);
    CHECK(glm::length(path.atFrame(99, 100).position - path.keys.back().position) < 1e-5f);
    const CameraPose mid = path.evaluate(0.5f);
    CHECK(mid.position.x > 0.0f);
    CHECK(mid.position.x < 1.0f);
}
