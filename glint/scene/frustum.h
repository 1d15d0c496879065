#pragma once
// View-frustum culling on the CPU: the six planes of a Vulkan clip space
// (x and y in [-w, w], z in [0, w]: reversed or not, finite or infinite
// far, perspective or orthographic) and conservative tests of world-space
// boxes and spheres against them. What the G-buffer, the shadow map and
// the particles' forward pass draw follows these tests.

#include "glint/scene/scene.h"

#include <glm/glm.hpp>

#include <array>

namespace glint::scene {

class Frustum {
public:
    // The planes of `clipFromWorld` (Gribb and Hartmann, "Fast Extraction
    // of Viewing Frustum Planes from the World-View-Projection Matrix",
    // 2001), for Vulkan's z range [0, w]. A plane of an infinite far plane
    // (reversed Z: z >= 0 everywhere in front of the camera) keeps every
    // point in front, as it should.
    explicit Frustum(const glm::mat4& clipFromWorld);

    // False only when the box lies wholly outside one plane: boxes that
    // straddle a corner outside the frustum may still pass (conservative).
    bool intersects(const Aabb& box) const;
    bool intersects(const glm::vec3& centre, float radius) const;

private:
    std::array<glm::vec4, 6> planes_;  // (n, d): n . p + d >= 0 inside
};

} // namespace glint::scene
