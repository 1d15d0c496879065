#pragma once
// The smoke scene: a handful of triangles in two BLASes and three instances,
// enough to check that acceleration structures, both ray backends, instance
// custom indices, geometry indices and barycentrics all work. It comes with
// a CPU reference tracer for tests.

#include "glint/smoke_shared.h"

#include <glm/glm.hpp>

#include <array>
#include <vector>

namespace glint::scene {

struct SmokeGeometry {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;  // empty: three positions per triangle
    uint32_t triangleCount() const;
    // Vertex positions of triangle `i`.
    std::array<glm::vec3, 3> triangle(uint32_t i) const;
};

struct SmokeBlas {
    std::vector<SmokeGeometry> geometries;
};

struct SmokeInstance {
    uint32_t blas = 0;
    glm::mat4 transform{1.0f};
    uint32_t customIndex = 0;
};

struct SmokeScene {
    std::vector<SmokeBlas> blases;
    std::vector<SmokeInstance> instances;
    glm::vec3 eye{0.0f};
    glm::vec3 target{0.0f, 0.0f, -1.0f};
    float verticalFovDegrees = 50.0f;
};

SmokeScene makeSmokeScene();

// Pinhole camera of `scene` for an image of width x height.
shader::SmokeCamera smokeCamera(const SmokeScene& scene, uint32_t width, uint32_t height);

// Closest-hit reference in double precision. `ambiguous[i]` is set where the
// ray passes within `edgeEpsilon` (barycentric) of a triangle edge, so a
// GPU may fairly decide either way.
struct SmokeReference {
    std::vector<shader::SmokeHit> hits;
    std::vector<bool> ambiguous;
};
SmokeReference traceSmokeReference(const SmokeScene& scene, const shader::SmokeCamera& camera,
                                   double edgeEpsilon = 1e-4);

// The instance transform as the 3x4 row-major matrix Vulkan instances use.
std::array<float, 12> rowMajor3x4(const glm::mat4& m);

} // namespace glint::scene
