// The sun's shadow map (passes/gbuffer.h, SunShadowSettings) on a real
// device, validation and synchronization validation on: a plate's shadow on
// a floor removes exactly the sun term inside its analytic outline, with
// its edge within two shadow texels; no acne under a 10-degree sun; the
// frustum culls of the view and of the shadow map leave the image the
// same; a skinned caster's posed shadow; an alpha-tested caster's shadow
// of its opaque half only; and a texel grid that stays fixed in the world
// as the camera moves.
#include "gbuffer_harness.h"
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/passes/gbuffer.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/procedural_meshes.h"

#include "glint/packing.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

using namespace glint;

namespace {

constexpr float kNear = test::kPassTestNear;
using test::square;
using test::testCamera;
using gbuffer_test::GBufferImage;
using gbuffer_test::render;

} // namespace

// A grey floor (y = 0) with a square plate hovering kPlateHeight above it,
// the sun at `elevationDegrees` above the horizon, coming from
// `azimuthDegrees` (0: from +Z, 90: from +X). With `skinnedShift` the plate
// is skinned to one joint that moves it that far from its bind pose.
constexpr float kPlateHeight = 1.0f;
constexpr float kPlateHalfSize = 1.0f;
const glm::vec3 kPlateCentre(0.0f, kPlateHeight, -3.0f);
const glm::vec3 kFloorAlbedo(0.6f, 0.55f, 0.5f);

scene::Scene floorAndPlateScene(float elevationDegrees, float azimuthDegrees,
                                glm::vec3 skinnedShift = glm::vec3(0.0f)) {
    scene::Scene s;
    s.name = "gbuffer-test-shadow";
    scene::Material grey;
    grey.baseColorFactor = glm::vec4(kFloorAlbedo, 1.0f);
    grey.roughnessFactor = 0.8f;
    grey.metallicFactor = 0.0f;
    s.materials.push_back(grey);
    // The floor's normal is (1,0,0) x (0,0,-1) = +Y, so is the plate's.
    for (const auto& [centre, halfSize] : {std::pair{glm::vec3(0.0f, 0.0f, -3.0f), 8.0f},
                                           std::pair{kPlateCentre, kPlateHalfSize}}) {
        scene::Mesh mesh;
        mesh.name = "square";
        mesh.lods.push_back({{square(centre, {1, 0, 0}, {0, 0, -1}, halfSize)}});
        s.meshes.push_back(std::move(mesh));
        scene::Instance inst;
        inst.mesh = uint32_t(s.meshes.size() - 1);
        s.instances.push_back(inst);
    }
    if (skinnedShift != glm::vec3(0.0f)) {
        scene::Geometry& plate = s.meshes[1].lods[0].geometries[0];
        plate.joints.assign(plate.positions.size(), glm::u16vec4(0));
        plate.weights.assign(plate.positions.size(), glm::vec4(1, 0, 0, 0));
        scene::Node bone;
        bone.name = "bone";
        bone.translation = skinnedShift;
        s.nodes.push_back(bone);
        s.skins.push_back({"plate skin", {0}, {glm::mat4(1.0f)}});
        s.instances[1].motion = scene::Motion::Skinned;
        s.instances[1].skin = 0;
    }
    const float e = glm::radians(elevationDegrees);
    const float a = glm::radians(azimuthDegrees);
    s.sun.directionToLight = {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)};
    s.environment.sky.zenithColor = {0.2f, 0.3f, 0.6f};
    s.environment.sky.horizonColor = {0.7f, 0.7f, 0.65f};
    s.environment.sky.groundColor = {0.1f, 0.1f, 0.1f};
    scene::prepareScene(s);
    return s;
}

// Above and in front of the plate, looking down at it: the floor around
// and beside the plate fills most of the image.
scene::Camera shadowTestCamera() {
    scene::Camera camera;
    camera.resolution = {128, 128};
    camera.lens = {glm::radians(90.0f), kNear, scene::kInfiniteFar};
    camera.jitter = false;
    camera.reset({{0.0f, 6.0f, 2.0f}, {0.0f, 0.0f, -3.0f}, {0, 1, 0}}, 0);
    return camera;
}

// The lit colour of an upward floor with no sun (glint/brdf.glsl:
// albedo / pi times the sky irradiance pi * mix(horizon, zenith, 0.5)).
glm::vec3 floorAmbient(const scene::Scene& scene) {
    const scene::ProceduralSky& sky = scene.environment.sky;
    return kFloorAlbedo * 0.5f * (sky.horizonColor + sky.zenithColor);
}

