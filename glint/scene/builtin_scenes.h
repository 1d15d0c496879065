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
//  "city": a wet street grid between blocks of instanced, finely
//   tessellated buildings of six kinds (recessed windows, dark and mirror
//   glass, shopfronts with lit signs), street lamps and traffic; a camera
//   path down the main street whose puddles mirror the facades ahead
//   (on screen: SSLR can) while the windows mirror what is behind and
//   beside the camera (only RT can). "city:instances=N,triangles=T,seed=S"
//   sets its size (CityOptions); streets, lamps and cars grow with it.
//
//  "mirror-motion": a bright lamp sliding across a wet floor (glossy metal,
//   roughness 0.1: traced, and noisy enough for the temporal pass's clamp
//   to be loose) in front of a wall, then the camera strafing past it
//   (kMirrorMotion's timeline):
//   what reflections in motion are measured on (ghosting behind a moving
//   object, lag under camera motion; glint-bench --motion).
//
//  "hard-cases": everything offset to about 10^4 m from the origin; a
//   grazing mirror corridor, walls 2 mm thick and zero thick, roughness 0
//   and 1, degenerate triangles, a 1 cm object 3 cm from the camera and a
//   wall 9 km away, seen through near 0.01 and an infinite far plane.

#include "glint/scene/gltf_loader.h"
#include "glint/scene/scene.h"

#include <cstdint>
#include <span>
#include <string_view>

namespace glint::scene {

inline constexpr std::string_view kDefaultSceneName = "plaza";

// The city's size. `instances` buildings in rows along streets (the main
// street first, both sides, then streets to either side); each of the six
// kinds tessellated so that its LOD 0 has at most about `triangles`
// triangles, or its coarsest tessellation (one quad per wall panel: 2,000
// to 14,000 triangles by kind) where that is more (LOD 1, the reflection
// BLAS's, has half the subdivision: about a quarter); `seed` picks
// the kind of each plot and the traffic's phases.
inline constexpr uint32_t kCityMinInstances = 16;
inline constexpr uint32_t kCityMaxInstances = 4096;
inline constexpr uint32_t kCityMinTriangles = 1000;
inline constexpr uint32_t kCityMaxTriangles = 1000000;
struct CityOptions {
    // About 2.0 million instanced triangles: seconds a frame on lavapipe at
    // 128x72, a large scene for the H200 (instances=1024 gives about 32M,
    // 4096 about 130M).
    uint32_t instances = 64;
    uint32_t triangles = 40000;
    uint32_t seed = 1;
};
// "city" or "city:KEY=VALUE,..." with keys instances, triangles, seed;
// throws SceneError naming the key for anything else or out of range.
CityOptions parseCityOptions(std::string_view spec);

// The mirror-motion scene's timeline (seconds, metres): the lamp stands
// at objectStartX until objectStartSeconds, slides along +x at objectSpeed
// until objectStopSeconds and stands again; the camera stands until
// cameraStartSeconds, then strafes along +x at cameraSpeed.
struct MirrorMotionTimeline {
    float objectStartSeconds = 2.0f;
    float objectStopSeconds = 3.0f;
    float objectStartX = -1.5f;
    float objectSpeed = 2.0f;
    float objectHeight = 0.5f;
    float objectZ = 0.0f;
    float cameraStartSeconds = 3.0f;
    float cameraSpeed = 1.5f;
    float loopSeconds = 10.0f;  // the lamp's animation loops after this
};
inline constexpr MirrorMotionTimeline kMirrorMotion{};

std::span<const std::string_view> builtinSceneNames();
// A built-in name, or "city:..." with the city's options.
bool isBuiltinScene(std::string_view name);

// Built and prepared (prepareScene). Throws SceneError for unknown names
// and bad city options.
Scene makeBuiltinScene(std::string_view name);
Scene makePlaza();
Scene makeHardCases();
Scene makeCity(const CityOptions& options = {});
// How the mirror-motion lamp slides: its instance's transform (Rigid), or
// with the instance standing, its one joint (Skinned) or its one morph
// target's weight (Morphed); the same path each way.
enum class MirrorMotionLamp : uint8_t { Rigid, Skinned, Morphed };
// "mirror-motion" (Rigid) or "mirror-motion:lamp=rigid|skinned|morphed";
// throws SceneError naming the option for anything else.
MirrorMotionLamp parseMirrorMotionLamp(std::string_view spec);
// withObject false: the same scene without the lamp (where its reflection
// should be is where the two differ).
Scene makeMirrorMotion(bool withObject = true, MirrorMotionLamp lamp = MirrorMotionLamp::Rigid);

// A built-in scene by name, otherwise a glTF file by path.
Scene loadScene(std::string_view nameOrPath, const GltfLoadOptions& options = {});

} // namespace glint::scene
