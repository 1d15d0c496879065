// tinygltf model -> scene model. Every accessor is checked against its
// bufferView and buffer (offset, count, stride, component type, element
// type) and every index against what it indexes before anything is read;
// tinygltf itself checks none of it.

#include "glint/scene/gltf_internal.h"

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/image_io.h"
#include "glint/scene/mesh_tools.h"

#include <spdlog/spdlog.h>

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <tuple>

namespace glint::scene::gltf {

namespace {

// ---------------------------------------------------------------------------
// Accessor rules
// ---------------------------------------------------------------------------

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

uint32_t typeBit(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return kScalar;
    case TINYGLTF_TYPE_VEC2: return kVec2;
    case TINYGLTF_TYPE_VEC3: return kVec3;
    case TINYGLTF_TYPE_VEC4: return kVec4;
    case TINYGLTF_TYPE_MAT4: return kMat4;
    default: return 0;
    }
}

uint32_t componentCount(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

uint32_t componentBit(int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return kFloat;
    case TINYGLTF_COMPONENT_TYPE_BYTE: return kByte;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return kUByte;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return kShort;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return kUShort;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return kUInt;
    default: return 0;
    }
}

size_t componentSize(int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    default: return 4;
    }
}

std::string componentTypeName(int componentType) {
    const char* name = "unknown";
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: name = "BYTE"; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: name = "UNSIGNED_BYTE"; break;
    case TINYGLTF_COMPONENT_TYPE_SHORT: name = "SHORT"; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: name = "UNSIGNED_SHORT"; break;
    case TINYGLTF_COMPONENT_TYPE_INT: name = "INT"; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: name = "UNSIGNED_INT"; break;
    case TINYGLTF_COMPONENT_TYPE_FLOAT: name = "FLOAT"; break;
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: name = "DOUBLE"; break;
    default: break;
    }
    return std::string(name) + " (" + std::to_string(componentType) + ")";
}

std::string typeName(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "type " + std::to_string(type);
    }
}

std::string typeList(uint32_t types) {
    std::string out;
    for (const auto& [bit, name] : {std::pair{kScalar, "SCALAR"}, std::pair{kVec2, "VEC2"}, std::pair{kVec3, "VEC3"},
                                    std::pair{kVec4, "VEC4"}, std::pair{kMat4, "MAT4"}}) {
        if (types & bit) {
            out += out.empty() ? name : std::string("/") + name;
        }
    }
    return out;
}

// Converts one component to float following the glTF normalisation rules
// (e.g. a normalized BYTE c is max(c / 127, -1)).
float componentAsFloat(const uint8_t* p, int componentType, bool normalized) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p, 4);
        return v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const float v = float(int8_t(p[0]));
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(p[0]) / 255.0f : float(p[0]);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t s;
        std::memcpy(&s, p, 2);
        return normalized ? std::max(float(s) / 32767.0f, -1.0f) : float(s);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s;
        std::memcpy(&s, p, 2);
        return normalized ? float(s) / 65535.0f : float(s);
    }
    default: return 0.0f;
    }
}

uint32_t componentAsUint(const uint8_t* p, int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s;
        std::memcpy(&s, p, 2);
        return s;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default: return 0;
    }
}

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

// Upper bound on elements of one accessor; indices are 32-bit.
constexpr size_t kMaxAccessorCount = size_t(1) << 31;

std::string nameOr(const std::string& name, const char* kind, size_t index) {
    return name.empty() ? std::string(kind) + " " + std::to_string(index) : std::string(kind) + " '" + name + "'";
}

std::string element(const char* kind, size_t index, const std::string& name) {
    std::string s = std::string(kind) + " " + std::to_string(index);
    return name.empty() ? s : s + " ('" + name + "')";
}

// ---------------------------------------------------------------------------
// The converter
// ---------------------------------------------------------------------------

class Converter {
public:
    Converter(const tinygltf::Model& model, LoadContext& context) : model_(model), context_(context) {
        quantized_ = std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_mesh_quantization") !=
                     model.extensionsUsed.end();
    }

    Scene run() {
        scene_.name = context_.file;
        convertMaterials();
        convertMeshes();
        convertNodes();
        convertSkins();
        convertAnimations();
        instantiate();
        return std::move(scene_);
    }

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

    // ----- accessors -----------------------------------------------------

