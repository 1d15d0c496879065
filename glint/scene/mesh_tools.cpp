#include "glint/scene/mesh_tools.h"

#include <glm/gtc/matrix_inverse.hpp>

#include <cmath>

namespace glint::scene {

Aabb computeBounds(std::span<const glm::vec3> positions) {
    Aabb box;
    for (const glm::vec3& p : positions) {
        box.extend(p);
    }
    return box;
}

namespace {

template <typename T> void unweld(std::vector<T>& attribute, const std::vector<uint32_t>& indices) {
    if (attribute.empty()) {
        return;
    }
    std::vector<T> out;
    out.reserve(indices.size());
    for (uint32_t i : indices) {
        out.push_back(attribute[i]);
    }
    attribute = std::move(out);
}

glm::vec3 faceNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const glm::vec3 n = glm::cross(b - a, c - a);
    const float len = glm::length(n);
    // A degenerate triangle has no normal; any unit vector keeps shading finite.
    return len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
}

} // namespace

void generateFlatNormals(Geometry& g) {
    unweld(g.positions, g.indices);
    unweld(g.tangents, g.indices);
    unweld(g.texcoords0, g.indices);
    unweld(g.texcoords1, g.indices);
    unweld(g.colors, g.indices);
    unweld(g.joints, g.indices);
    unweld(g.weights, g.indices);
    for (MorphTarget& target : g.morphTargets) {
        unweld(target.positions, g.indices);
        unweld(target.tangents, g.indices);
        // Flat normals are not morphed: a target's normal displacements
        // belong to the file's smooth normals, which this geometry lacks.
        target.normals.clear();
    }
    g.normals.resize(g.positions.size());
    for (size_t t = 0; t + 2 < g.positions.size(); t += 3) {
        const glm::vec3 n = faceNormal(g.positions[t], g.positions[t + 1], g.positions[t + 2]);
        g.normals[t] = g.normals[t + 1] = g.normals[t + 2] = n;
    }
    for (uint32_t i = 0; i < g.indices.size(); ++i) {
        g.indices[i] = i;
    }
}

glm::vec3 anyPerpendicular(const glm::vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    return {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
}

void generateTangents(Geometry& g, uint32_t texCoord) {
    const size_t n = g.positions.size();
    g.tangents.assign(n, glm::vec4(0.0f));
    std::vector<glm::vec3> bitangents(n, glm::vec3(0.0f));
    const std::vector<glm::vec2>& uvs = texCoord == 1 ? g.texcoords1 : g.texcoords0;
    if (uvs.size() == n) {
        for (size_t t = 0; t + 2 < g.indices.size(); t += 3) {
            const uint32_t i0 = g.indices[t], i1 = g.indices[t + 1], i2 = g.indices[t + 2];
            const glm::vec3 e1 = g.positions[i1] - g.positions[i0];
            const glm::vec3 e2 = g.positions[i2] - g.positions[i0];
            const glm::vec2 d1 = uvs[i1] - uvs[i0];
            const glm::vec2 d2 = uvs[i2] - uvs[i0];
            const float det = d1.x * d2.y - d2.x * d1.y;
            if (!(std::abs(det) > 1e-20f) || !std::isfinite(det)) {
                continue;  // no UV parameterisation on this triangle
            }
            const float r = 1.0f / det;
            // Unnormalised: larger triangles weigh more.
            const glm::vec3 tangent = (e1 * d2.y - e2 * d1.y) * r;
            const glm::vec3 bitangent = (e2 * d1.x - e1 * d2.x) * r;
            for (uint32_t i : {i0, i1, i2}) {
                g.tangents[i] += glm::vec4(tangent, 0.0f);
                bitangents[i] += bitangent;
            }
        }
    }
    for (size_t i = 0; i < n; ++i) {
        const glm::vec3 normal = i < g.normals.size() ? g.normals[i] : glm::vec3(0, 1, 0);
        glm::vec3 t = glm::vec3(g.tangents[i]);
        t -= normal * glm::dot(normal, t);  // Gram-Schmidt
        const float len = glm::length(t);
        if (len > 1e-12f && std::isfinite(len)) {
            t /= len;
            // glTF's bitangent cross(N, T) * w points along decreasing v (up
            // the image: glTF's v runs down it), the opposite of dP/dv; the
            // sign MikkTSpace gives on glTF coordinates, negated (as three.js
            // does for glTF, computeMikkTSpaceTangents' negateSign).
            const float w = glm::dot(glm::cross(normal, t), bitangents[i]) > 0.0f ? -1.0f : 1.0f;
            g.tangents[i] = glm::vec4(t, w);
        } else {
            g.tangents[i] = glm::vec4(anyPerpendicular(normal), 1.0f);
        }
    }
}

void transformGeometry(Geometry& g, const glm::mat4& transform) {
    const glm::mat3 normalMatrix = glm::inverseTranspose(glm::mat3(transform));
    // A mirroring transform flips the winding, so the bitangent sign flips.
    const float handedness = glm::determinant(glm::mat3(transform)) < 0.0f ? -1.0f : 1.0f;
    for (glm::vec3& p : g.positions) {
        p = glm::vec3(transform * glm::vec4(p, 1.0f));
    }
    for (glm::vec3& nrm : g.normals) {
        nrm = glm::normalize(normalMatrix * nrm);
    }
    for (glm::vec4& t : g.tangents) {
        t = glm::vec4(glm::normalize(glm::mat3(transform) * glm::vec3(t)), t.w * handedness);
    }
    g.bounds = computeBounds(g.positions);
}

void appendGeometry(Geometry& target, const Geometry& source) {
    const uint32_t base = target.vertexCount();
    const auto append = [](auto& dst, const auto& src) { dst.insert(dst.end(), src.begin(), src.end()); };
    append(target.positions, source.positions);
    append(target.normals, source.normals);
    append(target.tangents, source.tangents);
    append(target.texcoords0, source.texcoords0);
    append(target.texcoords1, source.texcoords1);
    append(target.colors, source.colors);
    append(target.joints, source.joints);
    append(target.weights, source.weights);
    target.indices.reserve(target.indices.size() + source.indices.size());
    for (uint32_t i : source.indices) {
        target.indices.push_back(base + i);
    }
    target.bounds.extend(source.bounds);
}

} // namespace glint::scene
