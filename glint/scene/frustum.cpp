#include "glint/scene/frustum.h"

#include <cmath>

namespace glint::scene {

Frustum::Frustum(const glm::mat4& m) {
    // Rows of the matrix (glm is column-major: m[column][row]).
    const auto row = [&](int r) { return glm::vec4(m[0][r], m[1][r], m[2][r], m[3][r]); };
    const glm::vec4 x = row(0), y = row(1), z = row(2), w = row(3);
    planes_ = {w + x, w - x, w + y, w - y, z, w - z};
    for (glm::vec4& p : planes_) {
        // Normalised, so the sphere test compares distances; a degenerate
        // plane (a zero normal) keeps everything.
        const float length = glm::length(glm::vec3(p));
        p = length > 0.0f && std::isfinite(length) ? p / length : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    }
}

bool Frustum::intersects(const Aabb& box) const {
    if (box.empty()) return false;
    for (const glm::vec4& p : planes_) {
        // The box corner farthest along the plane's normal.
        const glm::vec3 corner(p.x >= 0.0f ? box.max.x : box.min.x, p.y >= 0.0f ? box.max.y : box.min.y,
                               p.z >= 0.0f ? box.max.z : box.min.z);
        if (glm::dot(glm::vec3(p), corner) + p.w < 0.0f) return false;
    }
    return true;
}

bool Frustum::intersects(const glm::vec3& centre, float radius) const {
    for (const glm::vec4& p : planes_) {
        if (glm::dot(glm::vec3(p), centre) + p.w < -radius) return false;
    }
    return true;
}

} // namespace glint::scene
