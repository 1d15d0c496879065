// glTF accessors: each checked against its bufferView and buffer (offset,
// count, stride, component type, element type, sparse substitution) and
// against what its semantic accepts before anything is read; then read as
// floats or unsigned integers. Members of the Converter (gltf_converter.h).

#include "glint/scene/gltf_converter.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace glint::scene::gltf {

namespace {

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

// Upper bound on elements of one accessor; indices are 32-bit.
constexpr size_t kMaxAccessorCount = size_t(1) << 31;

} // namespace

CheckedAccessor Converter::checkAccessor(int index, const std::string& context, const AccessorRule& rule) const {
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

Converter::ViewRange Converter::checkBufferView(int index, const std::string& where) const {
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

void Converter::checkSparse(const tinygltf::Accessor& a, CheckedAccessor& c) const {
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
std::vector<T> Converter::readComponents(const CheckedAccessor& c, Convert convert) const {
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
std::vector<float> Converter::readFloats(const CheckedAccessor& c) const {
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

std::vector<uint32_t> Converter::readUints(const CheckedAccessor& c) const {
    const tinygltf::Accessor& a = *c.accessor;
    return readComponents<uint32_t>(c, [&](const uint8_t* src) { return componentAsUint(src, a.componentType); });
}

} // namespace glint::scene::gltf
