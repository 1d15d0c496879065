#include "glint/scene/procedural_meshes.h"

#include "glint/scene/mesh_tools.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace glint::scene {

namespace {

uint32_t addVertex(Geometry& g, const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv) {
    g.positions.push_back(p);
    g.normals.push_back(n);
    g.texcoords0.push_back(uv);
    return uint32_t(g.positions.size() - 1);
}

// Adds triangle (a, b, c) wound counter-clockwise around the vertices'
// normals, so every maker gets front faces right without hand-checking
// each winding; zero-area triangles (sphere poles) are dropped.
void addTriangle(Geometry& g, uint32_t a, uint32_t b, uint32_t c) {
    const glm::vec3 face = glm::cross(g.positions[b] - g.positions[a], g.positions[c] - g.positions[a]);
    if (glm::dot(face, face) <= 0.0f) {
        return;
    }
    const glm::vec3 n = g.normals[a] + g.normals[b] + g.normals[c];
    if (glm::dot(face, n) < 0.0f) {
        std::swap(b, c);
    }
    g.indices.insert(g.indices.end(), {a, b, c});
}

void addQuad(Geometry& g, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    addTriangle(g, a, b, c);
    addTriangle(g, a, c, d);
}

Geometry finish(Geometry g, uint32_t material) {
    g.material = material;
    generateTangents(g);
    g.bounds = computeBounds(g.positions);
    return g;
}

glm::vec3 heightNormal(float (*height)(float, float), float x, float z, float eps) {
    if (!height) {
        return {0.0f, 1.0f, 0.0f};
    }
    const float dx = (height(x + eps, z) - height(x - eps, z)) / (2.0f * eps);
    const float dz = (height(x, z + eps) - height(x, z - eps)) / (2.0f * eps);
    return glm::normalize(glm::vec3(-dx, 1.0f, -dz));
}

} // namespace

Geometry makeDividedBox(const glm::vec3& size, uint32_t divisions, uint32_t material, float uvPerMetre) {
    Geometry g;
    const uint32_t n = std::max(divisions, 1u);
    const glm::vec3 h = size * 0.5f;
    const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int axis = 0; axis < 3; ++axis) {
        for (float sign : {-1.0f, 1.0f}) {
            // addQuad winds each triangle around its vertices' normal.
            const glm::vec3 normal = axes[axis] * sign;
            const glm::vec3 u = axes[(axis + 1) % 3];
            const glm::vec3 v = axes[(axis + 2) % 3];
            const float hu = glm::dot(glm::abs(u), h);
            const float hv = glm::dot(glm::abs(v), h);
            const uint32_t first = g.vertexCount();
            for (uint32_t j = 0; j <= n; ++j) {
                for (uint32_t i = 0; i <= n; ++i) {
                    const glm::vec2 t(2.0f * float(i) / float(n) - 1.0f, 2.0f * float(j) / float(n) - 1.0f);
                    const glm::vec3 p = normal * h + u * (t.x * hu) + v * (t.y * hv);
                    addVertex(g, p, normal, glm::vec2(t.x * hu, t.y * hv) * uvPerMetre);
                }
            }
            for (uint32_t j = 0; j < n; ++j) {
                for (uint32_t i = 0; i < n; ++i) {
                    const uint32_t a = first + j * (n + 1) + i;
                    addQuad(g, a, a + 1, a + n + 2, a + n + 1);
                }
            }
        }
    }
    return finish(std::move(g), material);
}

// One quad a face: the same triangles, corners and order as any division.
Geometry makeBox(const glm::vec3& size, uint32_t material, float uvPerMetre) {
    return makeDividedBox(size, 1, material, uvPerMetre);
}

Geometry makeGrid(const glm::vec2& size, const glm::uvec2& cells, uint32_t material, float uvPerMetre,
                  float (*height)(float, float)) {
    Geometry g;
    const float eps = 0.5f * std::min(size.x / float(cells.x), size.y / float(cells.y));
    for (uint32_t j = 0; j <= cells.y; ++j) {
        for (uint32_t i = 0; i <= cells.x; ++i) {
            const float x = -0.5f * size.x + size.x * float(i) / float(cells.x);
            const float z = -0.5f * size.y + size.y * float(j) / float(cells.y);
            const float y = height ? height(x, z) : 0.0f;
            addVertex(g, {x, y, z}, heightNormal(height, x, z, eps), glm::vec2(x, z) * uvPerMetre);
        }
    }
    const uint32_t row = cells.x + 1;
    for (uint32_t j = 0; j < cells.y; ++j) {
        for (uint32_t i = 0; i < cells.x; ++i) {
            const uint32_t a = j * row + i;
            addQuad(g, a, a + 1, a + 1 + row, a + row);
        }
    }
    return finish(std::move(g), material);
}

