#include "glint/scene/smoke_scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace glint::scene {

uint32_t SmokeGeometry::triangleCount() const {
    return static_cast<uint32_t>((indices.empty() ? positions.size() : indices.size()) / 3);
}

std::array<glm::vec3, 3> SmokeGeometry::triangle(uint32_t i) const {
    if (indices.empty()) {
        return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
    }
    return {positions[indices[3 * i]], positions[indices[3 * i + 1]], positions[indices[3 * i + 2]]};
}

SmokeScene makeSmokeScene() {
    SmokeScene s;
    // BLAS 0, two geometries: an indexed floor quad and an unindexed back wall.
    SmokeGeometry floor;
    floor.positions = {{-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}};
    floor.indices = {0, 2, 1, 0, 3, 2};
    SmokeGeometry wall;
    wall.positions = {{-3, 0, -2.5f}, {3, 0, -2.5f}, {3, 3, -2.5f}, {-3, 0, -2.5f}, {3, 3, -2.5f}, {-3, 3, -2.5f}};
    s.blases.push_back({{floor, wall}});

    // BLAS 1: an open pyramid (four unindexed faces).
    const glm::vec3 apex{0, 1, 0};
    const glm::vec3 base[4] = {{-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}};
    SmokeGeometry pyramid;
    for (int i = 0; i < 4; ++i) {
        pyramid.positions.insert(pyramid.positions.end(), {base[i], base[(i + 1) % 4], apex});
    }
    s.blases.push_back({{pyramid}});

    s.instances.push_back({0, glm::mat4(1.0f), 0});
    s.instances.push_back({1, glm::translate(glm::mat4(1.0f), {-1.0f, 0.0f, 0.0f}), 10});
    glm::mat4 turned = glm::translate(glm::mat4(1.0f), {1.1f, 0.0f, -0.5f});
    turned = glm::rotate(turned, glm::radians(30.0f), {0, 1, 0});
    turned = glm::scale(turned, {1.0f, 1.6f, 1.0f});
    s.instances.push_back({1, turned, 11});

    s.eye = {0.0f, 1.6f, 4.0f};
    s.target = {0.0f, 0.6f, 0.0f};
    s.verticalFovDegrees = 50.0f;
    return s;
}

shader::SmokeCamera smokeCamera(const SmokeScene& scene, uint32_t width, uint32_t height) {
    const glm::vec3 forward = glm::normalize(scene.target - scene.eye);
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)));
    const glm::vec3 up = glm::cross(right, forward);
    const float halfHeight = std::tan(glm::radians(scene.verticalFovDegrees) * 0.5f);
    const float halfWidth = halfHeight * float(width) / float(height);
    shader::SmokeCamera c{};
    c.origin = glm::vec4(scene.eye, 1.0f);
    // Image row 0 is the top row: "lower-left" is the top-left corner and
    // vertical points down, so images come out upright.
    c.lowerLeft = glm::vec4(scene.eye + forward - halfWidth * right + halfHeight * up, 1.0f);
    c.horizontal = glm::vec4(2.0f * halfWidth * right, 0.0f);
    c.vertical = glm::vec4(-2.0f * halfHeight * up, 0.0f);
    c.size = {width, height, 0, 0};
    return c;
}

std::array<float, 12> rowMajor3x4(const glm::mat4& m) {
    std::array<float, 12> out{};
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 4; ++col) {
            out[row * 4 + col] = m[col][row];  // glm is column-major
        }
    }
    return out;
}

SmokeReference traceSmokeReference(const SmokeScene& scene, const shader::SmokeCamera& camera, double edgeEpsilon) {
    using dvec3 = glm::dvec3;
    const uint32_t width = camera.size.x;
    const uint32_t height = camera.size.y;
    SmokeReference ref;
    ref.hits.assign(size_t(width) * height, shader::SmokeHit{});
    ref.ambiguous.assign(size_t(width) * height, false);

    const dvec3 origin(camera.origin);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            // Same expression as smokeRayDirection() in the shaders, in double.
            const double u = (x + 0.5) / width;
            const double v = (y + 0.5) / height;
            const dvec3 target = dvec3(camera.lowerLeft) + u * dvec3(camera.horizontal) + v * dvec3(camera.vertical);
            const dvec3 dir = glm::normalize(target - origin);

            shader::SmokeHit best{};
            double bestT = shader::kSmokeTMax;
            bool ambiguous = false;
            for (const auto& inst : scene.instances) {
                const glm::dmat4 m(inst.transform);
                const auto& blas = scene.blases[inst.blas];
                for (uint32_t g = 0; g < blas.geometries.size(); ++g) {
                    const auto& geo = blas.geometries[g];
                    for (uint32_t p = 0; p < geo.triangleCount(); ++p) {
                        const auto tri = geo.triangle(p);
                        const dvec3 a = dvec3(m * glm::dvec4(glm::dvec3(tri[0]), 1.0));
                        const dvec3 b = dvec3(m * glm::dvec4(glm::dvec3(tri[1]), 1.0));
                        const dvec3 c = dvec3(m * glm::dvec4(glm::dvec3(tri[2]), 1.0));
                        // Möller-Trumbore, keeping u, v, t even outside the triangle.
                        const dvec3 e1 = b - a;
                        const dvec3 e2 = c - a;
                        const dvec3 pv = glm::cross(dir, e2);
                        const double det = glm::dot(e1, pv);
                        if (std::abs(det) < 1e-12) {
                            continue;  // ray parallel to the plane
                        }
                        const dvec3 tv = origin - a;
                        const double bu = glm::dot(tv, pv) / det;
                        const dvec3 qv = glm::cross(tv, e1);
                        const double bv = glm::dot(dir, qv) / det;
                        const double t = glm::dot(e2, qv) / det;
                        if (t <= shader::kSmokeTMin || t >= shader::kSmokeTMax) {
                            continue;
                        }
                        const double margin = std::min({bu, bv, 1.0 - bu - bv});
                        if (std::abs(margin) < edgeEpsilon) {
                            ambiguous = true;
                        }
                        if (margin >= 0.0 && best.hit && std::abs(t - bestT) < 1e-4 * t) {
                            ambiguous = true;  // two surfaces at (nearly) the same depth
                        }
                        if (margin >= 0.0 && t < bestT) {
                            bestT = t;
                            best = {1u, inst.customIndex, g, p, float(t), float(bu), float(bv), 0u};
                        }
                    }
                }
            }
            ref.hits[size_t(y) * width + x] = best;
            ref.ambiguous[size_t(y) * width + x] = ambiguous;
        }
    }
    return ref;
}

} // namespace glint::scene
