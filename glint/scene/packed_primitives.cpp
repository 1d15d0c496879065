#include "glint/scene/packed_primitives.h"

#include "glint/scene/animation.h"

#include <algorithm>

namespace glint::scene {

namespace {

glm::vec4 sampleRef(const Scene& scene, const Geometry& g, const TextureRef& ref, uint32_t vertex) {
    if (!ref.valid()) {
        return glm::vec4(1.0f);
    }
    const std::vector<glm::vec2>& uvs = ref.texCoord == 0 ? g.texcoords0 : g.texcoords1;
    // KHR_texture_transform: the same map the G-buffer's shader applies.
    const glm::vec2 uv =
        shader::applyUvTransform(ref.uvTransform(), vertex < uvs.size() ? uvs[vertex] : glm::vec2(0.0f));
    return sampleBilinear(scene.textures[size_t(ref.texture)], uv, ref.wrapS, ref.wrapT);
}

} // namespace

shader::SurfaceVertex surfaceAtVertex(const Scene& scene, const Geometry& g, uint32_t vertex) {
    const Material& m = scene.materials[g.material];
    glm::vec3 albedo = glm::vec3(m.baseColorFactor);
    if (!g.colors.empty()) {
        albedo *= glm::vec3(g.colors[vertex]);
    }
    const glm::vec4 base = sampleRef(scene, g, m.baseColorTexture, vertex);
    albedo *= glm::vec3(shader::srgbToLinear(base.r), shader::srgbToLinear(base.g), shader::srgbToLinear(base.b));
    const glm::vec4 mr = sampleRef(scene, g, m.metallicRoughnessTexture, vertex);
    shader::SurfaceVertex s;
    s.albedo = glm::clamp(albedo, glm::vec3(0.0f), glm::vec3(1.0f));
    s.roughness = std::clamp(m.roughnessFactor * mr.g, 0.0f, 1.0f);
    s.metallic = std::clamp(m.metallicFactor * mr.b, 0.0f, 1.0f);
    // The vertex normal, never the normal map: a normal map sampled at three
    // vertices and interpolated across a triangle is no normal map at all,
    // and the BVH's packed primitives carry one normal per vertex. Only the
    // G-buffer applies normal maps, per pixel.
    s.normal = vertex < g.normals.size() ? g.normals[vertex] : glm::vec3(0.0f, 1.0f, 0.0f);
    s.reflectance = m.reflectance;
    return s;
}

namespace {

// glTF: 8-bit emissive texels are sRGB; float images hold linear values.
glm::vec3 emissiveTexel(const Texture& texture, glm::vec4 texel) {
    if (texture.format != TextureFormat::Rgba8) return glm::vec3(texel);
    return {shader::srgbToLinear(texel.r), shader::srgbToLinear(texel.g), shader::srgbToLinear(texel.b)};
}

} // namespace

glm::vec3 emissionAtVertex(const Scene& scene, const Geometry& g, uint32_t vertex) {
    const Material& m = scene.materials[g.material];
    const glm::vec3 factor = m.emissiveFactor * m.emissiveStrength;
    if (factor == glm::vec3(0.0f) || !m.emissiveTexture.valid()) return factor;
    return factor * emissiveTexel(scene.textures[size_t(m.emissiveTexture.texture)],
                                  sampleRef(scene, g, m.emissiveTexture, vertex));
}

glm::vec3 meanEmission(const Scene& scene, const Material& m) {
    const glm::vec3 factor = m.emissiveFactor * m.emissiveStrength;
    if (factor == glm::vec3(0.0f) || !m.emissiveTexture.valid()) return factor;
    const Texture& texture = scene.textures[size_t(m.emissiveTexture.texture)];
    if (texture.width == 0 || texture.height == 0) return factor;
    glm::dvec3 sum(0.0);
    for (uint32_t y = 0; y < texture.height; ++y) {
        for (uint32_t x = 0; x < texture.width; ++x) {
            sum += glm::dvec3(emissiveTexel(texture, texture.texel(x, y)));
        }
    }
    return factor * glm::vec3(sum / (double(texture.width) * double(texture.height)));
}

UnwrappedGeometry unwrapGeometry(const Scene& scene, const Geometry& g, std::span<const glm::mat4> jointMatrices) {
    const bool skin = g.skinned() && !jointMatrices.empty();
    const auto skinMatrix = [&](uint32_t v) {
        glm::mat4 m(0.0f);
        for (int k = 0; k < 4; ++k) {
            const uint16_t joint = g.joints[v][k];
            if (g.weights[v][k] > 0.0f && joint < jointMatrices.size()) {
                m += g.weights[v][k] * jointMatrices[joint];
            }
        }
        return m;
    };
    UnwrappedGeometry out;
    out.positions.reserve(g.indices.size());
    out.primitives.reserve(g.triangleCount());
    for (uint32_t t = 0; t < g.triangleCount(); ++t) {
        shader::PackedPrimitive prim;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t v = g.indices[3 * t + k];
            shader::SurfaceVertex s = surfaceAtVertex(scene, g, v);
            glm::vec3 p = g.positions[v];
            if (skin) {
                const glm::mat4 m = skinMatrix(v);
                p = glm::vec3(m * glm::vec4(p, 1.0f));
                // Joint matrices of rigs carry no non-uniform scale, so the
                // upper 3x3 transforms normals too.
                const glm::vec3 n = glm::mat3(m) * s.normal;
                s.normal = glm::length(n) > 0.0f ? glm::normalize(n) : s.normal;
            }
            out.positions.push_back(p);
            prim.vertices[k] = shader::packVertex(s);
        }
        out.primitives.push_back(prim);
    }
    return out;
}

std::vector<shader::PackedPrimitive> buildPrimitivePool(const Scene& scene, const BvhPlan& plan) {
    std::vector<shader::PackedPrimitive> pool(plan.poolTriangles, shader::PackedPrimitive{});
    for (const BlasDesc& blas : plan.blases) {
        const MeshLod& lod = scene.meshes[blas.mesh].lods[blas.lod];
        std::span<const glm::mat4> joints;
        if (blas.instance != kNone && blas.motion == Motion::Skinned) {
            const Instance& inst = scene.instances[size_t(blas.instance)];
            joints = std::span<const glm::mat4>(scene.jointMatrices.data() + inst.jointOffset,
                                                scene.skins[size_t(inst.skin)].joints.size());
        }
        // A per-instance BLAS of a morphing mesh carries its instance's
        // weights (applied before skinning, as glTF orders them).
        std::span<const float> morphWeights;
        if (blas.instance != kNone) {
            morphWeights = scene.instances[size_t(blas.instance)].morphWeights;
        }
        for (const BlasGeometry& g : blas.geometries) {
            const Geometry& source = lod.geometries[g.meshGeometry];
            const UnwrappedGeometry u =
                source.morphTargets.empty() || morphWeights.empty()
                    ? unwrapGeometry(scene, source, joints)
                    : unwrapGeometry(scene, morphedGeometry(source, morphWeights), joints);
            std::copy(u.primitives.begin(), u.primitives.end(), pool.begin() + g.poolOffset);
        }
    }
    return pool;
}

} // namespace glint::scene
