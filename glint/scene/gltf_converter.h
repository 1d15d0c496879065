#pragma once
// What the glTF conversion's files share (not part of the interface; only
// they include it): the Converter, whose members they divide by purpose --
// gltf_convert.cpp (the entry point, nodes and the active scene),
// gltf_accessors.cpp (every accessor checked, then read),
// gltf_materials.cpp (textures and materials), gltf_meshes.cpp (meshes,
// primitives and morph targets) and gltf_animation.cpp (skins and
// animations) -- and the accessor rules it checks against.

#include "glint/scene/gltf_internal.h"

#include "glint/scene/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace glint::scene::gltf {

enum TypeBit : uint32_t { kScalar = 1, kVec2 = 2, kVec3 = 4, kVec4 = 8, kMat4 = 16 };
enum ComponentBit : uint32_t { kFloat = 1, kByte = 2, kUByte = 4, kShort = 8, kUShort = 16, kUInt = 32 };

// What a semantic accepts (glTF 2.0 section 3.7.2.1 and the
// KHR_mesh_quantization table).
struct AccessorRule {
    const char* semantic;
    uint32_t types;
    bool floats;              // FLOAT allowed
    uint32_t normalizedInts;  // integer types allowed with normalized: true
    uint32_t plainInts;       // integer types allowed with normalized: false
};

// A checked accessor: `base` points at element 0 (nullptr: no bufferView,
// all zeros) and `count` elements of `elementSize` bytes at `stride` lie
// inside the buffer.
struct CheckedAccessor {
    const tinygltf::Accessor* accessor = nullptr;
    std::string element;  // "accessor 3 (mesh 'Body' primitive 0 POSITION)"
    const uint8_t* base = nullptr;
    size_t count = 0;
    size_t stride = 0;
    size_t elementSize = 0;
    uint32_t components = 0;
    // Sparse substitution, checked the same way.
    size_t sparseCount = 0;
    const uint8_t* sparseIndices = nullptr;
    int sparseIndexType = 0;
    const uint8_t* sparseValues = nullptr;
};

// "node 3" or "node 3 ('Body')", as errors name an element (gltf_convert.cpp).
std::string element(const char* kind, size_t index, const std::string& name);

class Converter {
public:
    Converter(const tinygltf::Model& model, LoadContext& context) : model_(model), context_(context) {
        quantized_ = std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_mesh_quantization") !=
                     model.extensionsUsed.end();
    }

    Scene run();

private:
    [[noreturn]] void fail(const std::string& where, const std::string& detail) const {
        throw SceneError(context_.file, where, detail);
    }

    void warn(const std::string& where, const std::string& detail) const {
        spdlog::warn("{}: {}: {}", context_.file, where, detail);
    }

    // ----- rules ---------------------------------------------------------

    AccessorRule positionRule() const {
        return {"POSITION", kVec3, true, quantized_ ? kByte | kUByte | kShort | kUShort : 0u,
                quantized_ ? kByte | kUByte | kShort | kUShort : 0u};
    }
    AccessorRule normalRule() const { return {"NORMAL", kVec3, true, quantized_ ? kByte | kShort : 0u, 0u}; }
    AccessorRule tangentRule() const { return {"TANGENT", kVec4, true, quantized_ ? kByte | kShort : 0u, 0u}; }
    AccessorRule texcoordRule(const char* semantic) const {
        return {semantic, kVec2, true, kUByte | kUShort | (quantized_ ? kByte | kShort : 0u),
                quantized_ ? kByte | kUByte | kShort | kUShort : 0u};
    }
    // glTF 2.0 3.7.2.2 and KHR_mesh_quantization: displacements.
    AccessorRule morphPositionRule() const {
        const uint32_t q = quantized_ ? kByte | kShort : 0u;
        return {"morph target POSITION", kVec3, true, q, q};
    }
    AccessorRule morphDirectionRule(const char* semantic) const {
        return {semantic, kVec3, true, quantized_ ? kByte | kShort : 0u, 0u};
    }
    AccessorRule weightsOutputRule() const {
        return {"output", kScalar, true, kByte | kUByte | kShort | kUShort, 0u};
    }
    static AccessorRule colorRule() { return {"COLOR_0", kVec3 | kVec4, true, kUByte | kUShort, 0u}; }
    static AccessorRule jointsRule() { return {"JOINTS_0", kVec4, false, 0u, kUByte | kUShort}; }
    static AccessorRule weightsRule() { return {"WEIGHTS_0", kVec4, true, kUByte | kUShort, 0u}; }
    static AccessorRule indicesRule() { return {"indices", kScalar, false, 0u, kUByte | kUShort | kUInt}; }
    static AccessorRule timesRule() { return {"input", kScalar, true, 0u, 0u}; }
    static AccessorRule inverseBindRule() { return {"inverseBindMatrices", kMat4, true, 0u, 0u}; }
    AccessorRule animationOutputRule(AnimationPath path) const {
        if (path == AnimationPath::Rotation) {
            return {"output", kVec4, true, kByte | kUByte | kShort | kUShort, 0u};
        }
        const uint32_t q = quantized_ ? kByte | kUByte | kShort | kUShort : 0u;
        return {"output", kVec3, true, q, q};
    }

