#include "glint/scene/builtin_scenes.h"

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/foliage.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/procedural_meshes.h"
#include "glint/scene/scene_builder.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <cmath>
#include <functional>

namespace glint::scene {

namespace {

struct PavingTextures {
    Texture baseColor;
    Texture metallicRoughness;
};

// Wet paving: 4 x 4 stone tiles per texture with grout, and puddles (where
// an fBm mask crosses a threshold) that are darker and nearly mirror-smooth.
// Wet surfaces darken because water fills the pores (Lagarde, "Water drop
// 2b - Dynamic rain and its effects", 2013); their roughness drops to that
// of the water film.
PavingTextures makePavingTextures(uint32_t size) {
    PavingTextures t;
    t.baseColor = {"paving_base_color", size, size, TextureFormat::Rgba8, {}, {}};
    t.metallicRoughness = {"paving_metallic_roughness", size, size, TextureFormat::Rgba8, {}, {}};
    t.baseColor.rgba8.resize(size_t(size) * size * 4);
    t.metallicRoughness.rgba8.resize(size_t(size) * size * 4);
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            const float u = (float(x) + 0.5f) / float(size);
            const float v = (float(y) + 0.5f) / float(size);
            const float tileU = u * 4.0f, tileV = v * 4.0f;
            const float gu = tileU - std::floor(tileU), gv = tileV - std::floor(tileV);
            const bool grout = gu < 0.03f || gu > 0.97f || gv < 0.03f || gv > 0.97f;
            const float tint = 0.85f + 0.3f * hash01(int32_t(tileU), int32_t(tileV), 7u);
            const float puddle = glm::smoothstep(0.56f, 0.6f, fbm(u, v, 11u));
            const float grain = 0.9f + 0.2f * valueNoise(u * 64.0f, v * 64.0f, 64, 3u);
            glm::vec3 albedo = glm::vec3(0.30f, 0.27f, 0.24f) * tint * grain;
            if (grout) {
                albedo *= 0.45f;
            }
            albedo *= 1.0f - 0.55f * puddle;
            float roughness = grout ? 0.85f : 0.55f + 0.15f * grain - 0.1f;
            roughness = glm::mix(roughness, 0.02f, puddle);
            const size_t i = (size_t(y) * size + x) * 4;
            t.baseColor.rgba8[i + 0] = toSrgbByte(albedo.r);
            t.baseColor.rgba8[i + 1] = toSrgbByte(albedo.g);
            t.baseColor.rgba8[i + 2] = toSrgbByte(albedo.b);
            t.baseColor.rgba8[i + 3] = 255;
            t.metallicRoughness.rgba8[i + 0] = 255;  // unused (occlusion lives in R when packed)
            t.metallicRoughness.rgba8[i + 1] = toByte(roughness);
            t.metallicRoughness.rgba8[i + 2] = 0;  // dielectric
            t.metallicRoughness.rgba8[i + 3] = 255;
        }
    }
    return t;
}


// ---------------------------------------------------------------------------
// Plaza
// ---------------------------------------------------------------------------

// Hills around the town, rising with distance (plaza coordinates, metres).
float hillHeight(float x, float z) {
    const float r = std::sqrt(x * x + z * z);
    const float rise = std::clamp((r - 150.0f) / 300.0f, 0.0f, 1.0f) * 70.0f;
    return rise + 12.0f * std::sin(x * 0.021f) * std::cos(z * 0.017f) + 6.0f * std::sin((x + z) * 0.043f) - 2.0f;
}

struct PlazaMaterials {
    uint32_t paving, asphalt, plaster, plasterBlue, tiles, glass, shelterGlass, chrome, copper, redPlastic, wood, trunk, neon,
        carPaint, tyre, flag, cloth, hills, tower, mirrorTower, water, brass, lampGlow, skinTone;
};