Geometry makeSphere(float radius, uint32_t segments, uint32_t rings, uint32_t material) {
    Geometry g;
    for (uint32_t r = 0; r <= rings; ++r) {
        const float theta = glm::pi<float>() * float(r) / float(rings);
        for (uint32_t s = 0; s <= segments; ++s) {
            const float phi = glm::two_pi<float>() * float(s) / float(segments);
            const glm::vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
            addVertex(g, n * radius, n, {float(s) / float(segments), float(r) / float(rings)});
        }
    }
    const uint32_t row = segments + 1;
    for (uint32_t r = 0; r < rings; ++r) {
        for (uint32_t s = 0; s < segments; ++s) {
            const uint32_t a = r * row + s;
            addQuad(g, a, a + 1, a + 1 + row, a + row);
        }
    }
    return finish(std::move(g), material);
}

Geometry makeCylinder(float radius, float height, uint32_t segments, uint32_t material, bool caps) {
    Geometry g;
    for (uint32_t s = 0; s <= segments; ++s) {
        const float phi = glm::two_pi<float>() * float(s) / float(segments);
        const glm::vec3 n{std::cos(phi), 0.0f, std::sin(phi)};
        const float u = float(s) / float(segments) * glm::two_pi<float>() * radius;
        addVertex(g, n * radius, n, {u, 0.0f});
        addVertex(g, n * radius + glm::vec3(0, height, 0), n, {u, height});
    }
    for (uint32_t s = 0; s < segments; ++s) {
        addQuad(g, 2 * s, 2 * s + 2, 2 * s + 3, 2 * s + 1);
    }
    if (caps) {
        for (float y : {0.0f, height}) {
            const glm::vec3 n{0.0f, y > 0.0f ? 1.0f : -1.0f, 0.0f};
            const uint32_t centre = addVertex(g, {0.0f, y, 0.0f}, n, {0.0f, 0.0f});
            const uint32_t first = uint32_t(g.positions.size());
            for (uint32_t s = 0; s <= segments; ++s) {
                const float phi = glm::two_pi<float>() * float(s) / float(segments);
                const glm::vec2 xz{std::cos(phi) * radius, std::sin(phi) * radius};
                addVertex(g, {xz.x, y, xz.y}, n, xz);
            }
            for (uint32_t s = 0; s < segments; ++s) {
                addTriangle(g, centre, first + s, first + s + 1);
            }
        }
    }
    return finish(std::move(g), material);
}

Geometry makeCone(float radius, float height, uint32_t segments, uint32_t material) {
    Geometry g;
    const float slant = std::sqrt(radius * radius + height * height);
    for (uint32_t s = 0; s < segments; ++s) {
        const float phi0 = glm::two_pi<float>() * float(s) / float(segments);
        const float phi1 = glm::two_pi<float>() * float(s + 1) / float(segments);
        const float phiMid = 0.5f * (phi0 + phi1);
        const auto normal = [&](float phi) {
            return glm::vec3(std::cos(phi) * height, radius, std::sin(phi) * height) / slant;
        };
        const uint32_t a =
            addVertex(g, {std::cos(phi0) * radius, 0.0f, std::sin(phi0) * radius}, normal(phi0), {phi0 * radius, 0.0f});
        const uint32_t b =
            addVertex(g, {std::cos(phi1) * radius, 0.0f, std::sin(phi1) * radius}, normal(phi1), {phi1 * radius, 0.0f});
        const uint32_t apex = addVertex(g, {0.0f, height, 0.0f}, normal(phiMid), {phiMid * radius, slant});
        addTriangle(g, a, b, apex);
    }
    return finish(std::move(g), material);
}

Geometry makeTorus(float majorRadius, float minorRadius, uint32_t segments, uint32_t sides, uint32_t material) {
    Geometry g;
    for (uint32_t s = 0; s <= segments; ++s) {
        const float phi = glm::two_pi<float>() * float(s) / float(segments);
        const glm::vec3 dir{std::cos(phi), 0.0f, std::sin(phi)};
        for (uint32_t k = 0; k <= sides; ++k) {
            const float psi = glm::two_pi<float>() * float(k) / float(sides);
            const glm::vec3 n = dir * std::cos(psi) + glm::vec3(0.0f, std::sin(psi), 0.0f);
            addVertex(g, dir * majorRadius + n * minorRadius, n, {float(s) / float(segments), float(k) / float(sides)});
        }
    }
    const uint32_t row = sides + 1;
    for (uint32_t s = 0; s < segments; ++s) {
        for (uint32_t k = 0; k < sides; ++k) {
            const uint32_t a = s * row + k;
            addQuad(g, a, a + row, a + row + 1, a + 1);
        }
    }
    return finish(std::move(g), material);
}

