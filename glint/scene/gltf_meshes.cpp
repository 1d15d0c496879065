// glTF meshes -> scene meshes: each primitive's attributes checked and read
// (positions, normals, tangents, two texture coordinate sets, colours,
// joints and weights), its indices made a triangle list, its material's
// texture coordinate sets checked, its morph targets read, and missing
// normals and tangents generated. Members of the Converter
// (gltf_converter.h).

#include "glint/scene/gltf_converter.h"

#include "glint/scene/mesh_tools.h"

#include <utility>

namespace glint::scene::gltf {

namespace {

std::string nameOr(const std::string& name, const char* kind, size_t index) {
    return name.empty() ? std::string(kind) + " " + std::to_string(index) : std::string(kind) + " '" + name + "'";
}

} // namespace

void Converter::convertMeshes() {
    scene_.meshes.resize(model_.meshes.size());
    for (size_t m = 0; m < model_.meshes.size(); ++m) {
        const tinygltf::Mesh& src = model_.meshes[m];
        Mesh& mesh = scene_.meshes[m];
        mesh.name = src.name;
        mesh.lods.resize(1);
        bool warnedMode = false;
        for (size_t p = 0; p < src.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = src.primitives[p];
            const std::string context = nameOr(src.name, "mesh", m) + " primitive " + std::to_string(p);
            if (p > 0 && prim.targets.size() != src.primitives[0].targets.size()) {
                fail(context, std::to_string(prim.targets.size()) + " morph targets, but primitive 0 has " +
                                  std::to_string(src.primitives[0].targets.size()) +
                                  " (glTF requires the same number in every primitive)");
            }
            const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
                if (!warnedMode) {
                    warn(element("mesh", m, src.name), "point and line primitives are skipped");
                    warnedMode = true;
                }
                continue;
            }
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                fail(context, "mode " + std::to_string(prim.mode) + " is not a glTF primitive mode");
            }
            if (prim.attributes.find("POSITION") == prim.attributes.end()) {
                warn(context, "has no POSITION; skipped");
                continue;
            }
            Geometry g = convertPrimitive(prim, mode, context);
            mesh.lods[0].geometries.push_back(std::move(g));
        }
        const size_t targets = src.primitives.empty() ? 0 : src.primitives[0].targets.size();
        const std::string meshWhere = element("mesh", m, src.name);
        if (!src.weights.empty() && src.weights.size() != targets) {
            fail(meshWhere, "weights has " + std::to_string(src.weights.size()) + " numbers for " +
                                std::to_string(targets) + " morph targets");
        }
        mesh.morphWeights.assign(targets, 0.0f);
        for (size_t t = 0; t < src.weights.size(); ++t) {
            mesh.morphWeights[t] = finiteNumber(src.weights[t], meshWhere, "weights");
        }
    }
}