PlazaMaterials plazaMaterials(SceneBuilder& b) {
    PlazaMaterials m{};
    const PavingTextures paving = makePavingTextures(256);
    Material wet = makeMaterial("wet paving", glm::vec3(1.0f), 1.0f, 1.0f);
    wet.baseColorTexture.texture = b.texture(paving.baseColor);
    wet.metallicRoughnessTexture.texture = b.texture(paving.metallicRoughness);
    m.paving = b.material(wet);
    m.asphalt = b.material(makeMaterial("asphalt", {0.06f, 0.06f, 0.065f}, 0.0f, 0.85f));
    m.plaster = b.material(makeMaterial("ochre plaster", {0.72f, 0.55f, 0.36f}, 0.0f, 0.9f));
    m.plasterBlue = b.material(makeMaterial("blue plaster", {0.25f, 0.42f, 0.55f}, 0.0f, 0.85f));
    m.tiles = b.material(makeMaterial("glazed tiles", {0.08f, 0.32f, 0.36f}, 0.0f, 0.12f));
    m.glass = b.material(makeMaterial("window glass", {0.02f, 0.025f, 0.03f}, 0.0f, 0.03f));
    m.chrome = b.material(makeMaterial("chrome", {0.95f, 0.93f, 0.88f}, 1.0f, 0.05f));
    // Blended (glTF alphaMode BLEND, passes/transparent.h): a third of the
    // light is stopped and tinted; seen from both sides.
    Material shelterGlass = makeMaterial("shelter glass", {0.55f, 0.72f, 0.68f}, 0.0f, 0.05f);
    shelterGlass.baseColorFactor.a = 0.35f;
    shelterGlass.alphaMode = AlphaMode::Blend;
    shelterGlass.doubleSided = true;
    m.shelterGlass = b.material(shelterGlass);
    m.copper = b.material(makeMaterial("brushed copper", {0.95f, 0.64f, 0.54f}, 1.0f, 0.3f));
    m.redPlastic = b.material(makeMaterial("red plastic", {0.7f, 0.05f, 0.04f}, 0.0f, 0.35f));
    m.wood = b.material(makeMaterial("bench wood", {0.35f, 0.2f, 0.1f}, 0.0f, 0.7f));
    m.trunk = b.material(makeMaterial("palm trunk", {0.3f, 0.22f, 0.15f}, 0.0f, 0.9f));
    // Emission is in lit units at LightingSettings::emissiveScale 1, where
    // a sunlit white wall is ~2.5 and the default exposure's tonemap (PBR
    // Neutral) whitens a peak of 4 by a third: a neon tube (~10^4 nits,
    // dimmer than that wall in daylight) at 2.5 stays pink; at the 40 it
    // had before anything emitted, it rendered as a white bar.
    m.neon = b.material(makeEmissive("neon", {1.0f, 0.15f, 0.55f}, 2.5f));
    m.carPaint = b.material(makeMaterial("car paint", {0.04f, 0.09f, 0.45f}, 0.3f, 0.12f));
    m.tyre = b.material(makeMaterial("tyre rubber", {0.03f, 0.03f, 0.03f}, 0.0f, 0.8f));
    Material flag = makeMaterial("flag cloth", {0.85f, 0.7f, 0.08f}, 0.0f, 0.8f);
    flag.doubleSided = true;
    m.flag = b.material(flag);
    m.cloth = b.material(makeMaterial("clothes", {0.15f, 0.3f, 0.2f}, 0.0f, 0.75f));
    m.hills = b.material(makeMaterial("jungle hills", {0.06f, 0.16f, 0.05f}, 0.0f, 0.95f));
    m.tower = b.material(makeMaterial("concrete", {0.45f, 0.45f, 0.47f}, 0.0f, 0.8f));
    m.mirrorTower = b.material(makeMaterial("tower glass", {0.7f, 0.75f, 0.8f}, 1.0f, 0.04f));
    m.water = b.material(makeMaterial("fountain water", {0.02f, 0.03f, 0.035f}, 0.0f, 0.0f));
    m.brass = b.material(makeMaterial("brass", {0.9f, 0.72f, 0.35f}, 1.0f, 0.25f));
    // A bulb outshines a sunlit wall, but at 25 it burnt to pure white; 5
    // keeps a warm glow.
    m.lampGlow = b.material(makeEmissive("lamp glow", {1.0f, 0.75f, 0.45f}, 5.0f));
    m.skinTone = b.material(makeMaterial("skin", {0.6f, 0.42f, 0.32f}, 0.0f, 0.55f));
    return m;
}

// A building: plaster body, a tiled ground-floor band and glass windows on
// the side facing +Z (rotate the instance to face the plaza).
std::vector<Geometry> buildingGeometry(const glm::vec3& size, uint32_t wall, uint32_t band, uint32_t glass) {
    std::vector<Geometry> parts;
    parts.push_back(transformed(makeBox(size, wall, 0.5f), translation({0.0f, size.y * 0.5f, 0.0f})));
    parts.push_back(transformed(makeBox({size.x + 0.1f, 1.2f, size.z + 0.1f}, band, 1.0f), translation({0, 0.6f, 0})));
    Geometry windows;
    windows.material = glass;
    const int columns = std::max(1, int(size.x / 2.5f));
    for (int floor = 1; floor < int(size.y / 3.0f); ++floor) {
        for (int c = 0; c < columns; ++c) {
            const float x = -0.5f * size.x + (float(c) + 0.5f) * size.x / float(columns);
            appendGeometry(windows, transformed(makeBox({1.2f, 1.6f, 0.08f}, glass),
                                                translation({x, float(floor) * 3.0f + 0.8f, 0.5f * size.z + 0.02f})));
        }
    }
    parts.push_back(std::move(windows));
    return parts;
}