    // ----- accessors (gltf_accessors.cpp) ---------------------------------

    CheckedAccessor checkAccessor(int index, const std::string& context, const AccessorRule& rule) const;

    struct ViewRange {
        const uint8_t* data;
        size_t bytes;
        size_t stride;
    };

    ViewRange checkBufferView(int index, const std::string& where) const;
    void checkSparse(const tinygltf::Accessor& a, CheckedAccessor& c) const;
    template <typename T, typename Convert>
    std::vector<T> readComponents(const CheckedAccessor& c, Convert convert) const;
    std::vector<float> readFloats(const CheckedAccessor& c) const;
    std::vector<uint32_t> readUints(const CheckedAccessor& c) const;

    template <typename Vec> static std::vector<Vec> toVectors(const std::vector<float>& flat, uint32_t components) {
        std::vector<Vec> out(flat.size() / components);
        for (size_t i = 0; i < out.size(); ++i) {
            for (uint32_t k = 0; k < components && k < uint32_t(Vec::length()); ++k) {
                out[i][int(k)] = flat[i * components + k];
            }
        }
        return out;
    }

    // ----- numbers --------------------------------------------------------

    // A JSON number as a float; beyond the float range is as wrong as
    // infinity (and converting it would be undefined behaviour).
    float finiteNumber(double v, const std::string& where, const char* what) const {
        if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max())) {
            fail(where, std::string(what) + " is not finite");
        }
        return float(v);
    }

    template <int N>
    glm::vec<N, float> factor(const std::vector<double>& values, const glm::vec<N, float>& fallback,
                              const std::string& where, const char* what) const {
        if (values.empty()) {
            return fallback;
        }
        if (values.size() != size_t(N)) {
            fail(where, std::string(what) + " has " + std::to_string(values.size()) + " numbers (expected " +
                            std::to_string(N) + ")");
        }
        glm::vec<N, float> out;
        for (int i = 0; i < N; ++i) {
            out[i] = finiteNumber(values[size_t(i)], where, what);
        }
        return out;
    }

    // ----- textures and materials (gltf_materials.cpp) --------------------

    int32_t imageTexture(int index);
    static Wrap wrapMode(int gl);

    // Texture coordinate sets the loader keeps (Geometry::texcoords0/1).
    static constexpr int kTexCoordSets = 2;

    glm::vec2 transformPair(const tinygltf::Value& ext, const char* key, glm::vec2 fallback,
                            const std::string& where) const;
    template <typename Info> TextureRef textureRef(const Info& info, const std::string& where);

    void convertMaterials();
    uint32_t defaultMaterial();

    // ----- meshes (gltf_meshes.cpp) ---------------------------------------

    void convertMeshes();
    Geometry convertPrimitive(const tinygltf::Primitive& prim, int mode, const std::string& context);
    void convertMorphTargets(const tinygltf::Primitive& prim, Geometry& g, const std::string& context);
    std::vector<uint32_t> toTriangleList(const std::vector<uint32_t>& indices, int mode,
                                         const std::string& where) const;

    // ----- nodes (gltf_convert.cpp) ---------------------------------------

    void convertNodes();

    // ----- skins and animations (gltf_animation.cpp) ----------------------

    void convertSkins();
    AnimationSampler convertSampler(const tinygltf::Animation& anim, int samplerIndex, AnimationPath path,
                                    const std::string& where, size_t weightCount);
    void convertAnimations();

    // ----- the active scene (gltf_convert.cpp) ----------------------------

    bool animatedOrBelowAnimated(uint32_t node) const;
    void instantiate();
    void instantiateNode(uint32_t n, const tinygltf::Node& src, const glm::mat4& world);
    void lightFromNode(uint32_t n, const tinygltf::Node& src, const glm::mat4& world, bool& warnedLights);
    void cameraFromNode(const tinygltf::Node& src, const glm::mat4& world);

    const tinygltf::Model& model_;
    LoadContext& context_;
    Scene scene_;
    bool quantized_ = false;
    std::optional<uint32_t> defaultMaterial_;
    std::map<int, int32_t> imageTextures_;
    std::set<int> warnedTextures_;
    std::set<uint32_t> animatedNodes_;  // by translation, rotation or scale
    std::set<uint32_t> morphedNodes_;   // by weights
    bool sunFound_ = false;
    bool cameraFound_ = false;
};

} // namespace glint::scene::gltf