Geometry Converter::convertPrimitive(const tinygltf::Primitive& prim, int mode, const std::string& context) {
    Geometry g;
    const auto attribute = [&](const char* semantic) -> int {
        const auto it = prim.attributes.find(semantic);
        return it == prim.attributes.end() ? -2 : it->second;
    };
    const CheckedAccessor position = checkAccessor(attribute("POSITION"), context + " POSITION", positionRule());
    g.positions = toVectors<glm::vec3>(readFloats(position), 3);
    const size_t n = g.positions.size();
    const auto sameCount = [&](const CheckedAccessor& c, const char* semantic) {
        if (c.count != n) {
            fail(c.element, std::string(semantic) + " count " + std::to_string(c.count) +
                                " differs from POSITION count " + std::to_string(n));
        }
    };
    for (const auto& [semantic, index] : prim.attributes) {
        const std::string where = context + " " + semantic;
        if (semantic == "POSITION") {
            continue;
        } else if (semantic == "NORMAL") {
            const CheckedAccessor c = checkAccessor(index, where, normalRule());
            sameCount(c, "NORMAL");
            g.normals = toVectors<glm::vec3>(readFloats(c), 3);
        } else if (semantic == "TANGENT") {
            const CheckedAccessor c = checkAccessor(index, where, tangentRule());
            sameCount(c, "TANGENT");
            g.tangents = toVectors<glm::vec4>(readFloats(c), 4);
        } else if (semantic == "TEXCOORD_0" || semantic == "TEXCOORD_1") {
            const CheckedAccessor c = checkAccessor(index, where, texcoordRule(semantic.c_str()));
            sameCount(c, semantic.c_str());
            (semantic == "TEXCOORD_0" ? g.texcoords0 : g.texcoords1) = toVectors<glm::vec2>(readFloats(c), 2);
        } else if (semantic == "COLOR_0") {
            const CheckedAccessor c = checkAccessor(index, where, colorRule());
            sameCount(c, "COLOR_0");
            g.colors = toVectors<glm::vec4>(readFloats(c), c.components);
            if (c.components == 3) {
                for (glm::vec4& color : g.colors) {
                    color.a = 1.0f;
                }
            }
        } else if (semantic == "JOINTS_0") {
            const CheckedAccessor c = checkAccessor(index, where, jointsRule());
            sameCount(c, "JOINTS_0");
            const std::vector<uint32_t> joints = readUints(c);
            g.joints.resize(n);
            for (size_t i = 0; i < n; ++i) {
                // UNSIGNED_BYTE/SHORT by the rule, so every value fits 16 bits.
                g.joints[i] = glm::u16vec4(joints[4 * i], joints[4 * i + 1], joints[4 * i + 2], joints[4 * i + 3]);
            }
        } else if (semantic == "WEIGHTS_0") {
            const CheckedAccessor c = checkAccessor(index, where, weightsRule());
            sameCount(c, "WEIGHTS_0");
            g.weights = toVectors<glm::vec4>(readFloats(c), 4);
        } else {
            spdlog::debug("{}: {}: attribute {} is not used", context_.file, context, semantic);
        }
    }
    if (g.joints.empty() != g.weights.empty()) {
        fail(context, "JOINTS_0 and WEIGHTS_0 must come together");
    }
    for (glm::vec4& w : g.weights) {
        const float sum = w.x + w.y + w.z + w.w;
        w = sum > 0.0f ? w / sum : glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
    }

    std::vector<uint32_t> indices;
    std::string indexElement;
    if (prim.indices >= 0 || prim.indices < -1) {
        const CheckedAccessor c = checkAccessor(prim.indices, context + " indices", indicesRule());
        indices = readUints(c);
        indexElement = c.element;
        for (size_t i = 0; i < indices.size(); ++i) {
            if (indices[i] >= n) {
                fail(c.element, "index " + std::to_string(indices[i]) + " at position " + std::to_string(i) +
                                    " >= vertex count " + std::to_string(n));
            }
        }
    } else {
        indexElement = position.element;
        context_.chargeDecoded(n * sizeof(uint32_t), context);
        indices.resize(n);
        for (uint32_t i = 0; i < n; ++i) {
            indices[i] = i;
        }
    }
    g.indices = toTriangleList(indices, mode, indexElement);

    if (prim.material == -1) {
        g.material = defaultMaterial();
    } else if (prim.material < 0 || size_t(prim.material) >= model_.materials.size()) {
        fail(context, "material " + std::to_string(prim.material) + " out of range (" +
                          std::to_string(model_.materials.size()) + " materials)");
    } else {
        g.material = uint32_t(prim.material);
    }

    // Every texture the material samples needs its coordinate set here
    // (the glTF validator's MESH_PRIMITIVE_TOO_FEW_TEXCOORDS).
    const Material& material = scene_.materials[g.material];
    for (const auto& [ref, slot] : {std::pair{&material.baseColorTexture, "baseColorTexture"},
                                    std::pair{&material.metallicRoughnessTexture, "metallicRoughnessTexture"},
                                    std::pair{&material.normalTexture, "normalTexture"},
                                    std::pair{&material.emissiveTexture, "emissiveTexture"},
                                    std::pair{&material.occlusionTexture, "occlusionTexture"}}) {
        const bool present = ref->texCoord == 0 ? !g.texcoords0.empty() : !g.texcoords1.empty();
        if (ref->valid() && !present) {
            fail(context, element("material", g.material, material.name) + " " + slot + " uses TEXCOORD_" +
                              std::to_string(ref->texCoord) + ", which the primitive does not have");
        }
    }

    convertMorphTargets(prim, g, context);

    if (g.normals.empty()) {
        // glTF 2.0 3.7.2.1: without normals, flat normals.
        context_.chargeDecoded(g.indices.size() * (sizeof(glm::vec3) * 2 + sizeof(glm::vec2)), context);
        generateFlatNormals(g);
    } else {
        for (glm::vec3& nrm : g.normals) {
            const float len = glm::length(nrm);
            nrm = len > 0.0f ? nrm / len : glm::vec3(0.0f, 1.0f, 0.0f);
        }
    }
    if (g.tangents.empty()) {
        // From the coordinates the normal map is sampled with.
        context_.chargeDecoded(g.positions.size() * sizeof(glm::vec4), context);
        generateTangents(g, material.normalTexture.valid() ? material.normalTexture.texCoord : 0);
    } else {
        // glTF: unit xyz, w = +-1 (the bitangent's sign). A zero tangent
        // becomes any vector perpendicular to the normal.
        for (size_t v = 0; v < g.tangents.size(); ++v) {
            glm::vec4& t = g.tangents[v];
            const glm::vec3 xyz(t);
            const float len = glm::length(xyz);
            t = glm::vec4(len > 0.0f ? xyz / len : anyPerpendicular(g.normals[v]), t.w < 0.0f ? -1.0f : 1.0f);
        }
    }
    return g;
}