Scene buildPlaza() {
    SceneBuilder b("plaza");
    const PlazaMaterials mat = plazaMaterials(b);
    const FoliageMaterials foliage = foliageMaterials(b, 128);
    Scene& s = b.scene;

    // --- Ground: the puddled plaza (mirror-like where wet) beside a rough street.
    const uint32_t floorMesh = b.mesh("plaza floor", {{makeGrid({40, 40}, {80, 80}, mat.paving, 0.25f)},
                                                      {makeGrid({40, 40}, {20, 20}, mat.paving, 0.25f)}});
    b.place("plaza floor", floorMesh, {0, 0, 0});
    const uint32_t streetMesh =
        b.mesh("street", {{makeGrid({12, 80}, {12, 80}, mat.asphalt)}, {makeGrid({12, 80}, {3, 20}, mat.asphalt)}});
    b.place("street", streetMesh, {26, 0.0f, 0});
    const uint32_t kerbMesh = b.mesh("kerb", {{makeBox({0.3f, 0.15f, 80.0f}, mat.tiles)}});
    b.place("kerb", kerbMesh, {20.1f, 0.075f, 0});

    // --- Buildings around the plaza, close enough to fill reflections.
    const uint32_t buildingA =
        b.mesh("building A", {buildingGeometry({10.0f, 12.0f, 8.0f}, mat.plaster, mat.tiles, mat.glass)});
    const uint32_t buildingB =
        b.mesh("building B", {buildingGeometry({8.0f, 9.0f, 8.0f}, mat.plasterBlue, mat.tiles, mat.glass)});
    const glm::quat facePlusX = axisAngle({0, 1, 0}, glm::half_pi<float>());
    const glm::quat faceMinusZ = axisAngle({0, 1, 0}, glm::pi<float>());
    b.place("west building 1", buildingA, {-25.0f, 0, -12.0f}, facePlusX);
    b.place("west building 2", buildingB, {-25.0f, 0, 0.0f}, facePlusX);
    b.place("west building 3", buildingA, {-25.0f, 0, 12.0f}, facePlusX);
    b.place("north building 1", buildingB, {-12.0f, 0, -25.0f});
    b.place("north building 2", buildingA, {0.0f, 0, -25.0f});
    b.place("north building 3", buildingB, {12.0f, 0, -25.0f});
    b.place("east building 1", buildingA, {40.0f, 0, -15.0f}, axisAngle({0, 1, 0}, -glm::half_pi<float>()));
    b.place("east building 2", buildingB, {40.0f, 0, 10.0f}, axisAngle({0, 1, 0}, -glm::half_pi<float>()));
    b.place("south building", buildingA, {-8.0f, 0, 28.0f}, faceMinusZ);

    // A cafe awning with a ceiling fan.
    const uint32_t awning =
        b.mesh("awning", {{transformed(makeBox({6.0f, 0.15f, 3.0f}, mat.redPlastic), translation({0, 3.6f, 0})),
                           transformed(makeCylinder(0.06f, 3.6f, 12, mat.chrome), translation({-2.9f, 0, 1.4f})),
                           transformed(makeCylinder(0.06f, 3.6f, 12, mat.chrome), translation({2.9f, 0, 1.4f}))}});
    b.place("awning", awning, {-18.5f, 0, 6.0f}, facePlusX);

    // --- Props: metal and dielectric, some near the camera path.
    const uint32_t chromeSphere =
        b.mesh("chrome sphere", {{makeSphere(1.0f, 48, 24, mat.chrome)}, {makeSphere(1.0f, 16, 8, mat.chrome)}});
    b.place("chrome sphere", chromeSphere, {-5.0f, 1.0f, -3.0f});
    const uint32_t redSphere =
        b.mesh("red sphere", {{makeSphere(0.5f, 32, 16, mat.redPlastic)}, {makeSphere(0.5f, 12, 6, mat.redPlastic)}});
    b.place("red sphere 1", redSphere, {-2.0f, 0.5f, 4.0f});
    b.place("red sphere 2", redSphere, {3.5f, 0.5f, 6.5f});
    b.place("red sphere 3", redSphere, {-8.0f, 0.5f, 9.0f});
    const uint32_t pillar = b.mesh(
        "copper pillar", {{makeCylinder(0.4f, 4.0f, 32, mat.copper)}, {makeCylinder(0.4f, 4.0f, 10, mat.copper)}});
    for (int i = 0; i < 4; ++i) {
        b.place("copper pillar " + std::to_string(i), pillar, {-12.0f + 8.0f * float(i), 0, -14.0f});
    }
    const uint32_t bench =
        b.mesh("bench", {{makeBox({2.0f, 0.08f, 0.5f}, mat.wood),
                          transformed(makeBox({0.08f, 0.45f, 0.45f}, mat.chrome), translation({-0.9f, -0.25f, 0})),
                          transformed(makeBox({0.08f, 0.45f, 0.45f}, mat.chrome), translation({0.9f, -0.25f, 0}))}});
    b.place("bench 1", bench, {2.0f, 0.5f, 12.0f});
    b.place("bench 2", bench, {-6.0f, 0.5f, 14.0f}, axisAngle({0, 1, 0}, 0.4f));
    b.place("bench 3", bench, {12.0f, 0.5f, 2.0f}, facePlusX);
    b.place("bench 4", bench, {-14.0f, 0.5f, -6.0f}, facePlusX);

    // Fountain: a copper rim around a mirror-still water disk.
    const uint32_t fountain =
        b.mesh("fountain", {{makeTorus(2.5f, 0.25f, 64, 12, mat.copper),
                             transformed(makeCylinder(2.4f, 0.05f, 48, mat.water), translation({0, 0.1f, 0})),
                             transformed(makeCylinder(0.3f, 1.6f, 16, mat.chrome), translation({0, 0, 0}))}});
    b.place("fountain", fountain, {6.0f, 0.25f, -6.0f});

    // Street lamps along the kerb, their heads glowing.
    const uint32_t lamp =
        b.mesh("street lamp", {{makeCylinder(0.08f, 5.0f, 12, mat.chrome),
                                transformed(makeSphere(0.3f, 16, 8, mat.lampGlow), translation({0, 5.2f, 0}))}});
    for (int i = 0; i < 6; ++i) {
        b.place("street lamp " + std::to_string(i), lamp, {19.5f, 0, -30.0f + 12.0f * float(i)});
    }

    // Foliage (alpha-tested, foliage.h): grass around the foot of four
    // palms and a chain-link fence across the plaza's north-west corner,
    // over the puddles the camera path passes.
    const uint32_t grass = b.mesh("grass patch", {{makeGrassPatch(16, 0.4f, 1.6f, 21u, foliage.grass)}});
    for (const glm::vec3 at : {glm::vec3{-17, 0, 0}, glm::vec3{0, 0, 17}, glm::vec3{-3, 0, -17}, glm::vec3{-16, 0, 18}}) {
        b.place("grass at " + std::to_string(int(at.x)) + "," + std::to_string(int(at.z)), grass, at);
    }
    const uint32_t fence = b.mesh("fence", {{makeFencePanel(7.0f, 1.4f, foliage.fence)}});
    b.place("fence", fence, {-15.0f, 0, -2.0f});

    // A bus shelter with blended glass walls beside the entrance: seen
    // directly, never in a reflection (passes/transparent.h).
    {
        const glm::vec3 size{3.2f, 2.3f, 1.4f};
        const auto pane = [&](glm::vec2 extent, const glm::mat4& place) {
            // The grid faces +Y; turned to face +Z, then placed.
            return transformed(makeGrid(extent, {1, 1}, mat.shelterGlass),
                               place * glm::mat4_cast(axisAngle({1, 0, 0}, glm::half_pi<float>())));
        };
        const glm::quat side = axisAngle({0, 1, 0}, glm::half_pi<float>());
        std::vector<Geometry> shelter = {
            transformed(makeBox({size.x + 0.2f, 0.08f, size.z + 0.2f}, mat.chrome), translation({0, size.y, 0})),
            pane({size.x, size.y - 0.1f}, translation({0, size.y * 0.5f, -size.z * 0.5f})),
            pane({size.z, size.y - 0.1f}, translation({-size.x * 0.5f, size.y * 0.5f, 0}) * glm::mat4_cast(side)),
            pane({size.z, size.y - 0.1f}, translation({size.x * 0.5f, size.y * 0.5f, 0}) * glm::mat4_cast(side)),
        };
        for (const float x : {-0.5f, 0.5f}) {
            for (const float z : {-0.5f, 0.5f}) {
                shelter.push_back(transformed(makeCylinder(0.04f, size.y, 8, mat.chrome),
                                              translation({x * size.x, 0, z * size.z})));
            }
        }
        b.place("bus shelter", b.mesh("bus shelter", {shelter}), {1.5f, 0, 2.5f});
    }

    // --- Far away: towers beyond the 100 m BVH radius (some enter it along
    // the camera path, some never do) and long-range hills.
    const uint32_t tower =
        b.mesh("tower", {{transformed(makeBox({16, 60, 16}, mat.tower, 0.1f), translation({0, 30, 0}))}});
    const uint32_t glassTower =
        b.mesh("glass tower", {{transformed(makeBox({18, 90, 18}, mat.mirrorTower, 0.1f), translation({0, 45, 0}))}});
    b.place("tower north", tower, {0.0f, 0, 125.0f});
    b.place("tower west", tower, {-110.0f, 0, -30.0f});
    b.place("tower east", tower, {95.0f, 0, -60.0f});
    b.place("tower far east", tower, {160.0f, 0, 40.0f});
    b.place("tower far south", tower, {30.0f, 0, -190.0f});
    b.place("glass tower", glassTower, {-140.0f, 0, 100.0f});
    for (int sector = 0; sector < 8; ++sector) {
        const float a0 = glm::two_pi<float>() * float(sector) / 8.0f;
        const float a1 = glm::two_pi<float>() * float(sector + 1) / 8.0f;
        const uint32_t hills = b.mesh("hills " + std::to_string(sector),
                                      {{makeRingSector(150.0f, 450.0f, a0, a1, 24, 12, mat.hills, &hillHeight)},
                                       {makeRingSector(150.0f, 450.0f, a0, a1, 8, 4, mat.hills, &hillHeight)}});
        b.place("hills " + std::to_string(sector), hills, {0, 0, 0}).longRange = true;
    }

    // --- Rigidly animated (Motion::Dynamic): TLAS instance updates only.
    // Each loop is its own animation: an animation loops over its longest
    // track, so tracks of different periods must not share one.
    {
        Animation anim;
        anim.name = "car";
        // A car driving up one lane of the street and back down the other.
        const uint32_t car = b.mesh(
            "car", {{transformed(makeBox({1.8f, 0.7f, 4.2f}, mat.carPaint), translation({0, 0.65f, 0})),
                     transformed(makeBox({1.6f, 0.55f, 2.2f}, mat.glass), translation({0, 1.25f, -0.2f})), [&] {
                         Geometry wheels;
                         wheels.material = mat.tyre;
                         const glm::mat4 toSide = glm::rotate(glm::mat4(1.0f), glm::half_pi<float>(), {0, 0, 1});
                         for (float x : {-0.95f, 0.95f}) {
                             for (float z : {-1.3f, 1.3f}) {
                                 appendGeometry(wheels, transformed(makeCylinder(0.35f, 0.25f, 16, mat.tyre),
                                                                    translation({x + 0.125f, 0.35f, z}) * toSide));
                             }
                         }
                         return wheels;
                     }()}});
        const uint32_t carNode = b.node("car", kNone, {28, 0, -38});
        b.instance("car", car, carNode, Motion::Dynamic);
        const float lap = 22.0f;
        b.translationTrack(anim, carNode, lap, 45, [](float t) {
            if (t < 10.0f) return glm::vec3(28.0f, 0.0f, -38.0f + 7.6f * t);
            if (t < 11.0f) return glm::vec3(28.0f - 4.0f * (t - 10.0f), 0.0f, 38.0f);
            if (t < 21.0f) return glm::vec3(24.0f, 0.0f, 38.0f - 7.6f * (t - 11.0f));
            return glm::vec3(24.0f + 4.0f * (t - 21.0f), 0.0f, -38.0f);
        });
        b.rotationTrack(anim, carNode, lap, 45, [](float t) {
            float turns = 0.0f;  // half turns completed
            if (t >= 10.0f) turns = std::min(t - 10.0f, 1.0f);
            if (t >= 21.0f) turns = 1.0f + std::min(t - 21.0f, 1.0f);
            return glm::angleAxis(glm::pi<float>() * turns, glm::vec3(0, 1, 0));
        });
        b.play(std::move(anim));

        // The awning's ceiling fan.
        Geometry blades;
        blades.material = mat.chrome;
        for (int k = 0; k < 4; ++k) {
            const glm::mat4 r = glm::rotate(glm::mat4(1.0f), glm::half_pi<float>() * float(k), {0, 1, 0});
            appendGeometry(blades,
                           transformed(makeBox({0.9f, 0.02f, 0.16f}, mat.chrome), r * translation({0.5f, 0, 0})));
        }
        const uint32_t fan =
            b.mesh("ceiling fan",
                   {{blades, transformed(makeCylinder(0.08f, 0.25f, 12, mat.brass), translation({0, -0.1f, 0}))}});
        const uint32_t fanNode = b.node("ceiling fan", kNone, {-18.5f, 3.3f, 6.0f});
        b.instance("ceiling fan", fan, fanNode, Motion::Dynamic);
        anim = Animation{"ceiling fan", {}, {}};
        b.rotationTrack(anim, fanNode, 2.0f, 9, [](float t) {
            return axisAngle({0, 1, 0}, glm::two_pi<float>() * t / 2.0f);
        });
        b.play(std::move(anim));

        // A neon sign turning above the north side.
        const uint32_t sign =
            b.mesh("neon sign", {{makeBox({3.0f, 0.8f, 0.12f}, mat.neon),
                                  transformed(makeBox({3.2f, 1.0f, 0.1f}, mat.chrome), translation({0, 0, -0.1f}))}});
        const uint32_t signNode = b.node("neon sign", kNone, {0.0f, 6.0f, -18.0f});
        b.instance("neon sign", sign, signNode, Motion::Dynamic);
        anim = Animation{"neon sign", {}, {}};
        b.rotationTrack(anim, signNode, 8.0f, 17, [](float t) {
            return axisAngle({0, 1, 0}, glm::two_pi<float>() * t / 8.0f);
        });
        b.play(std::move(anim));

        // A lantern swinging on a chain.
        const uint32_t lantern = b.mesh(
            "hanging lantern", {{transformed(makeCylinder(0.015f, 1.2f, 6, mat.brass), translation({0, -1.2f, 0})),
                                 transformed(makeBox({0.3f, 0.4f, 0.3f}, mat.lampGlow), translation({0, -1.4f, 0}))}});
        const uint32_t lanternNode = b.node("hanging lantern", kNone, {10.0f, 4.2f, 12.0f});
        b.instance("hanging lantern", lantern, lanternNode, Motion::Dynamic);
        anim = Animation{"hanging lantern", {}, {}};
        b.rotationTrack(anim, lanternNode, 3.0f, 13, [](float t) {
            return axisAngle({1, 0, 0}, 0.35f * std::sin(glm::two_pi<float>() * t / 3.0f));
        });
        b.play(std::move(anim));
    }

    // --- Skinned (Motion::Skinned): palms and flags in the wind, walkers.
    {
        Animation wind;
        wind.name = "palms in the wind";
        const std::array<glm::vec3, 8> palms = {glm::vec3{-16, 0, -18},
                                                {-16, 0, 18},
                                                {16, 0, -18},
                                                {16, 0, 18},
                                                {-17, 0, 0},
                                                {0, 0, 17},
                                                {17, 0, 0},
                                                {-3, 0, -17}};
        for (size_t p = 0; p < palms.size(); ++p) {
            const std::string name = "palm " + std::to_string(p);
            const float height = 6.0f + 0.5f * float(p % 3);
            // Alpha-tested fronds: leaflets cut out of curved strips, rising
            // from the crown and drooping (foliage.h).
            Geometry leaves;
            leaves.material = foliage.frond;
            for (int k = 0; k < 9; ++k) {
                const float turn = glm::two_pi<float>() * (float(k) + 0.3f * float(p % 2)) / 9.0f;
                const glm::mat4 m = translation({0, height, 0}) * glm::rotate(glm::mat4(1.0f), turn, {0, 1, 0}) *
                                    glm::rotate(glm::mat4(1.0f), 0.45f - 0.1f * float(k % 3), {0, 0, 1});
                appendGeometry(leaves, transformed(makeFrond(2.8f, 1.0f, 1.6f, 6, foliage.frond), m));
            }
            bindToJoint(leaves, 3);
            const uint32_t palmMesh = b.mesh(name, {{makeSkinnedTube(0.18f, height, 12, 16, 4, mat.trunk), leaves}});
            const uint32_t palmNode = b.node(name, kNone, palms[p]);
            const auto [skin, joints] = b.jointChain(name, palmNode, {0, height / 4.0f, 0}, 4);
            Instance& inst = b.instance(name, palmMesh, palmNode, Motion::Skinned);
            inst.skin = skin;
            const float phase = 0.7f * float(p);
            for (size_t j = 1; j < joints.size(); ++j) {
                b.rotationTrack(wind, joints[j], 4.0f, 17, [=](float t) {
                    const float a = 0.05f * std::sin(glm::two_pi<float>() * t / 4.0f + phase + 0.4f * float(j));
                    return axisAngle({0.3f, 0, 1}, a);
                });
            }
        }
        b.play(std::move(wind));
        Animation flags;
        flags.name = "flags in the wind";
        for (int f = 0; f < 3; ++f) {
            const std::string name = "flag " + std::to_string(f);
            const glm::vec3 base{-2.0f + 4.0f * float(f), 0.0f, -16.0f};
            b.place(name + " pole", b.mesh(name + " pole", {{makeCylinder(0.05f, 7.0f, 10, mat.chrome)}}), base);
            const uint32_t flagMesh = b.mesh(name, {{makeSkinnedSheet({2.0f, 1.2f}, {16, 8}, 6, mat.flag)}});
            const uint32_t flagNode = b.node(name, kNone, base + glm::vec3(0.05f, 5.6f, 0.0f));
            const auto [skin, joints] = b.jointChain(name, flagNode, {2.0f / 6.0f, 0, 0}, 6);
            Instance& inst = b.instance(name, flagMesh, flagNode, Motion::Skinned);
            inst.skin = skin;
            for (size_t j = 0; j < joints.size(); ++j) {
                b.rotationTrack(flags, joints[j], 1.5f, 13, [=](float t) {
                    const float a = 0.25f * std::sin(glm::two_pi<float>() * t / 1.5f - 0.9f * float(j) + float(f));
                    return axisAngle({0, 1, 0}, a);
                });
            }
        }
        b.play(std::move(flags));

        // Two people walking around the fountain (a 16 s loop), bending at
        // every step (a 1 s loop).
        Animation walk;
        walk.name = "walker paths";
        Animation steps;
        steps.name = "walker steps";
        for (int w = 0; w < 2; ++w) {
            const std::string name = "walker " + std::to_string(w);
            Geometry head = transformed(makeSphere(0.16f, 16, 8, mat.skinTone), translation({0, 1.85f, 0}));
            bindToJoint(head, 3);
            const uint32_t body = b.mesh(name, {{makeSkinnedTube(0.22f, 1.65f, 12, 12, 4, mat.cloth), head}});
            const uint32_t rootNode = b.node(name, kNone, {6.0f + 5.0f, 0.0f, -6.0f});
            const auto [skin, joints] = b.jointChain(name, rootNode, {0, 1.65f / 4.0f, 0}, 4);
            Instance& inst = b.instance(name, body, rootNode, Motion::Skinned);
            inst.skin = skin;
            const float period = 16.0f;
            const float direction = w == 0 ? 1.0f : -1.0f;
            const float radius = w == 0 ? 5.0f : 4.2f;
            b.translationTrack(walk, rootNode, period, 33, [=](float t) {
                const float a = direction * glm::two_pi<float>() * t / period + float(w) * glm::pi<float>();
                return glm::vec3(6.0f + radius * std::cos(a), 0.0f, -6.0f + radius * std::sin(a));
            });
            b.rotationTrack(walk, rootNode, period, 33, [=](float t) {
                const float a = direction * glm::two_pi<float>() * t / period + float(w) * glm::pi<float>();
                return axisAngle({0, 1, 0}, -a);
            });
            for (size_t j = 1; j < joints.size(); ++j) {
                b.rotationTrack(steps, joints[j], 1.0f, 9, [=](float t) {
                    return axisAngle({1, 0, 0}, 0.06f * std::sin(glm::two_pi<float>() * t + 0.5f * float(j)));
                });
            }
        }
        b.play(std::move(walk));
        b.play(std::move(steps));
    }

    // --- First person: an arm holding a lantern, hanging below the camera
    // node so it follows the view; skinned, so it deforms every frame.
    {
        s.cameraNode = int32_t(b.node("camera", kNone, {0, 0, 0}));
        Geometry hand = transformed(makeBox({0.12f, 0.12f, 0.1f}, mat.skinTone), translation({0, 0.48f, 0}));
        Geometry lanternFrame = transformed(makeBox({0.1f, 0.02f, 0.1f}, mat.brass), translation({0, 0.62f, 0}));
        appendGeometry(lanternFrame, transformed(makeBox({0.1f, 0.02f, 0.1f}, mat.brass), translation({0, 0.76f, 0})));
        Geometry lanternGlow = transformed(makeBox({0.08f, 0.12f, 0.08f}, mat.lampGlow), translation({0, 0.69f, 0}));
        for (Geometry* g : {&hand, &lanternFrame, &lanternGlow}) {
            bindToJoint(*g, 2);
        }
        const uint32_t arm =
            b.mesh("first-person arm",
                   {{makeSkinnedTube(0.045f, 0.45f, 10, 6, 3, mat.cloth), hand, lanternFrame, lanternGlow}});
        const uint32_t armNode =
            b.node("first-person arm", s.cameraNode, {0.26f, -0.38f, -0.2f}, axisAngle({1, 0, 0}, -1.35f));
        const auto [skin, joints] = b.jointChain("first-person arm", armNode, {0, 0.15f, 0}, 3);
        Instance& inst = b.instance("first-person arm", arm, armNode, Motion::Skinned);
        inst.skin = skin;
        inst.firstPerson = true;
        Animation bob;
        bob.name = "first-person bob";
        for (size_t j = 1; j < joints.size(); ++j) {
            b.rotationTrack(bob, joints[j], 1.2f, 9, [=](float t) {
                return axisAngle({1, 0, 0.3f}, 0.08f * std::sin(glm::two_pi<float>() * t / 1.2f + float(j)));
            });
        }
        b.play(std::move(bob));
    }

    // --- Particles: glow around the street lamps (the particle TLAS).
    for (int i = 0; i < 6; ++i) {
        for (int k = 0; k < 4; ++k) {
            const float a = glm::half_pi<float>() * float(k) + 0.3f * float(i);
            s.particles.push_back({{19.5f + 0.6f * std::cos(a), 5.0f + 0.25f * float(k % 2),
                                    -30.0f + 12.0f * float(i) + 0.6f * std::sin(a)},
                                   0.12f,
                                   {1.0f, 0.7f, 0.4f, 0.6f}});
        }
    }

    // --- Light, sky, camera: a low sun after rain.
    s.sun.directionToLight = glm::normalize(glm::vec3(-0.5f, 0.35f, -0.6f));
    s.sun.color = {1.0f, 0.82f, 0.65f};
    s.sun.illuminance = 60000.0f;
    s.environment.sky.zenithColor = {0.22f, 0.34f, 0.58f};
    s.environment.sky.horizonColor = {0.95f, 0.72f, 0.55f};
    s.environment.sky.groundColor = {0.12f, 0.11f, 0.1f};
    s.lens = {glm::radians(60.0f), 0.1f, kInfiniteFar};
    s.cameraPath.keys = {
        {0.0f, {0.0f, 1.7f, 18.0f}, {0.0f, 1.2f, 0.0f}},      {3.0f, {-6.0f, 1.7f, 12.0f}, {-5.0f, 1.0f, -3.0f}},
        {6.0f, {-10.0f, 1.7f, 2.0f}, {-25.0f, 4.0f, 0.0f}},   {9.0f, {-4.0f, 1.7f, -8.0f}, {6.0f, 0.5f, -6.0f}},
        {12.0f, {6.0f, 1.7f, -14.0f}, {26.0f, 2.0f, -10.0f}}, {15.0f, {14.0f, 1.7f, -2.0f}, {26.0f, 3.0f, 20.0f}},
        {18.0f, {8.0f, 1.7f, 10.0f}, {0.0f, 1.0f, 0.0f}},     {20.0f, {0.0f, 1.7f, 18.0f}, {0.0f, 1.2f, 0.0f}},
    };
    // Presets (glint-render --camera): points of the path, and one low over
    // the mirror puddles where reflections dominate the image.
    const auto pathView = [&](const char* name, float seconds) {
        const CameraPose pose = s.cameraPath.evaluate(seconds);
        s.views.push_back({name, s.lens, pose.position, pose.target});
    };
    pathView("entrance", 0.0f);
    pathView("puddles", 3.0f);
    pathView("street", 9.0f);
    pathView("far-buildings", 12.0f);
    s.views.push_back({"puddle-low", s.lens, {-4.0f, 0.4f, 9.0f}, {-4.0f, 0.0f, -10.0f}});
    return std::move(b.scene);
}