glm::vec3 worldAt(const scene::Camera& camera, const GBufferImage& img, uint32_t x, uint32_t y) {
    const glm::vec2 ndc((float(x) + 0.5f) / float(img.width) * 2.0f - 1.0f,
                        (float(y) + 0.5f) / float(img.height) * 2.0f - 1.0f);
    const glm::vec4 p = glm::inverse(camera.viewProjection()) * glm::vec4(ndc, img.depth[img.at(x, y)], 1.0f);
    return glm::vec3(p) / p.w;
}

// Shadow-map texel coordinates of a world point under `fit`.
glm::vec2 shadowTexel(const shader::GBufferShadow& fit, glm::vec3 world) {
    const glm::vec4 clip = fit.viewProjection * glm::vec4(world, 1.0f);
    return (glm::vec2(clip) * 0.5f + 0.5f) * float(fit.resolution);
}

// Signed distance from `p` to the convex quad `q`: negative inside.
float signedDistanceToQuad(glm::vec2 p, const std::array<glm::vec2, 4>& q) {
    float distance = std::numeric_limits<float>::max();
    int positive = 0, negative = 0;
    for (size_t i = 0; i < 4; ++i) {
        const glm::vec2 a = q[i], e = q[(i + 1) % 4] - q[i];
        const float side = e.x * (p.y - a.y) - e.y * (p.x - a.x);
        positive += side > 0.0f;
        negative += side < 0.0f;
        const float t = glm::clamp(glm::dot(p - a, e) / glm::dot(e, e), 0.0f, 1.0f);
        distance = std::min(distance, glm::length(p - (a + t * e)));
    }
    return positive == 0 || negative == 0 ? -distance : distance;
}

// Per floor pixel: where it lies against the plate's analytic shadow, in
// shadow texels (negative inside), and the lit colours with and without
// shadows.
struct FloorPixel {
    uint32_t x = 0, y = 0;
    float edgeTexels = 0.0f;
    glm::vec3 lit{0.0f};
    glm::vec3 unshadowed{0.0f};
};

std::vector<FloorPixel> floorPixels(const scene::Camera& camera, const shader::GBufferShadow& fit,
                                    const GBufferImage& shadowed, const GBufferImage& unshadowed,
                                    glm::vec3 plateShift = glm::vec3(0.0f)) {
    // The plate's shadow on the floor is where the sun's rays through the
    // plate land: in the shadow map's plane, the plate's own outline.
    std::array<glm::vec2, 4> plate;
    const glm::vec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (size_t i = 0; i < 4; ++i) {
        plate[i] = shadowTexel(fit, kPlateCentre + plateShift +
                                        kPlateHalfSize * glm::vec3(corners[i].x, 0.0f, corners[i].y));
    }
    std::vector<FloorPixel> out;
    for (uint32_t y = 0; y < shadowed.height; ++y) {
        for (uint32_t x = 0; x < shadowed.width; ++x) {
            const size_t i = shadowed.at(x, y);
            if (shadowed.normal[i].w == 0.0f) continue;
            const glm::vec3 world = worldAt(camera, shadowed, x, y);
            if (std::abs(world.y) > 1e-3f) continue;  // the plate
            out.push_back({x, y, signedDistanceToQuad(shadowTexel(fit, world), plate), glm::vec3(shadowed.lit[i]),
                           glm::vec3(unshadowed.lit[i])});
        }
    }
    return out;
}

bool near(glm::vec3 a, glm::vec3 b) {
    const glm::vec3 d = glm::abs(a - b);
    const glm::vec3 tolerance = 3e-3f * glm::abs(b) + 1e-3f;  // half precision
    return d.x <= tolerance.x && d.y <= tolerance.y && d.z <= tolerance.z;
}

// A lookup is affected only by texel centres less than two texels away
// (the filter's reach), and the normal offset moves lookups up to one texel
// sideways (SunShadowSettings::normalOffset); the map samples the occluder
// at texel centres, so the stored edge adds nothing. Beyond 3 texels from
// the analytic edge a pixel is fully lit or fully shadowed.
constexpr float kPenumbraTexels = 3.0f;

