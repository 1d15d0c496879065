#pragma once
// glTF 2.0 (.gltf with embedded or external buffers and images, and .glb)
// into the scene model, through tinygltf.
//
// Every index, offset, count, stride and type is checked before any data is
// read, and every size before memory is allocated: a broken file gives a
// SceneError naming the file and the element ("accessor 3 (mesh 'Body'
// primitive 0 POSITION): ..."), never a crash, an out-of-bounds read or an
// unbounded allocation. A missing or undecodable texture is not an error:
// the material keeps its flat factors and the loader warns once per image.
//
// Supported extensions: KHR_materials_emissive_strength,
// KHR_lights_punctual (the first directional light becomes the sun),
// KHR_materials_ior (as reflectance), KHR_mesh_quantization,
// KHR_texture_transform (per texture reference: offset, rotation, scale,
// texCoord). Others are ignored with one log line each, unless the file
// requires them.
//
// Texture coordinate sets TEXCOORD_0 and TEXCOORD_1 are loaded; a texture
// reference to a higher set is dropped with a warning naming the material.
// Missing TANGENTs are generated (mesh_tools.h, generateTangents). Morph
// targets (POSITION, NORMAL, TANGENT) are loaded with the mesh's default
// weights, node weights and animated `weights` channels; instances with
// animated or non-zero weights are Motion::Dynamic, and the CPU applies the
// weights (animation.h, morphedGeometry) for the G-buffer's and the BVH's
// vertex data.

#include "glint/scene/reflection_lod.h"
#include "glint/scene/scene.h"

#include <cstdint>
#include <filesystem>
#include <optional>

namespace glint::scene {

struct GltfLoadOptions {
    // The .gltf/.glb file and each external buffer or image. tinygltf takes
    // GLB sizes as 32-bit, so this must stay below 4 GiB.
    uint64_t maxFileBytes = 1ull << 30;
    // Geometry and textures after decoding, all together. Accessors may be
    // shared by many meshes, so this is not bounded by the file size alone.
    uint64_t maxDecodedBytes = 2ull << 30;
    uint32_t maxImageDimension = 16384;
    // Deeper JSON is refused before parsing (parsers recurse on nesting).
    uint32_t maxJsonDepth = 64;
    // false: skip image decoding; materials keep their factors only.
    bool loadTextures = true;
    // A reflection LOD for every mesh (glTF gives one level of detail),
    // which the BVH builds from (scene/reflection_lod.h); unset: the BVH
    // builds from full detail.
    std::optional<ReflectionLodSettings> reflectionLods = ReflectionLodSettings{};
};

// Loads `path` (.gltf or .glb, recognised by content), prepares the scene
// (prepareScene) and gives it a camera that frames it, or the file's first
// perspective camera. Throws SceneError.
Scene loadGltf(const std::filesystem::path& path, const GltfLoadOptions& options = {});

// The extensions loadGltf understands.
bool isSupportedGltfExtension(std::string_view name);

} // namespace glint::scene