// glTF morph targets of `prim` (per-vertex displacements) into `g`.
void Converter::convertMorphTargets(const tinygltf::Primitive& prim, Geometry& g, const std::string& context) {
    const size_t n = g.positions.size();
    for (size_t t = 0; t < prim.targets.size(); ++t) {
        const std::string targetWhere = context + " target " + std::to_string(t);
        MorphTarget target;
        for (const auto& [semantic, index] : prim.targets[t]) {
            const std::string where = targetWhere + " " + semantic;
            std::vector<glm::vec3>* out = nullptr;
            AccessorRule rule;
            if (semantic == "POSITION") {
                out = &target.positions;
                rule = morphPositionRule();
            } else if (semantic == "NORMAL") {
                out = &target.normals;
                rule = morphDirectionRule("morph target NORMAL");
            } else if (semantic == "TANGENT") {
                out = &target.tangents;
                rule = morphDirectionRule("morph target TANGENT");
            } else {
                spdlog::debug("{}: {}: morph target attribute {} is not used", context_.file, targetWhere,
                              semantic);
                continue;
            }
            const CheckedAccessor c = checkAccessor(index, where, rule);
            if (c.count != n) {
                fail(c.element, "morph target " + semantic + " count " + std::to_string(c.count) +
                                    " differs from POSITION count " + std::to_string(n));
            }
            *out = toVectors<glm::vec3>(readFloats(c), 3);
        }
        g.morphTargets.push_back(std::move(target));
    }
}

std::vector<uint32_t> Converter::toTriangleList(const std::vector<uint32_t>& indices, int mode,
                                                const std::string& where) const {
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (indices.size() % 3 != 0) {
            fail(where, "triangle list of " + std::to_string(indices.size()) + " indices (not a multiple of 3)");
        }
        return indices;
    }
    if (indices.size() < 3) {
        fail(where, "triangle strip or fan of " + std::to_string(indices.size()) + " indices");
    }
    std::vector<uint32_t> out;
    out.reserve((indices.size() - 2) * 3);
    for (size_t i = 0; i + 2 < indices.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            // glTF 2.0 3.7.2.1: keep the winding of even triangles.
            const size_t odd = i % 2;
            out.insert(out.end(), {indices[i], indices[i + 1 + odd], indices[i + 2 - odd]});
        } else {
            out.insert(out.end(), {indices[i + 1], indices[i + 2], indices[0]});
        }
    }
    return out;
}

} // namespace glint::scene::gltf