TEST_CASE("a plate above a floor shadows the analytic region: ambient light inside, the full sun outside") {
    test::GpuTest gpu;
    const scene::Scene scene = floorAndPlateScene(45.0f, 160.0f);
    const scene::Camera camera = shadowTestCamera();
    passes::GBufferSettings settings;
    SUBCASE("default resolution") {}
    SUBCASE("256 texels, so the edge is resolved by the pixels") { settings.shadow.resolution = 256; }
    passes::GBufferSettings off = settings;
    off.shadow.enabled = false;

    passes::GBufferStats stats, offStats;
    const GBufferImage shadowed = render(gpu, scene, {camera}, &stats, settings);
    const GBufferImage unshadowed = render(gpu, scene, {camera}, &offStats, off);
    const shader::GBufferShadow fit = passes::fitSunShadow(scene, camera, settings.shadow);
    REQUIRE(stats.shadow.enabled == 1u);
    CHECK(stats.shadow.resolution == settings.shadow.resolution);
    CHECK(stats.shadowDraws == 2u);
    CHECK(offStats.shadow.enabled == 0u);
    CHECK(offStats.shadowDraws == 0u);
    // The scene is smaller than the view's 60 m: the map covers the scene.
    CHECK(fit.fadeEnd <= fit.fadeStart);
    CHECK(fit.texelWorldSize * float(fit.resolution) < 40.0f);

    const glm::vec3 ambient = floorAmbient(scene);
    uint32_t inside = 0, outside = 0, penumbra = 0;
    for (const FloorPixel& p : floorPixels(camera, fit, shadowed, unshadowed)) {
        INFO("pixel " << p.x << ", " << p.y << ": " << p.edgeTexels << " texels from the edge, lit " << p.lit.r
                      << " " << p.lit.g << " " << p.lit.b << ", unshadowed " << p.unshadowed.r);
        // Without shadows the sun reaches everywhere on the floor.
        REQUIRE(glm::all(glm::greaterThan(p.unshadowed, ambient * 1.5f)));
        const glm::vec3 sun = p.unshadowed - ambient;
        const float visibility = (glm::dot(p.lit - ambient, glm::vec3(1.0f))) / glm::dot(sun, glm::vec3(1.0f));
        if (p.edgeTexels < -kPenumbraTexels) {
            REQUIRE(near(p.lit, ambient));
            ++inside;
        } else if (p.edgeTexels > kPenumbraTexels) {
            REQUIRE(near(p.lit, p.unshadowed));
            ++outside;
        } else {
            // The half-shadow line lies within two texels of the analytic edge.
            if (visibility < 0.5f) REQUIRE(p.edgeTexels < 2.0f);
            if (visibility > 0.5f) REQUIRE(p.edgeTexels > -2.0f);
            ++penumbra;
        }
    }
    // The plate's shadow is about 2 x 2 units, the floor 16 x 16.
    CHECK(inside > 100u);
    CHECK(outside > 2000u);
    MESSAGE("floor pixels: " << inside << " in shadow, " << outside << " lit, " << penumbra << " at the edge");
}

TEST_CASE("a floor under a 10-degree sun has no acne: every floor pixel outside the plate's shadow gets the full sun") {
    test::GpuTest gpu;
    float azimuth = 160.0f;
    passes::GBufferSettings settings;
    SUBCASE("sun from the far side, default resolution") {}
    SUBCASE("sun from the side, at 45 degrees to the texel grid") { azimuth = 225.0f; }
    SUBCASE("sun from the side, 512 texels") {
        azimuth = 250.0f;
        settings.shadow.resolution = 512;
    }
    const scene::Scene scene = floorAndPlateScene(10.0f, azimuth);
    const scene::Camera camera = shadowTestCamera();
    passes::GBufferSettings off = settings;
    off.shadow.enabled = false;
    const GBufferImage shadowed = render(gpu, scene, {camera}, nullptr, settings);
    const GBufferImage unshadowed = render(gpu, scene, {camera}, nullptr, off);
    const shader::GBufferShadow fit = passes::fitSunShadow(scene, camera, settings.shadow);

    const glm::vec3 ambient = floorAmbient(scene);
    uint32_t lit = 0, inside = 0;
    for (const FloorPixel& p : floorPixels(camera, fit, shadowed, unshadowed)) {
        INFO("pixel " << p.x << ", " << p.y << ": " << p.edgeTexels << " texels from the edge, lit " << p.lit.r
                      << ", unshadowed " << p.unshadowed.r << ", ambient " << ambient.r);
        // At 10 degrees the sun still gives the floor more than the sky does.
        REQUIRE(p.unshadowed.r > 1.3f * ambient.r);
        if (p.edgeTexels > kPenumbraTexels) {
            REQUIRE(near(p.lit, p.unshadowed));
            ++lit;
        } else if (p.edgeTexels < -kPenumbraTexels) {
            REQUIRE(near(p.lit, ambient));
            ++inside;
        }
    }
    CHECK(lit > 4000u);
    MESSAGE("floor pixels: " << lit << " lit, " << inside << " in shadow");
}

