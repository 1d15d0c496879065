#pragma once
// Scenes built in code, so the demo, the benchmarks and the tests need no
// files:
//
//  "plaza" (the default): a wet tropical plaza beside a street. Puddles of
//   near-mirror floor (a generated puddle mask drives roughness) next to
//   rough asphalt, rough plaster and smooth tiled walls, metal and
//   dielectric props, rigidly animated objects (a car, a fan, a sign, a
//   lantern), skinned ones (palms and flags in the wind, two walkers), a
//   first-person arm holding a lantern, and buildings and hills both near
//   the camera and beyond 100 m, so the BVH radius and the long-range group
//   matter. A 20-second camera path walks through it.
//
//  "hard-cases": everything offset to about 10^4 m from the origin; a
//   grazing mirror corridor, walls 2 mm thick and zero thick, roughness 0
//   and 1, degenerate triangles, a 1 cm object 3 cm from the camera and a
//   wall 9 km away, seen through near 0.01 and an infinite far plane.

#include "scene/gltf_loader.h"
#include "scene/scene.h"

#include <span>
#include <string_view>

namespace glint::scene {

inline constexpr std::string_view kDefaultSceneName = "plaza";

std::span<const std::string_view> builtinSceneNames();
bool isBuiltinScene(std::string_view name);

// Built and prepared (prepareScene). Throws SceneError for unknown names.
Scene makeBuiltinScene(std::string_view name);
Scene makePlaza();
Scene makeHardCases();

// A built-in scene by name, otherwise a glTF file by path.
Scene loadScene(std::string_view nameOrPath, const GltfLoadOptions& options = {});

} // namespace glint::scene
