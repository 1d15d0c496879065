#pragma once
// Scene pieces the pass-level GPU tests share: a 64x64 image seen through a
// 90-degree camera at the origin looking down -Z (so at distance d the image
// spans [-d, d] in x and y), and squares to build planes from.

#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include <glm/glm.hpp>

namespace glint::test {

inline constexpr uint32_t kPassTestSize = 64;
inline constexpr float kPassTestNear = 0.1f;

// A square of side 2 * halfSize in the plane through `center` spanned by
// `u` and `v`, facing u x v.
inline scene::Geometry square(glm::vec3 center, glm::vec3 u, glm::vec3 v, float halfSize, uint32_t material = 0) {
    scene::Geometry g;
    const glm::vec3 n = glm::normalize(glm::cross(u, v));
    for (const glm::vec2 c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        g.positions.push_back(center + halfSize * (c.x * u + c.y * v));
        g.normals.push_back(n);
    }
    g.indices = {0, 1, 2, 0, 2, 3};
    g.material = material;
    return g;
}

// 90 degrees vertically on the square test image, no jitter, infinite far
// plane: one world unit at distance d is kPassTestSize / (2 d) pixels.
inline scene::Camera testCamera(glm::vec3 position = glm::vec3(0.0f)) {
    scene::Camera camera;
    camera.resolution = {kPassTestSize, kPassTestSize};
    camera.lens = {glm::radians(90.0f), kPassTestNear, scene::kInfiniteFar};
    camera.jitter = false;
    camera.reset({position, position + glm::vec3(0, 0, -1), {0, 1, 0}}, 0);
    return camera;
}

// NDC of a pixel's centre (+y down the image, as the G-buffer draws it).
inline glm::vec2 pixelNdc(uint32_t x, uint32_t y) {
    return {(float(x) + 0.5f) / float(kPassTestSize) * 2.0f - 1.0f,
            (float(y) + 0.5f) / float(kPassTestSize) * 2.0f - 1.0f};
}

} // namespace glint::test