    CheckedAccessor checkAccessor(int index, const std::string& context, const AccessorRule& rule) const {
        if (index < 0 || size_t(index) >= model_.accessors.size()) {
            fail(context, "accessor " + std::to_string(index) + " out of range (" +
                              std::to_string(model_.accessors.size()) + " accessors)");
        }
        const tinygltf::Accessor& a = model_.accessors[size_t(index)];
        CheckedAccessor c;
        c.accessor = &a;
        c.element = "accessor " + std::to_string(index) + " (" + context + ")";
        if (!(typeBit(a.type) & rule.types)) {
            fail(c.element, "type " + typeName(a.type) + " is not allowed for " + rule.semantic + " (expected " +
                                typeList(rule.types) + ")");
        }
        const uint32_t bit = componentBit(a.componentType);
        const bool allowed = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT
                                 ? rule.floats
                                 : (bit & (a.normalized ? rule.normalizedInts : rule.plainInts)) != 0;
        if (!allowed) {
            fail(c.element, "componentType " + componentTypeName(a.componentType) +
                                (a.normalized ? " normalized" : "") + " is not allowed for " + rule.semantic);
        }
        c.components = componentCount(a.type);
        c.elementSize = componentSize(a.componentType) * c.components;
        c.count = a.count;
        if (c.count == 0 || c.count > kMaxAccessorCount) {
            fail(c.element,
                 "count " + std::to_string(c.count) + " (must be 1 to " + std::to_string(kMaxAccessorCount) + ")");
        }
        c.stride = c.elementSize;
        if (a.bufferView != -1) {
            const auto [data, bytes, stride] = checkBufferView(a.bufferView, c.element);
            c.stride = stride ? stride : c.elementSize;
            if (c.stride < c.elementSize) {
                fail(c.element, "byteStride " + std::to_string(c.stride) + " of bufferView " +
                                    std::to_string(a.bufferView) + " is smaller than the element size " +
                                    std::to_string(c.elementSize));
            }
            // byteOffset + (count - 1) * stride + elementSize <= bytes, in
            // an order that cannot overflow.
            const bool fits = a.byteOffset <= bytes && c.elementSize <= bytes - a.byteOffset &&
                              (c.count - 1) <= (bytes - a.byteOffset - c.elementSize) / c.stride;
            if (!fits) {
                fail(c.element, "byteOffset " + std::to_string(a.byteOffset) + " + count " + std::to_string(c.count) +
                                    " * stride " + std::to_string(c.stride) + " exceeds bufferView " +
                                    std::to_string(a.bufferView) + " (" + std::to_string(bytes) + " bytes)");
            }
            c.base = data + a.byteOffset;
        }
        if (a.sparse.isSparse) {
            checkSparse(a, c);
        }
        return c;
    }

    struct ViewRange {
        const uint8_t* data;
        size_t bytes;
        size_t stride;
    };