Geometry makeRingSector(float innerRadius, float outerRadius, float angle0, float angle1, uint32_t segments,
                        uint32_t rings, uint32_t material, float (*height)(float, float)) {
    Geometry g;
    const float eps = 0.5f * (outerRadius - innerRadius) / float(rings);
    for (uint32_t r = 0; r <= rings; ++r) {
        const float radius = innerRadius + (outerRadius - innerRadius) * float(r) / float(rings);
        for (uint32_t s = 0; s <= segments; ++s) {
            const float phi = angle0 + (angle1 - angle0) * float(s) / float(segments);
            const float x = std::cos(phi) * radius;
            const float z = std::sin(phi) * radius;
            addVertex(g, {x, height ? height(x, z) : 0.0f, z}, heightNormal(height, x, z, eps),
                      glm::vec2(x, z) * 0.05f);
        }
    }
    const uint32_t row = segments + 1;
    for (uint32_t r = 0; r < rings; ++r) {
        for (uint32_t s = 0; s < segments; ++s) {
            const uint32_t a = r * row + s;
            addQuad(g, a, a + 1, a + 1 + row, a + row);
        }
    }
    return finish(std::move(g), material);
}

namespace {

// Joints and weights for a position `t` (in joint spacings) along a chain
// of `bones` joints: linear blend between the two nearest joints.
void chainWeights(float t, uint32_t bones, glm::u16vec4& joints, glm::vec4& weights) {
    const float clamped = std::clamp(t, 0.0f, float(bones - 1));
    const uint32_t k0 = std::min(uint32_t(clamped), bones - 1);
    const uint32_t k1 = std::min(k0 + 1, bones - 1);
    const float f = clamped - float(k0);
    joints = glm::u16vec4(uint16_t(k0), uint16_t(k1), 0, 0);
    weights = k0 == k1 ? glm::vec4(1, 0, 0, 0) : glm::vec4(1.0f - f, f, 0.0f, 0.0f);
}

} // namespace

Geometry makeSkinnedTube(float radius, float height, uint32_t segments, uint32_t rings, uint32_t bones,
                         uint32_t material) {
    Geometry g;
    const float spacing = height / float(bones);
    for (uint32_t r = 0; r <= rings; ++r) {
        const float y = height * float(r) / float(rings);
        for (uint32_t s = 0; s <= segments; ++s) {
            const float phi = glm::two_pi<float>() * float(s) / float(segments);
            const glm::vec3 n{std::cos(phi), 0.0f, std::sin(phi)};
            addVertex(g, n * radius + glm::vec3(0.0f, y, 0.0f), n, {float(s) / float(segments), y});
        }
    }
    const uint32_t row = segments + 1;
    for (uint32_t r = 0; r < rings; ++r) {
        for (uint32_t s = 0; s < segments; ++s) {
            const uint32_t a = r * row + s;
            addQuad(g, a, a + 1, a + 1 + row, a + row);
        }
    }
    // Top cap, so the tube is closed where it can be seen from above.
    const uint32_t centre = addVertex(g, {0.0f, height, 0.0f}, {0, 1, 0}, {0.5f, 0.5f});
    const uint32_t first = uint32_t(g.positions.size());
    for (uint32_t s = 0; s <= segments; ++s) {
        const float phi = glm::two_pi<float>() * float(s) / float(segments);
        addVertex(g, {std::cos(phi) * radius, height, std::sin(phi) * radius}, {0, 1, 0}, {0.5f, 0.5f});
    }
    for (uint32_t s = 0; s < segments; ++s) {
        addTriangle(g, centre, first + s, first + s + 1);
    }
    g.joints.resize(g.positions.size());
    g.weights.resize(g.positions.size());
    for (size_t v = 0; v < g.positions.size(); ++v) {
        chainWeights(g.positions[v].y / spacing, bones, g.joints[v], g.weights[v]);
    }
    return finish(std::move(g), material);
}

Geometry makeSkinnedSheet(const glm::vec2& size, const glm::uvec2& cells, uint32_t bones, uint32_t material) {
    Geometry g;
    const float spacing = size.x / float(bones);
    for (uint32_t j = 0; j <= cells.y; ++j) {
        for (uint32_t i = 0; i <= cells.x; ++i) {
            const glm::vec2 uv{float(i) / float(cells.x), float(j) / float(cells.y)};
            addVertex(g, {uv.x * size.x, uv.y * size.y, 0.0f}, {0, 0, 1}, {uv.x, 1.0f - uv.y});
        }
    }
    const uint32_t row = cells.x + 1;
    for (uint32_t j = 0; j < cells.y; ++j) {
        for (uint32_t i = 0; i < cells.x; ++i) {
            const uint32_t a = j * row + i;
            addQuad(g, a, a + 1, a + 1 + row, a + row);
        }
    }
    g.joints.resize(g.positions.size());
    g.weights.resize(g.positions.size());
    for (size_t v = 0; v < g.positions.size(); ++v) {
        chainWeights(g.positions[v].x / spacing, bones, g.joints[v], g.weights[v]);
    }
    return finish(std::move(g), material);
}

void bindToJoint(Geometry& geometry, uint16_t joint) {
    geometry.joints.assign(geometry.positions.size(), glm::u16vec4(joint, 0, 0, 0));
    geometry.weights.assign(geometry.positions.size(), glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
}

} // namespace glint::scene