// ---------------------------------------------------------------------------
// Hard cases
// ---------------------------------------------------------------------------

// Everything sits this far from the origin, where a float step is ~1 mm.
constexpr glm::vec3 kFarOrigin{10000.0f, 0.0f, 10000.0f};

Scene buildHardCases() {
    SceneBuilder b("hard-cases");
    Scene& s = b.scene;
    const uint32_t mirror = b.material(makeMaterial("perfect mirror", {0.95f, 0.95f, 0.95f}, 1.0f, 0.0f));
    const uint32_t glossy = b.material(makeMaterial("glossy mirror", {0.9f, 0.9f, 0.92f}, 1.0f, 0.08f));
    const uint32_t floorMirror = b.material(makeMaterial("mirror floor", {0.9f, 0.9f, 0.9f}, 1.0f, 0.0f));
    const uint32_t rough = b.material(makeMaterial("rough white", {0.8f, 0.8f, 0.8f}, 0.0f, 1.0f));
    const uint32_t smoothDielectric = b.material(makeMaterial("smooth black", {0.02f, 0.02f, 0.02f}, 0.0f, 0.0f));
    const uint32_t roughMetal = b.material(makeMaterial("rough gold", {1.0f, 0.78f, 0.34f}, 1.0f, 1.0f));
    Material thin = makeMaterial("thin panel", {0.7f, 0.2f, 0.1f}, 0.0f, 0.4f);
    thin.doubleSided = true;
    const uint32_t thinPanel = b.material(thin);
    const uint32_t farWall = b.material(makeEmissive("far wall", {0.3f, 0.5f, 1.0f}, 4.0f));
    const uint32_t ground = b.material(makeMaterial("far ground", {0.3f, 0.28f, 0.25f}, 0.0f, 0.9f));

    const glm::vec3 o = kFarOrigin;
    // The mirror corridor: 4 m wide, 4 m high, 200 m long towards -Z; the
    // camera looks down it, so the floor is seen at grazing angles.
    const uint32_t corridorFloor = b.mesh(
        "corridor floor", {{makeGrid({4, 200}, {4, 100}, floorMirror)}, {makeGrid({4, 200}, {1, 10}, floorMirror)}});
    b.place("corridor floor", corridorFloor, o + glm::vec3(0, 0, -100));
    const uint32_t corridorWall = b.mesh("corridor wall", {{makeGrid({4, 200}, {2, 100}, mirror)}});
    const uint32_t corridorWallGlossy = b.mesh("corridor wall glossy", {{makeGrid({4, 200}, {2, 100}, glossy)}});
    // Grid faces +Y; roll it to face +X (left wall) or -X (right wall).
    b.place("left wall", corridorWall, o + glm::vec3(-2, 2, -100), axisAngle({0, 0, 1}, -glm::half_pi<float>()));
    b.place("right wall", corridorWallGlossy, o + glm::vec3(2, 2, -100), axisAngle({0, 0, 1}, glm::half_pi<float>()));

    // Thin walls: 2 mm thick, and zero thick (one double-sided quad), and
    // 1 cm pillars.
    const uint32_t thinWall = b.mesh("2 mm wall", {{makeBox({4.0f, 1.5f, 0.002f}, thinPanel)}});
    b.place("2 mm wall", thinWall, o + glm::vec3(0, 0.75f, -40));
    const uint32_t sheet = b.mesh("zero-thickness wall", {{makeGrid({1.5f, 3.0f}, {1, 1}, thinPanel)}});
    b.place("zero-thickness wall", sheet, o + glm::vec3(-1.1f, 1.5f, -70), axisAngle({1, 0, 0}, glm::half_pi<float>()));
    const uint32_t pillar = b.mesh("1 cm pillar", {{makeCylinder(0.005f, 3.0f, 8, rough)}});
    b.place("pillar left", pillar, o + glm::vec3(-1, 0, -25));
    b.place("pillar right", pillar, o + glm::vec3(1, 0, -25));

    // Roughness 0 and 1, metal and dielectric.
    const uint32_t sphere0 = b.mesh("sphere roughness 0", {{makeSphere(0.4f, 32, 16, smoothDielectric)}});
    const uint32_t sphere1 = b.mesh("sphere roughness 1", {{makeSphere(0.4f, 32, 16, rough)}});
    const uint32_t sphere2 = b.mesh("metal sphere roughness 1", {{makeSphere(0.4f, 32, 16, roughMetal)}});
    const uint32_t sphere3 = b.mesh("metal sphere roughness 0", {{makeSphere(0.4f, 32, 16, mirror)}});
    b.place("sphere roughness 0", sphere0, o + glm::vec3(-1.2f, 0.4f, -15));
    b.place("sphere roughness 1", sphere1, o + glm::vec3(-0.4f, 0.4f, -15));
    b.place("metal sphere roughness 1", sphere2, o + glm::vec3(0.4f, 0.4f, -15));
    b.place("metal sphere roughness 0", sphere3, o + glm::vec3(1.2f, 0.4f, -15));

    // Degenerate triangles next to good ones: repeated indices, collinear
    // points, a zero-area sliver.
    {
        Geometry g;
        g.material = rough;
        g.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}, {1, 1, 0}, {1, 1, 0}};
        g.normals.assign(g.positions.size(), {0, 0, 1});
        g.texcoords0.assign(g.positions.size(), {0, 0});
        g.indices = {0, 1, 2,   // good
                     3, 4, 5,   // collinear
                     0, 0, 1,   // repeated index
                     6, 7, 2,   // coincident positions
                     1, 6, 2};  // good
        generateTangents(g);
        const uint32_t degenerate = b.mesh("degenerate triangles", {{g}});
        b.place("degenerate triangles", degenerate, o + glm::vec3(-1.5f, 0.2f, -10));
    }

    // Depth discontinuities: boxes at staggered depths.
    const uint32_t block = b.mesh("block", {{makeBox({0.5f, 0.5f, 0.5f}, rough)}});
    for (int i = 0; i < 4; ++i) {
        b.place("block " + std::to_string(i), block,
                o + glm::vec3(0.9f, 0.25f + 0.5f * float(i), -6.0f - 3.0f * float(i)));
    }

    // A 1 cm cube 3 cm in front of the first camera position (near = 0.01).
    const uint32_t tiny = b.mesh("1 cm cube", {{makeBox({0.01f, 0.01f, 0.01f}, roughMetal)}});
    b.place("1 cm cube", tiny, o + glm::vec3(0.012f, 1.595f, 2.0f - 0.03f));

    // Far: long-range ground at 300 m and a wall 9 km away (beyond every
    // BVH radius: reflections can only get it from the screen).
    const uint32_t farGround = b.mesh("far ground", {{makeGrid({600, 600}, {12, 12}, ground, 0.05f)}});
    b.place("far ground", farGround, o + glm::vec3(0, -0.5f, -500)).longRange = true;
    const uint32_t wall9km = b.mesh("wall 9 km", {{makeBox({3000.0f, 800.0f, 10.0f}, farWall, 0.001f)}});
    b.place("wall 9 km", wall9km, o + glm::vec3(0, 400, -9000)).longRange = true;

    // A thin mirror blade turning across the corridor (rigid motion).
    {
        const uint32_t blade = b.mesh("turning blade", {{makeBox({1.5f, 2.5f, 0.004f}, mirror)}});
        const uint32_t bladeNode = b.node("turning blade", kNone, o + glm::vec3(0.5f, 1.5f, -50));
        b.instance("turning blade", blade, bladeNode, Motion::Dynamic);
        Animation spin;
        spin.name = "blade";
        b.rotationTrack(spin, bladeNode, 8.0f, 17, [](float t) {
            return axisAngle({0, 1, 0}, glm::two_pi<float>() * t / 8.0f);
        });
        b.play(std::move(spin));
    }

    s.sun.directionToLight = glm::normalize(glm::vec3(0.3f, 0.8f, 0.2f));
    s.lens = {glm::radians(70.0f), 0.01f, kInfiniteFar};
    s.cameraPath.keys = {
        {0.0f, o + glm::vec3(0, 1.6f, 2.0f), o + glm::vec3(0, 1.6f, -100.0f)},
        {4.0f, o + glm::vec3(0, 1.6f, -8.0f), o + glm::vec3(0, 1.2f, -100.0f)},
        {7.0f, o + glm::vec3(0.3f, 0.3f, -12.0f), o + glm::vec3(0.3f, 0.25f, -100.0f)},  // grazing the floor
        {10.0f, o + glm::vec3(-1.6f, 1.0f, -20.0f), o + glm::vec3(1.9f, 1.0f, -60.0f)},  // grazing a wall
    };
    for (const auto& [name, seconds] : {std::pair{"corridor", 0.0f}, {"grazing-floor", 7.0f}, {"grazing-wall", 10.0f}}) {
        const CameraPose pose = s.cameraPath.evaluate(seconds);
        s.views.push_back({name, s.lens, pose.position, pose.target});
    }
    return std::move(b.scene);
}

} // namespace