    ViewRange checkBufferView(int index, const std::string& where) const {
        if (index < 0 || size_t(index) >= model_.bufferViews.size()) {
            fail(where, "bufferView " + std::to_string(index) + " out of range (" +
                            std::to_string(model_.bufferViews.size()) + " bufferViews)");
        }
        const tinygltf::BufferView& view = model_.bufferViews[size_t(index)];
        const std::string viewName = "bufferView " + std::to_string(index);
        if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size()) {
            fail(where, viewName + " refers to buffer " + std::to_string(view.buffer) + " out of range (" +
                            std::to_string(model_.buffers.size()) + " buffers)");
        }
        const std::vector<unsigned char>& data = model_.buffers[size_t(view.buffer)].data;
        if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
            fail(where, viewName + " (byteOffset " + std::to_string(view.byteOffset) + " + byteLength " +
                            std::to_string(view.byteLength) + ") exceeds buffer " + std::to_string(view.buffer) + " (" +
                            std::to_string(data.size()) + " bytes)");
        }
        return {data.data() + view.byteOffset, view.byteLength, view.byteStride};
    }

    void checkSparse(const tinygltf::Accessor& a, CheckedAccessor& c) const {
        const auto& s = a.sparse;
        if (s.count <= 0 || size_t(s.count) > c.count) {
            fail(c.element,
                 "sparse count " + std::to_string(s.count) + " (accessor count " + std::to_string(c.count) + ")");
        }
        const uint32_t indexBit = componentBit(s.indices.componentType);
        if (!(indexBit & (kUByte | kUShort | kUInt))) {
            fail(c.element, "sparse indices componentType " + componentTypeName(s.indices.componentType));
        }
        c.sparseCount = size_t(s.count);
        c.sparseIndexType = s.indices.componentType;
        const auto place = [&](int viewIndex, int byteOffset, size_t elementBytes, const char* what) {
            const ViewRange view = checkBufferView(viewIndex, c.element + " sparse " + what);
            const size_t need = c.sparseCount * elementBytes;
            if (byteOffset < 0 || size_t(byteOffset) > view.bytes || need > view.bytes - size_t(byteOffset)) {
                fail(c.element, std::string("sparse ") + what + " (byteOffset " + std::to_string(byteOffset) + " + " +
                                    std::to_string(need) + " bytes) exceed bufferView " + std::to_string(viewIndex) +
                                    " (" + std::to_string(view.bytes) + " bytes)");
            }
            return view.data + byteOffset;
        };
        c.sparseIndices =
            place(s.indices.bufferView, s.indices.byteOffset, componentSize(s.indices.componentType), "indices");
        c.sparseValues = place(s.values.bufferView, s.values.byteOffset, c.elementSize, "values");
    }

    // All components of all elements, each converted by `convert` from its
    // bytes, with sparse substitution applied.
    template <typename T, typename Convert>
    std::vector<T> readComponents(const CheckedAccessor& c, Convert convert) const {
        const size_t componentBytes = componentSize(c.accessor->componentType);
        context_.chargeDecoded(uint64_t(c.count) * c.components * sizeof(T), c.element);
        std::vector<T> out(c.count * c.components, T{});
        const auto readElement = [&](const uint8_t* src, size_t i) {
            for (uint32_t k = 0; k < c.components; ++k) {
                out[i * c.components + k] = convert(src + k * componentBytes);
            }
        };
        if (c.base) {
            for (size_t i = 0; i < c.count; ++i) {
                readElement(c.base + i * c.stride, i);
            }
        }
        for (size_t k = 0; k < c.sparseCount; ++k) {
            const uint32_t target =
                componentAsUint(c.sparseIndices + k * componentSize(c.sparseIndexType), c.sparseIndexType);
            if (target >= c.count) {
                fail(c.element, "sparse index " + std::to_string(target) + " at position " + std::to_string(k) +
                                    " >= count " + std::to_string(c.count));
            }
            readElement(c.sparseValues + k * c.elementSize, target);
        }
        return out;
    }

    // All components of all elements as floats (normalised per glTF),
    // sparse substitution applied, every value finite.
    std::vector<float> readFloats(const CheckedAccessor& c) const {
        const tinygltf::Accessor& a = *c.accessor;
        std::vector<float> out = readComponents<float>(
            c, [&](const uint8_t* src) { return componentAsFloat(src, a.componentType, a.normalized); });
        for (size_t i = 0; i < out.size(); ++i) {
            if (!std::isfinite(out[i])) {
                fail(c.element, "element " + std::to_string(i / c.components) + " is not finite");
            }
        }
        return out;
    }

    std::vector<uint32_t> readUints(const CheckedAccessor& c) const {
        const tinygltf::Accessor& a = *c.accessor;
        return readComponents<uint32_t>(c, [&](const uint8_t* src) { return componentAsUint(src, a.componentType); });
    }

    template <typename Vec> static std::vector<Vec> toVectors(const std::vector<float>& flat, uint32_t components) {
        std::vector<Vec> out(flat.size() / components);
        for (size_t i = 0; i < out.size(); ++i) {
            for (uint32_t k = 0; k < components && k < uint32_t(Vec::length()); ++k) {
                out[i][int(k)] = flat[i * components + k];
            }
        }
        return out;
    }

    // ----- textures and materials -----------------------------------------

    // Scene texture of glTF image `index`, decoded on first use; kNone with
    // one warning when the image is missing or cannot be decoded.
    int32_t imageTexture(int index) {
        if (const auto it = imageTextures_.find(index); it != imageTextures_.end()) {
            return it->second;
        }
        const tinygltf::Image& image = model_.images[size_t(index)];
        const std::string where = element("image", size_t(index), image.name.empty() ? image.uri : image.name);
        int32_t result = kNone;
        std::span<const uint8_t> bytes;
        std::string missing;
        if (image.bufferView >= 0) {
            const ViewRange view = checkBufferView(image.bufferView, where);  // a bad range is a broken file: throws
            bytes = {view.data, view.bytes};
        } else if (const auto enc = context_.encodedImages.find(index); enc != context_.encodedImages.end()) {
            bytes = enc->second;
        } else if (const auto m = context_.missingImages.find(index); m != context_.missingImages.end()) {
            missing = m->second;
        } else {
            missing = "no image data could be read";
        }
        if (missing.empty()) {
            try {
                const uint64_t remaining = context_.options.maxDecodedBytes - context_.decodedBytes;
                const ImageLimits limits{context_.options.maxImageDimension, remaining};
                Texture texture = decodeImageRgba8(bytes, limits, context_.file, where);
                texture.name = image.name.empty() ? image.uri : image.name;
                context_.chargeDecoded(texture.rgba8.size(), where);
                result = int32_t(scene_.textures.size());
                scene_.textures.push_back(std::move(texture));
            } catch (const SceneError& e) {
                missing = e.what();
                const std::string prefix = context_.file + ": " + where + ": ";
                if (missing.rfind(prefix, 0) == 0) {
                    missing = missing.substr(prefix.size());
                }
            }
        }
        if (result == kNone) {
            warn(where, missing + "; materials using it fall back to their factors");
        }
        imageTextures_[index] = result;
        return result;
    }

    static Wrap wrapMode(int gl) {
        switch (gl) {
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
        default: return Wrap::Repeat;
        }
    }

    // Texture coordinate sets the loader keeps (Geometry::texcoords0/1).
    static constexpr int kTexCoordSets = 2;

    // A number of a KHR_texture_transform member, or `fallback` if absent.
    glm::vec2 transformPair(const tinygltf::Value& ext, const char* key, glm::vec2 fallback,
                            const std::string& where) const {
        if (!ext.Has(key)) {
            return fallback;
        }
        const tinygltf::Value& v = ext.Get(key);
        if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber()) {
            fail(where, std::string("KHR_texture_transform ") + key + " is not an array of two numbers");
        }
        return {finiteNumber(v.Get(0).GetNumberAsDouble(), where, key),
                finiteNumber(v.Get(1).GetNumberAsDouble(), where, key)};
    }

    // glTF textureInfo (index, texCoord, extensions) -> TextureRef, with
    // KHR_texture_transform (offset, rotation, scale, texCoord override).
    template <typename Info> TextureRef textureRef(const Info& info, const std::string& where) {
        TextureRef ref;
        const int textureIndex = info.index;
        if (textureIndex == -1) {
            return ref;
        }
        if (textureIndex < 0 || size_t(textureIndex) >= model_.textures.size()) {
            fail(where, "texture " + std::to_string(textureIndex) + " out of range (" +
                            std::to_string(model_.textures.size()) + " textures)");
        }
        int texCoord = info.texCoord;
        if (const auto it = info.extensions.find("KHR_texture_transform"); it != info.extensions.end()) {
            const tinygltf::Value& ext = it->second;
            if (!ext.IsObject()) {
                fail(where, "KHR_texture_transform is not an object");
            }
            ref.offset = transformPair(ext, "offset", glm::vec2(0.0f), where);
            ref.scale = transformPair(ext, "scale", glm::vec2(1.0f), where);
            if (ext.Has("rotation")) {
                if (!ext.Get("rotation").IsNumber()) {
                    fail(where, "KHR_texture_transform rotation is not a number");
                }
                ref.rotation = finiteNumber(ext.Get("rotation").GetNumberAsDouble(), where, "rotation");
            }
            if (ext.Has("texCoord")) {
                const tinygltf::Value& tc = ext.Get("texCoord");
                const double v = tc.IsNumber() ? tc.GetNumberAsDouble() : -1.0;
                if (!(v >= 0.0 && v <= 65535.0) || v != std::floor(v)) {
                    fail(where, "KHR_texture_transform texCoord must be a non-negative integer");
                }
                texCoord = int(v);
            }
        }
        if (texCoord < 0) {
            fail(where, "texCoord " + std::to_string(texCoord) + " (must be a non-negative integer)");
        }
        if (!context_.options.loadTextures) {
            return ref;
        }
        if (texCoord >= kTexCoordSets) {
            warn(where, "uses TEXCOORD_" + std::to_string(texCoord) +
                            " (only TEXCOORD_0 and TEXCOORD_1 are supported); the texture is not used");
            return ref;
        }
        const tinygltf::Texture& texture = model_.textures[size_t(textureIndex)];
        const std::string textureName = element("texture", size_t(textureIndex), texture.name);
        if (texture.source < 0) {
            if (warnedTextures_.insert(textureIndex).second) {
                warn(textureName, "has no core image source (an image extension?); flat fallback");
            }
            return ref;
        }
        if (size_t(texture.source) >= model_.images.size()) {
            fail(textureName, "source " + std::to_string(texture.source) + " out of range (" +
                                  std::to_string(model_.images.size()) + " images)");
        }
        if (texture.sampler != -1) {
            if (texture.sampler < 0 || size_t(texture.sampler) >= model_.samplers.size()) {
                fail(textureName, "sampler " + std::to_string(texture.sampler) + " out of range");
            }
            ref.wrapS = wrapMode(model_.samplers[size_t(texture.sampler)].wrapS);
            ref.wrapT = wrapMode(model_.samplers[size_t(texture.sampler)].wrapT);
        }
        ref.texture = imageTexture(texture.source);
        ref.texCoord = uint32_t(texCoord);
        return ref;
    }

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

    void convertMaterials() {
        for (size_t i = 0; i < model_.materials.size(); ++i) {
            const tinygltf::Material& src = model_.materials[i];
            const std::string where = element("material", i, src.name);
            Material m;
            m.name = src.name;
            const tinygltf::PbrMetallicRoughness& pbr = src.pbrMetallicRoughness;
            m.baseColorFactor = factor<4>(pbr.baseColorFactor, glm::vec4(1.0f), where, "baseColorFactor");
            m.metallicFactor = std::clamp(finiteNumber(pbr.metallicFactor, where, "metallicFactor"), 0.0f, 1.0f);
            m.roughnessFactor = std::clamp(finiteNumber(pbr.roughnessFactor, where, "roughnessFactor"), 0.0f, 1.0f);
            m.emissiveFactor = factor<3>(src.emissiveFactor, glm::vec3(0.0f), where, "emissiveFactor");
            m.normalScale = finiteNumber(src.normalTexture.scale, where, "normalTexture.scale");
            m.occlusionStrength = finiteNumber(src.occlusionTexture.strength, where, "occlusionTexture.strength");
            if (src.alphaMode == "OPAQUE" || src.alphaMode.empty()) {
                m.alphaMode = AlphaMode::Opaque;
            } else if (src.alphaMode == "MASK") {
                m.alphaMode = AlphaMode::Mask;
            } else if (src.alphaMode == "BLEND") {
                m.alphaMode = AlphaMode::Blend;
            } else {
                fail(where, "alphaMode '" + src.alphaMode + "'");
            }
            m.alphaCutoff = finiteNumber(src.alphaCutoff, where, "alphaCutoff");
            m.doubleSided = src.doubleSided;
            m.baseColorTexture = textureRef(pbr.baseColorTexture, where + " baseColorTexture");
            m.metallicRoughnessTexture = textureRef(pbr.metallicRoughnessTexture, where + " metallicRoughnessTexture");
            m.normalTexture = textureRef(src.normalTexture, where + " normalTexture");
            m.emissiveTexture = textureRef(src.emissiveTexture, where + " emissiveTexture");
            m.occlusionTexture = textureRef(src.occlusionTexture, where + " occlusionTexture");

            if (const auto it = src.extensions.find("KHR_materials_emissive_strength"); it != src.extensions.end()) {
                const tinygltf::Value& strength = it->second.Get("emissiveStrength");
                if (strength.IsNumber()) {
                    const float s = finiteNumber(strength.GetNumberAsDouble(), where, "emissiveStrength");
                    if (s < 0.0f) {
                        fail(where, "emissiveStrength " + std::to_string(s) + " is negative");
                    }
                    m.emissiveStrength = s;
                }
            }
            if (const auto it = src.extensions.find("KHR_materials_ior"); it != src.extensions.end()) {
                const tinygltf::Value& iorValue = it->second.Get("ior");
                if (iorValue.IsNumber()) {
                    const float ior = finiteNumber(iorValue.GetNumberAsDouble(), where, "ior");
                    // f0 = ((ior - 1) / (ior + 1))^2 (Fresnel at normal
                    // incidence), then Filament's f0 = 0.16 reflectance^2.
                    const float r = (ior - 1.0f) / (ior + 1.0f);
                    m.reflectance = ior >= 1.0f ? std::clamp(std::sqrt(r * r / 0.16f), 0.0f, 1.0f) : 1.0f;
                }
            }
            scene_.materials.push_back(std::move(m));
        }
    }

    uint32_t defaultMaterial() {
        if (!defaultMaterial_) {
            Material m;
            m.name = "default";
            // glTF 2.0 3.9.6: the default material is metallic 1, roughness 1;
            // a grey dielectric looks like what authors expect instead.
            m.metallicFactor = 0.0f;
            m.roughnessFactor = 0.5f;
            defaultMaterial_ = uint32_t(scene_.materials.size());
            scene_.materials.push_back(std::move(m));
        }
        return *defaultMaterial_;
    }

    // ----- meshes ----------------------------------------------------------

    void convertMeshes() {
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

    Geometry convertPrimitive(const tinygltf::Primitive& prim, int mode, const std::string& context) {
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
    void convertMorphTargets(const tinygltf::Primitive& prim, Geometry& g, const std::string& context) {
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

    std::vector<uint32_t> toTriangleList(const std::vector<uint32_t>& indices, int mode,
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

    // ----- nodes -------------------------------------------------------------

    void convertNodes() {
        scene_.nodes.resize(model_.nodes.size());
        for (size_t i = 0; i < model_.nodes.size(); ++i) {
            const tinygltf::Node& src = model_.nodes[i];
            const std::string where = element("node", i, src.name);
            Node& node = scene_.nodes[i];
            node.name = src.name;
            const auto numbers = [&](const std::vector<double>& values, size_t expected, const char* what) {
                if (!values.empty() && values.size() != expected) {
                    fail(where, std::string(what) + " has " + std::to_string(values.size()) + " numbers (expected " +
                                    std::to_string(expected) + ")");
                }
                for (double v : values) {
                    finiteNumber(v, where, what);
                }
                return !values.empty();
            };
            if (numbers(src.matrix, 16, "matrix")) {
                std::array<float, 16> m{};
                std::transform(src.matrix.begin(), src.matrix.end(), m.begin(), [](double d) { return float(d); });
                node.matrix = glm::make_mat4(m.data());  // glTF matrices are column-major, as glm's
            }
            if (numbers(src.translation, 3, "translation")) {
                node.translation = glm::vec3(src.translation[0], src.translation[1], src.translation[2]);
            }
            if (numbers(src.rotation, 4, "rotation")) {
                const glm::vec4 q(src.rotation[0], src.rotation[1], src.rotation[2], src.rotation[3]);
                const float len = glm::length(q);
                if (!(len > 0.0f)) {
                    fail(where, "rotation is a zero quaternion");
                }
                node.rotation = glm::quat(q.w / len, q.x / len, q.y / len, q.z / len);
            }
            if (numbers(src.scale, 3, "scale")) {
                node.scale = glm::vec3(src.scale[0], src.scale[1], src.scale[2]);
            }
            if (src.mesh < -1 || src.mesh >= int(model_.meshes.size())) {
                fail(where, "mesh " + std::to_string(src.mesh) + " out of range (" +
                                std::to_string(model_.meshes.size()) + " meshes)");
            }
            if (src.mesh >= 0) {
                node.morphWeights = scene_.meshes[size_t(src.mesh)].morphWeights;
            }
            if (!src.weights.empty()) {
                if (src.mesh < 0) {
                    fail(where, "has weights but no mesh");
                }
                if (src.weights.size() != node.morphWeights.size()) {
                    fail(where, "weights has " + std::to_string(src.weights.size()) + " numbers for the " +
                                    std::to_string(node.morphWeights.size()) + " morph targets of mesh " +
                                    std::to_string(src.mesh));
                }
                for (size_t t = 0; t < src.weights.size(); ++t) {
                    node.morphWeights[t] = finiteNumber(src.weights[t], where, "weights");
                }
            }
            if (src.skin < -1 || src.skin >= int(model_.skins.size())) {
                fail(where, "skin " + std::to_string(src.skin) + " out of range (" +
                                std::to_string(model_.skins.size()) + " skins)");
            }
            if (src.camera < -1 || src.camera >= int(model_.cameras.size())) {
                fail(where, "camera " + std::to_string(src.camera) + " out of range");
            }
        }
        for (size_t i = 0; i < model_.nodes.size(); ++i) {
            for (int child : model_.nodes[i].children) {
                const std::string where = element("node", i, model_.nodes[i].name);
                if (child < 0 || size_t(child) >= model_.nodes.size()) {
                    fail(where, "child " + std::to_string(child) + " out of range (" +
                                    std::to_string(model_.nodes.size()) + " nodes)");
                }
                if (size_t(child) == i) {
                    fail(where, "is its own child");
                }
                Node& c = scene_.nodes[size_t(child)];
                if (c.parent != kNone) {
                    fail(element("node", size_t(child), c.name),
                         "has two parents (nodes " + std::to_string(c.parent) + " and " + std::to_string(i) + ")");
                }
                c.parent = int32_t(i);
            }
        }
        for (size_t i = 0; i < scene_.nodes.size(); ++i) {
            int32_t p = scene_.nodes[i].parent;
            for (size_t steps = 0; p != kNone; ++steps) {
                if (steps > scene_.nodes.size()) {
                    fail(element("node", i, scene_.nodes[i].name), "is its own ancestor (the hierarchy has a cycle)");
                }
                p = scene_.nodes[size_t(p)].parent;
            }
        }
    }

    // ----- skins ---------------------------------------------------------------

    void convertSkins() {
        for (size_t s = 0; s < model_.skins.size(); ++s) {
            const tinygltf::Skin& src = model_.skins[s];
            const std::string where = element("skin", s, src.name);
            Skin skin;
            skin.name = src.name;
            if (src.joints.empty()) {
                fail(where, "has no joints");
            }
            for (int j : src.joints) {
                if (j < 0 || size_t(j) >= model_.nodes.size()) {
                    fail(where, "joint node " + std::to_string(j) + " out of range (" +
                                    std::to_string(model_.nodes.size()) + " nodes)");
                }
                skin.joints.push_back(uint32_t(j));
            }
            if (src.inverseBindMatrices == -1) {
                skin.inverseBindMatrices.assign(skin.joints.size(), glm::mat4(1.0f));
            } else {
                const CheckedAccessor c =
                    checkAccessor(src.inverseBindMatrices, where + " inverseBindMatrices", inverseBindRule());
                if (c.count < skin.joints.size()) {
                    fail(c.element,
                         std::to_string(c.count) + " matrices for " + std::to_string(skin.joints.size()) + " joints");
                }
                const std::vector<float> m = readFloats(c);
                for (size_t j = 0; j < skin.joints.size(); ++j) {
                    skin.inverseBindMatrices.push_back(glm::make_mat4(m.data() + 16 * j));
                }
            }
            scene_.skins.push_back(std::move(skin));
        }
    }

    // ----- animations ------------------------------------------------------

    // `weightCount`: morph targets of the animated node's mesh (Weights only).
    AnimationSampler convertSampler(const tinygltf::Animation& anim, int samplerIndex, AnimationPath path,
                                    const std::string& where, size_t weightCount) {
        const tinygltf::AnimationSampler& src = anim.samplers[size_t(samplerIndex)];
        const std::string samplerWhere = where + " sampler " + std::to_string(samplerIndex);
        AnimationSampler out;
        if (src.interpolation == "LINEAR" || src.interpolation.empty()) {
            out.interpolation = Interpolation::Linear;
        } else if (src.interpolation == "STEP") {
            out.interpolation = Interpolation::Step;
        } else if (src.interpolation == "CUBICSPLINE") {
            out.interpolation = Interpolation::CubicSpline;
        } else {
            fail(samplerWhere, "interpolation '" + src.interpolation + "'");
        }
        const CheckedAccessor input = checkAccessor(src.input, samplerWhere + " input", timesRule());
        out.times = readFloats(input);
        for (size_t k = 1; k < out.times.size(); ++k) {
            if (out.times[k] < out.times[k - 1]) {
                fail(input.element, "key times decrease at key " + std::to_string(k));
            }
        }
        const size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
        if (path == AnimationPath::Weights) {
            const CheckedAccessor output = checkAccessor(src.output, samplerWhere + " output", weightsOutputRule());
            if (output.count != input.count * perKey * weightCount) {
                fail(output.element, std::to_string(output.count) + " values for " + std::to_string(input.count) +
                                         " keys of " + std::to_string(weightCount) + " morph target weights" +
                                         (perKey == 3 ? " (CUBICSPLINE needs 3 per key)" : ""));
            }
            out.weights = readFloats(output);
            out.weightCount = uint32_t(weightCount);
            return out;
        }
        const CheckedAccessor output = checkAccessor(src.output, samplerWhere + " output", animationOutputRule(path));
        if (output.count != input.count * perKey) {
            fail(output.element, std::to_string(output.count) + " values for " + std::to_string(input.count) + " keys" +
                                     (perKey == 3 ? " (CUBICSPLINE needs 3 per key)" : ""));
        }
        out.values = toVectors<glm::vec4>(readFloats(output), output.components);
        return out;
    }

    void convertAnimations() {
        for (size_t a = 0; a < model_.animations.size(); ++a) {
            const tinygltf::Animation& src = model_.animations[a];
            const std::string where = element("animation", a, src.name);
            Animation anim;
            anim.name = src.name;
            // glTF samplers -> scene samplers, per path (a sampler's output
            // type follows the path of the channels using it).
            std::map<std::tuple<int, AnimationPath, size_t>, uint32_t> converted;
            for (size_t c = 0; c < src.channels.size(); ++c) {
                const tinygltf::AnimationChannel& ch = src.channels[c];
                const std::string channelWhere = where + " channel " + std::to_string(c);
                if (ch.sampler < 0 || size_t(ch.sampler) >= src.samplers.size()) {
                    fail(channelWhere, "sampler " + std::to_string(ch.sampler) + " out of range (" +
                                           std::to_string(src.samplers.size()) + " samplers)");
                }
                if (ch.target_node == -1) {
                    continue;  // targets something an extension defines
                }
                if (ch.target_node < 0 || size_t(ch.target_node) >= model_.nodes.size()) {
                    fail(channelWhere, "target node " + std::to_string(ch.target_node) + " out of range (" +
                                           std::to_string(model_.nodes.size()) + " nodes)");
                }
                AnimationPath path;
                if (ch.target_path == "translation") {
                    path = AnimationPath::Translation;
                } else if (ch.target_path == "rotation") {
                    path = AnimationPath::Rotation;
                } else if (ch.target_path == "scale") {
                    path = AnimationPath::Scale;
                } else if (ch.target_path == "weights") {
                    path = AnimationPath::Weights;
                } else {
                    fail(channelWhere, "target path '" + ch.target_path + "'");
                }
                const size_t weightCount = scene_.nodes[size_t(ch.target_node)].morphWeights.size();
                if (path == AnimationPath::Weights && weightCount == 0) {
                    fail(channelWhere, "animates the weights of node " + std::to_string(ch.target_node) +
                                           ", whose mesh has no morph targets");
                }
                if (path != AnimationPath::Weights && scene_.nodes[size_t(ch.target_node)].matrix) {
                    fail(channelWhere, "targets node " + std::to_string(ch.target_node) +
                                           ", which has a matrix (glTF allows animating TRS nodes only)");
                }
                const size_t keyWeights = path == AnimationPath::Weights ? weightCount : 0;
                const auto key = std::make_tuple(ch.sampler, path, keyWeights);
                auto it = converted.find(key);
                if (it == converted.end()) {
                    it = converted.emplace(key, uint32_t(anim.samplers.size())).first;
                    anim.samplers.push_back(convertSampler(src, ch.sampler, path, where, keyWeights));
                }
                anim.channels.push_back({it->second, uint32_t(ch.target_node), path});
                (path == AnimationPath::Weights ? morphedNodes_ : animatedNodes_).insert(uint32_t(ch.target_node));
            }
            scene_.animations.push_back(std::move(anim));
        }
        if (!scene_.animations.empty()) {
            scene_.playbacks.push_back({0, 1.0f, true});
        }
    }

    // ----- the active scene ------------------------------------------------

    bool animatedOrBelowAnimated(uint32_t node) const {
        for (int32_t n = int32_t(node); n != kNone; n = scene_.nodes[size_t(n)].parent) {
            if (animatedNodes_.count(uint32_t(n))) {
                return true;
            }
        }
        return false;
    }

    void instantiate() {
        std::vector<uint32_t> roots;
        if (model_.scenes.empty()) {
            for (size_t n = 0; n < scene_.nodes.size(); ++n) {
                if (scene_.nodes[n].parent == kNone) {
                    roots.push_back(uint32_t(n));
                }
            }
        } else {
            const int index = model_.defaultScene == -1 ? 0 : model_.defaultScene;
            if (index < 0 || size_t(index) >= model_.scenes.size()) {
                fail("scene", "default scene " + std::to_string(index) + " out of range (" +
                                  std::to_string(model_.scenes.size()) + " scenes)");
            }
            const std::string where = element("scene", size_t(index), model_.scenes[size_t(index)].name);
            std::set<int> seen;
            for (int n : model_.scenes[size_t(index)].nodes) {
                if (n < 0 || size_t(n) >= scene_.nodes.size()) {
                    fail(where, "node " + std::to_string(n) + " out of range (" + std::to_string(scene_.nodes.size()) +
                                    " nodes)");
                }
                if (scene_.nodes[size_t(n)].parent != kNone) {
                    fail(where, "node " + std::to_string(n) + " is not a root (its parent is node " +
                                    std::to_string(scene_.nodes[size_t(n)].parent) + ")");
                }
                if (!seen.insert(n).second) {
                    fail(where, "lists node " + std::to_string(n) + " twice");
                }
                roots.push_back(uint32_t(n));
            }
        }
        std::vector<std::vector<uint32_t>> children(scene_.nodes.size());
        for (size_t n = 0; n < scene_.nodes.size(); ++n) {
            if (scene_.nodes[n].parent != kNone) {
                children[size_t(scene_.nodes[n].parent)].push_back(uint32_t(n));
            }
        }
        const std::vector<glm::mat4> world = worldTransforms(scene_.nodes);
        bool warnedLights = false;
        // Depth-first in document order, iteratively (no recursion on
        // untrusted depth).
        std::vector<uint32_t> stack(roots.rbegin(), roots.rend());
        while (!stack.empty()) {
            const uint32_t n = stack.back();
            stack.pop_back();
            const std::vector<uint32_t>& kids = children[n];
            stack.insert(stack.end(), kids.rbegin(), kids.rend());
            const tinygltf::Node& src = model_.nodes[n];
            instantiateNode(n, src, world[n]);
            lightFromNode(n, src, world[n], warnedLights);
            cameraFromNode(src, world[n]);
        }
    }

    void instantiateNode(uint32_t n, const tinygltf::Node& src, const glm::mat4& world) {
        if (src.mesh < 0) {
            return;
        }
        Instance inst;
        inst.name = src.name.empty() ? scene_.meshes[size_t(src.mesh)].name : src.name;
        inst.mesh = uint32_t(src.mesh);
        inst.node = int32_t(n);
        inst.transform = inst.previousTransform = world;
        // Morph weights deform the mesh: animated or not zero, the instance
        // gets a BLAS of its own with its shape (a shared static BLAS holds
        // the base shape), rebuilt when they change (deformVersion).
        inst.morphWeights = scene_.nodes[n].morphWeights;
        const bool morphed = morphedNodes_.count(n) != 0 ||
                             std::any_of(inst.morphWeights.begin(), inst.morphWeights.end(),
                                         [](float w) { return w != 0.0f; });
        inst.motion = animatedOrBelowAnimated(n) || morphed ? Motion::Dynamic : Motion::Static;
        if (src.skin >= 0) {
            const std::string where = element("node", n, src.name);
            const size_t joints = scene_.skins[size_t(src.skin)].joints.size();
            const Mesh& mesh = scene_.meshes[size_t(src.mesh)];
            bool skinnable = !mesh.lods[0].geometries.empty();
            for (const Geometry& g : mesh.lods[0].geometries) {
                skinnable = skinnable && g.skinned();
                for (size_t v = 0; v < g.joints.size(); ++v) {
                    const glm::u16vec4 j = g.joints[v];
                    if (std::max({j.x, j.y, j.z, j.w}) >= joints) {
                        fail(where, "mesh " + std::to_string(src.mesh) + " vertex " + std::to_string(v) +
                                        " uses joint " + std::to_string(std::max({j.x, j.y, j.z, j.w})) + " but skin " +
                                        std::to_string(src.skin) + " has " + std::to_string(joints) + " joints");
                    }
                }
            }
            if (skinnable) {
                inst.motion = Motion::Skinned;
                inst.skin = src.skin;
            } else {
                warn(where, "has a skin but its mesh has no JOINTS_0/WEIGHTS_0; drawn rigid");
            }
        }
        scene_.instances.push_back(std::move(inst));
    }

    void lightFromNode(uint32_t n, const tinygltf::Node& src, const glm::mat4& world, bool& warnedLights) {
        const auto ext = src.extensions.find("KHR_lights_punctual");
        if (ext == src.extensions.end() || !ext->second.Get("light").IsNumber()) {
            return;
        }
        const double index = ext->second.Get("light").GetNumberAsDouble();
        const std::string where = element("node", n, src.name);
        if (!(index >= 0.0 && index < double(model_.lights.size())) || index != std::floor(index)) {
            fail(where, "KHR_lights_punctual light " + std::to_string(index) + " out of range (" +
                            std::to_string(model_.lights.size()) + " lights)");
        }
        const size_t light = size_t(index);
        const tinygltf::Light& l = model_.lights[light];
        if (l.type != "directional") {
            if (!warnedLights) {
                spdlog::info("{}: point and spot lights are not used (only a directional sun)", context_.file);
                warnedLights = true;
            }
            return;
        }
        if (sunFound_) {
            return;
        }
        const std::string lightWhere = element("light", light, l.name);
        // KHR_lights_punctual: a directional light shines along its node's -Z.
        const glm::vec3 shines = glm::vec3(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
        if (!(glm::length(shines) > 0.0f)) {
            fail(where, "the light's node transform is degenerate");
        }
        scene_.sun.directionToLight = -glm::normalize(shines);
        scene_.sun.color = factor<3>(l.color, glm::vec3(1.0f), lightWhere, "color");
        scene_.sun.illuminance = finiteNumber(l.intensity, lightWhere, "intensity");  // lux for directional lights
        sunFound_ = true;
    }

    // Every usable perspective camera becomes a named view; the first is
    // also the scene's suggested view.
    void cameraFromNode(const tinygltf::Node& src, const glm::mat4& world) {
        if (src.camera < 0 || model_.cameras[size_t(src.camera)].type != "perspective") {
            return;
        }
        const tinygltf::Camera& camera = model_.cameras[size_t(src.camera)];
        const tinygltf::PerspectiveCamera& p = camera.perspective;
        constexpr double kLargest = 1e30;  // keeps the float conversions defined
        if (!(p.yfov > 0.0 && p.yfov < 3.1) || !(p.znear > 0.0 && p.znear < kLargest) ||
            !(p.zfar >= 0.0 && p.zfar < kLargest)) {
            return;  // unusable; the loader frames the scene instead
        }
        const glm::vec3 position(world[3]);
        const glm::vec3 forward = -glm::vec3(world[2]);
        if (!(glm::length(forward) > 0.0f) || !std::isfinite(position.x + position.y + position.z)) {
            return;
        }
        SceneView view;
        view.name = !camera.name.empty() ? camera.name
                    : !src.name.empty()  ? src.name
                                         : "camera " + std::to_string(scene_.views.size());
        view.lens.verticalFovRadians = float(p.yfov);
        view.lens.nearPlane = float(p.znear);
        view.lens.farPlane = p.zfar > p.znear ? float(p.zfar) : kInfiniteFar;
        view.position = position;
        view.target = position + glm::normalize(forward);
        scene_.views.push_back(view);
        if (!cameraFound_) {
            useView(scene_, view);
            cameraFound_ = true;
        }
    }

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

} // namespace

Scene convertModel(const tinygltf::Model& model, LoadContext& context) {
    return Converter(model, context).run();
}

} // namespace glint::scene::gltf