TEST_CASE("instances outside the view are not drawn, those outside the shadow map not cast, and the image is the same") {
    test::GpuTest gpu;
    scene::Scene scene = floorAndPlateScene(45.0f, 160.0f);
    // A box behind the camera (outside its frustum, inside the shadow map's
    // box: it may still cast into the view), and one 300 m away, beyond the
    // map fitted to the view's 60 m.
    scene::Mesh box;
    box.name = "box";
    box.lods.push_back({{scene::makeBox({1.0f, 1.0f, 1.0f}, 0)}});
    scene.meshes.push_back(std::move(box));
    for (const glm::vec3 at : {glm::vec3(0.0f, 1.0f, 20.0f), glm::vec3(300.0f, 1.0f, -3.0f)}) {
        scene::Instance inst;
        inst.mesh = uint32_t(scene.meshes.size() - 1);
        inst.transform = inst.previousTransform = glm::translate(glm::mat4(1.0f), at);
        scene.instances.push_back(inst);
    }
    scene::prepareScene(scene);
    const scene::Camera camera = shadowTestCamera();
    passes::GBufferSettings culled, all;
    all.frustumCulling = false;
    passes::GBufferStats culledStats, allStats;
    const GBufferImage a = render(gpu, scene, {camera}, &culledStats, culled);
    const GBufferImage b = render(gpu, scene, {camera}, &allStats, all);
    CHECK(culledStats.instancesCulled == 2u);
    CHECK(culledStats.shadowInstancesCulled == 1u);
    CHECK(culledStats.draws == 2u);
    CHECK(culledStats.shadowDraws == 3u);
    CHECK(allStats.instancesCulled == 0u);
    CHECK(allStats.draws == 4u);
    CHECK(allStats.shadowDraws == 4u);
    // Nothing culled could reach a pixel: every target is bit for bit the same.
    CHECK(a.depth == b.depth);
    CHECK(a.normal == b.normal);
    CHECK(a.albedo == b.albedo);
    CHECK(a.motion == b.motion);
    CHECK(a.lit == b.lit);
}

TEST_CASE("a skinned plate casts the shadow of its skinned pose, not of its bind pose") {
    test::GpuTest gpu;
    const glm::vec3 shift(2.0f, 0.0f, 0.5f);
    const scene::Scene scene = floorAndPlateScene(45.0f, 160.0f, shift);
    const scene::Camera camera = shadowTestCamera();
    passes::GBufferSettings settings, off;
    off.shadow.enabled = false;
    const GBufferImage shadowed = render(gpu, scene, {camera}, nullptr, settings);
    const GBufferImage unshadowed = render(gpu, scene, {camera}, nullptr, off);
    const shader::GBufferShadow fit = passes::fitSunShadow(scene, camera, settings.shadow);

    const glm::vec3 ambient = floorAmbient(scene);
    uint32_t inside = 0, outside = 0;
    for (const FloorPixel& p : floorPixels(camera, fit, shadowed, unshadowed, shift)) {
        INFO("pixel " << p.x << ", " << p.y << ": " << p.edgeTexels << " texels from the edge, lit " << p.lit.r);
        if (p.edgeTexels < -kPenumbraTexels) {
            REQUIRE(near(p.lit, ambient));
            ++inside;
        } else if (p.edgeTexels > kPenumbraTexels) {
            REQUIRE(near(p.lit, p.unshadowed));
            ++outside;
        }
    }
    CHECK(inside > 100u);
    CHECK(outside > 2000u);
}