std::span<const std::string_view> builtinSceneNames() {
    static constexpr std::array<std::string_view, 4> kNames = {"plaza", "hard-cases", "city", "mirror-motion"};
    return kNames;
}

bool isBuiltinScene(std::string_view name) {
    const auto names = builtinSceneNames();
    return std::find(names.begin(), names.end(), name.substr(0, name.find(':'))) != names.end();
}

Scene makePlaza() {
    Scene s = buildPlaza();
    prepareScene(s);
    return s;
}

Scene makeHardCases() {
    Scene s = buildHardCases();
    prepareScene(s);
    return s;
}

Scene makeBuiltinScene(std::string_view name) {
    if (name == "plaza") {
        return makePlaza();
    }
    if (name == "hard-cases") {
        return makeHardCases();
    }
    if (name.substr(0, name.find(':')) == "city") {
        return makeCity(parseCityOptions(name));
    }
    if (name.substr(0, name.find(':')) == "mirror-motion") {
        return makeMirrorMotion(true, parseMirrorMotionLamp(name));
    }
    throw SceneError(std::string(name), "", "no such built-in scene (plaza, hard-cases, city, mirror-motion)");
}

Scene loadScene(std::string_view nameOrPath, const GltfLoadOptions& options) {
    if (isBuiltinScene(nameOrPath)) {
        return makeBuiltinScene(nameOrPath);
    }
    return loadGltf(std::filesystem::path(nameOrPath), options);
}

} // namespace glint::scene
