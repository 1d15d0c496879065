// glTF textures and materials -> scene textures and materials: images
// decoded on first use (a missing or undecodable one falls back to the
// material's factors with a warning), samplers, KHR_texture_transform,
// KHR_materials_emissive_strength and KHR_materials_ior. Members of the
// Converter (gltf_converter.h).

#include "glint/scene/gltf_converter.h"

#include "glint/scene/image_io.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace glint::scene::gltf {

// Scene texture of glTF image `index`, decoded on first use; kNone with
// one warning when the image is missing or cannot be decoded.
int32_t Converter::imageTexture(int index) {
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

Wrap Converter::wrapMode(int gl) {
    switch (gl) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
    default: return Wrap::Repeat;
    }
}

// A number of a KHR_texture_transform member, or `fallback` if absent.
glm::vec2 Converter::transformPair(const tinygltf::Value& ext, const char* key, glm::vec2 fallback,
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
template <typename Info> TextureRef Converter::textureRef(const Info& info, const std::string& where) {
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

void Converter::convertMaterials() {
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

uint32_t Converter::defaultMaterial() {
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

} // namespace glint::scene::gltf
