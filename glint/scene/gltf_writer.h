#pragma once
// Writes a scene as glTF 2.0 for inspection in other tools (Blender, the
// Khronos sample viewer): LOD 0 of every mesh with positions, normals,
// texture coordinates and indices; materials with their factors (textures
// are not written); one node per instance with its current transform
// (skinned instances in bind pose); the sun as a KHR_lights_punctual
// directional light.

#include "glint/scene/scene.h"

#include <filesystem>

namespace glint::scene {

// Writes `gltfPath` and, next to it, the binary buffer `<stem>.bin`.
// Throws SceneError when a file cannot be written.
void writeGltf(const Scene& scene, const std::filesystem::path& gltfPath);

} // namespace glint::scene