TEST_CASE("the shadow map fitted to the view keeps its texel size and world grid as the camera moves and turns") {
    // A floor far larger than the view's reach: the fit follows the camera.
    scene::Scene scene;
    scene.name = "gbuffer-test-large-floor";
    scene.materials.push_back({});
    scene::Mesh mesh;
    mesh.name = "floor";
    mesh.lods.push_back({{square({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, 1000.0f)}});
    scene.meshes.push_back(std::move(mesh));
    scene.instances.push_back({});
    scene.sun.directionToLight = glm::normalize(glm::vec3(-0.5f, 0.35f, -0.6f));
    scene::prepareScene(scene);

    const passes::SunShadowSettings settings;
    scene::Camera camera = testCamera({0.0f, 1.7f, 0.0f});
    const shader::GBufferShadow first = passes::fitSunShadow(scene, camera, settings);
    REQUIRE(first.enabled == 1u);
    CHECK(first.fadeEnd == doctest::Approx(settings.maxDistance));
    CHECK(first.fadeStart < first.fadeEnd);

    const glm::vec3 probe(3.217f, 0.0f, -7.931f);
    const glm::vec2 firstTexel = shadowTexel(first, probe);
    for (const glm::vec3 position : {glm::vec3(0.37f, 1.7f, -2.113f), glm::vec3(-11.9f, 2.2f, 5.31f)}) {
        for (const glm::vec3 look : {glm::vec3(0, 0, -1), glm::vec3(0.6f, -0.2f, 0.3f)}) {
            INFO("camera at " << position.x << ", " << position.y << ", " << position.z);
            camera.advance({position, position + look, {0, 1, 0}}, 1);
            const shader::GBufferShadow fit = passes::fitSunShadow(scene, camera, settings);
            CHECK(fit.texelWorldSize == first.texelWorldSize);
            // The probe sits at the same place within its texel.
            const glm::vec2 texel = shadowTexel(fit, probe);
            const glm::vec2 drift = (texel - firstTexel) - glm::round(texel - firstTexel);
            CHECK(std::abs(drift.x) < 2e-3f);
            CHECK(std::abs(drift.y) < 2e-3f);
        }
    }
}

TEST_CASE("an alpha-tested plate casts the shadow of its opaque half only") {
    test::GpuTest gpu;
    scene::Scene scene = floorAndPlateScene(60.0f, 160.0f);
    // The plate's left half (x < 0) opaque, its right half cut out.
    scene::Geometry& plate = scene.meshes[1].lods[0].geometries[0];
    for (const glm::vec3& p : plate.positions) {
        plate.texcoords0.push_back({(p.x - kPlateCentre.x) / (2.0f * kPlateHalfSize) + 0.5f, 0.5f});
    }
    scene::Texture halves;
    halves.name = "halves";
    halves.width = 64;
    halves.height = 4;
    for (uint32_t y = 0; y < halves.height; ++y) {
        for (uint32_t x = 0; x < halves.width; ++x) {
            halves.rgba8.insert(halves.rgba8.end(), {128, 128, 128, uint8_t(x < 32 ? 255 : 0)});
        }
    }
    scene.textures.push_back(halves);
    scene::Material cutout = scene.materials[0];
    cutout.baseColorTexture.texture = 0;
    cutout.alphaMode = scene::AlphaMode::Mask;
    cutout.doubleSided = true;
    scene.materials.push_back(cutout);
    plate.material = 1;
    scene::prepareScene(scene);

    const scene::Camera camera = shadowTestCamera();
    passes::GBufferSettings settings;
    passes::GBufferSettings off = settings;
    off.shadow.enabled = false;
    const GBufferImage shadowed = render(gpu, scene, {camera}, nullptr, settings);
    const GBufferImage unshadowed = render(gpu, scene, {camera}, nullptr, off);
    const shader::GBufferShadow fit = passes::fitSunShadow(scene, camera, settings.shadow);
    const glm::vec3 ambient = floorAmbient(scene);
    // The analytic shadows of the two halves on the floor.
    const auto halfQuad = [&](float x0, float x1) {
        std::array<glm::vec2, 4> q;
        const glm::vec2 corners[4] = {{x0, -1}, {x1, -1}, {x1, 1}, {x0, 1}};
        for (size_t i = 0; i < 4; ++i) {
            q[i] = shadowTexel(fit, kPlateCentre + kPlateHalfSize * glm::vec3(corners[i].x, 0.0f, corners[i].y));
        }
        return q;
    };
    const auto opaqueHalf = halfQuad(-1.0f, 0.0f), cutHalf = halfQuad(0.0f, 1.0f);
    uint32_t inOpaque = 0, inCut = 0;
    for (const FloorPixel& p : floorPixels(camera, fit, shadowed, unshadowed)) {
        const glm::vec3 world = worldAt(camera, shadowed, p.x, p.y);
        const glm::vec2 texel = shadowTexel(fit, world);
        if (signedDistanceToQuad(texel, opaqueHalf) < -kPenumbraTexels) {
            INFO("pixel " << p.x << ", " << p.y << " under the opaque half");
            REQUIRE(near(p.lit, ambient));
            ++inOpaque;
        } else if (signedDistanceToQuad(texel, cutHalf) < -kPenumbraTexels &&
                   signedDistanceToQuad(texel, opaqueHalf) > kPenumbraTexels) {
            INFO("pixel " << p.x << ", " << p.y << " under the cut-out half");
            REQUIRE(near(p.lit, p.unshadowed));
            ++inCut;
        }
    }
    CHECK(inOpaque > 30u);
    CHECK(inCut > 30u);
}
