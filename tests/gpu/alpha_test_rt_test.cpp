// Alpha-tested geometry (glTF alphaMode MASK) in the ray-traced reflections,
// on a real device through the whole reflection frame, validation on: a
// striped cut-out fence that only the floor's reflection shows (it stands
// above the top of the view) in front of a wall. Reflection rays pass
// through the fence's transparent stripes to the wall, in rt and in hybrid
// mode (SSLR cannot see the fence) and with both ray backends; with the
// alpha test off, or an opaque fence, the wall is hidden. A shadow ray
// passes through the cut-outs too: a sunlit floor under a striped canopy,
// seen only in a mirror, is striped with the canopy's shadow.
#include "support/gpu_test.h"
#include "support/frame_render.h"

#include "glint/passes/reflection_frame.h"
#include "glint/scene/animation.h"
#include "glint/scene/procedural_meshes.h"

#include <doctest/doctest.h>

#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr glm::uvec2 kSize{128, 96};

struct Run {
    passes::ReflectionMode mode = passes::ReflectionMode::Rt;
    passes::RtBackend backend = passes::RtBackend::Auto;
    bool alphaTest = true;
    // The hits' sun visibility from the shadow map where it covers them
    // (the default); off, from a shadow ray each (what the shadow test
    // below checks: rays through the cut-outs).
    bool shadowMapAtHits = true;
};

// The last of `frames` composited frames, RGBA8.
std::vector<uint8_t> render(gpu::Context& ctx, const scene::Scene& s, const Run& run, uint32_t frames = 3) {
    passes::ReflectionFrameSettings settings;
    settings.mode = run.mode;
    settings.rt.alphaTest = run.alphaTest;
    settings.rt.shadowMapAtHits = run.shadowMapAtHits;
    passes::ReflectionRendererOptions options;
    options.backend = run.backend;
    return test::renderComposited(ctx, s, kSize, frames, settings, options);
}

// 8 x 1 texels: opaque, opaque, clear, clear, ... (two stripes a period).
scene::Texture stripesTexture() {
    scene::Texture stripes;
    stripes.name = "stripes";
    stripes.width = 8;
    stripes.height = 1;
    for (uint32_t x = 0; x < stripes.width; ++x) {
        stripes.rgba8.insert(stripes.rgba8.end(), {255, 255, 255, uint8_t((x / 2) % 2 == 0 ? 255 : 0)});
    }
    return stripes;
}

scene::Geometry quad(glm::vec3 centre, glm::vec3 u, glm::vec3 v, glm::vec2 half, uint32_t material) {
    scene::Geometry g;
    const glm::vec3 n = glm::normalize(glm::cross(u, v));
    for (const glm::vec2 c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        g.positions.push_back(centre + c.x * half.x * u + c.y * half.y * v);
        g.normals.push_back(n);
        // One texture period per metre along the fence, anchored at x = 0.
        g.texcoords0.push_back(glm::vec2(centre.x + c.x * half.x, c.y * half.y));
    }
    g.indices = {0, 1, 2, 0, 2, 3};
    g.material = material;
    return g;
}

// A mirror floor, a red emissive fence 4 m ahead whose base colour texture
// has transparent stripes (half of every metre along it), a green emissive
// wall 8 m ahead; the camera looks down steeply, so both appear only in
// the floor's reflection. No sun: colours are the emission.
scene::Scene fenceScene(scene::AlphaMode mode) {
    scene::Scene s;
    s.name = "cut-out fence";
    scene::Material floor;
    floor.baseColorFactor = {0.9f, 0.9f, 0.9f, 1.0f};
    floor.metallicFactor = 1.0f;
    floor.roughnessFactor = 0.0f;
    floor.doubleSided = true;
    const auto emissive = [](glm::vec3 colour) {
        scene::Material m;
        m.baseColorFactor = {0.0f, 0.0f, 0.0f, 1.0f};
        m.metallicFactor = 0.0f;
        m.roughnessFactor = 1.0f;
        m.emissiveFactor = colour;
        m.emissiveStrength = 1.0f;
        m.doubleSided = true;
        return m;
    };
    scene::Material fence = emissive({1.0f, 0.02f, 0.02f});
    fence.alphaMode = mode;
    fence.alphaCutoff = 0.5f;
    fence.baseColorTexture.texture = 0;
    s.materials = {floor, fence, emissive({0.02f, 1.0f, 0.02f})};
    s.textures = {stripesTexture()};
    scene::Mesh floorMesh;
    floorMesh.name = "floor";
    floorMesh.lods.push_back({{scene::makeGrid({80.0f, 80.0f}, {1, 1}, 0)}});
    scene::Mesh fenceMesh;
    fenceMesh.name = "fence";
    fenceMesh.lods.push_back({{quad({0.0f, 15.0f, -4.0f}, {1, 0, 0}, {0, 1, 0}, {20.0f, 15.0f}, 1)}});
    scene::Mesh wallMesh;
    wallMesh.name = "wall";
    wallMesh.lods.push_back({{quad({0.0f, 30.0f, -8.0f}, {1, 0, 0}, {0, 1, 0}, {40.0f, 30.0f}, 2)}});
    s.meshes = {floorMesh, fenceMesh, wallMesh};
    for (uint32_t m = 0; m < 3; ++m) {
        scene::Instance inst;
        inst.name = s.meshes[m].name;
        inst.mesh = m;
        s.instances.push_back(inst);
    }
    s.sun.illuminance = 0.0f;
    s.lens.verticalFovRadians = glm::radians(50.0f);
    s.cameraPath.keys.push_back({0.0f, glm::vec3(0.0f, 2.5f, 0.0f), glm::vec3(0.0f, 0.0f, -1.0f)});
    scene::prepareScene(s);
    return s;
}

struct Colours {
    uint32_t red = 0;    // the fence
    uint32_t green = 0;  // the wall, through the fence's cut-outs
};

Colours countColours(const std::vector<uint8_t>& rgba) {
    Colours c;
    for (size_t i = 0; i < rgba.size(); i += 4) {
        const int r = rgba[i], g = rgba[i + 1], b = rgba[i + 2];
        c.red += r > g + 50 && r > b + 50 ? 1u : 0u;
        c.green += g > r + 50 && g > b + 50 ? 1u : 0u;
    }
    return c;
}

// A mirror wall filling the view, and behind the camera (seen only in the
// mirror) a white floor under a high striped cut-out canopy, the sun
// almost overhead: the floor's hits are lit only where their shadow rays
// pass through the canopy's transparent stripes.
scene::Scene canopyScene() {
    scene::Scene s;
    s.name = "cut-out canopy";
    scene::Material mirror;
    mirror.baseColorFactor = {0.9f, 0.9f, 0.9f, 1.0f};
    mirror.metallicFactor = 1.0f;
    mirror.roughnessFactor = 0.0f;
    mirror.doubleSided = true;
    scene::Material floor;
    floor.baseColorFactor = {0.8f, 0.8f, 0.8f, 1.0f};
    floor.metallicFactor = 0.0f;
    floor.roughnessFactor = 1.0f;
    floor.doubleSided = true;
    scene::Material canopy;
    canopy.baseColorFactor = {0.05f, 0.05f, 0.05f, 1.0f};
    canopy.metallicFactor = 0.0f;
    canopy.roughnessFactor = 1.0f;
    canopy.doubleSided = true;
    canopy.alphaMode = scene::AlphaMode::Mask;
    canopy.baseColorTexture.texture = 0;
    s.materials = {mirror, floor, canopy};
    s.textures = {stripesTexture()};
    scene::Mesh mirrorMesh;
    mirrorMesh.name = "mirror";
    mirrorMesh.lods.push_back({{quad({0.0f, 6.0f, -3.0f}, {1, 0, 0}, {0, 1, 0}, {30.0f, 6.0f}, 0)}});
    scene::Mesh floorMesh;
    floorMesh.name = "floor behind the camera";
    floorMesh.lods.push_back({{quad({0.0f, 0.0f, 18.5f}, {1, 0, 0}, {0, 0, -1}, {30.0f, 21.4f}, 1)}});
    scene::Mesh canopyMesh;
    canopyMesh.name = "canopy";
    canopyMesh.lods.push_back({{quad({0.0f, 4.0f, 18.5f}, {1, 0, 0}, {0, 0, -1}, {30.0f, 21.4f}, 2)}});
    s.meshes = {mirrorMesh, floorMesh, canopyMesh};
    for (uint32_t m = 0; m < 3; ++m) {
        scene::Instance inst;
        inst.name = s.meshes[m].name;
        inst.mesh = m;
        s.instances.push_back(inst);
    }
    s.sun.directionToLight = glm::normalize(glm::vec3(0.0f, 1.0f, 0.1f));
    s.lens.verticalFovRadians = glm::radians(50.0f);
    s.cameraPath.keys.push_back({0.0f, glm::vec3(0.0f, 1.5f, 0.0f), glm::vec3(0.0f, 1.5f, -3.0f)});
    scene::prepareScene(s);
    return s;
}

std::vector<Run> tracedRuns(const gpu::Context& ctx) {
    std::vector<Run> runs = {{passes::ReflectionMode::Rt, passes::RtBackend::Pipeline},
                             {passes::ReflectionMode::Hybrid, passes::RtBackend::Pipeline}};
    if (ctx.caps().rayQuery) {
        runs.push_back({passes::ReflectionMode::Rt, passes::RtBackend::RayQuery});
        runs.push_back({passes::ReflectionMode::Hybrid, passes::RtBackend::RayQuery});
    }
    return runs;
}

} // namespace

TEST_CASE("reflection rays pass through an alpha-tested fence's transparent stripes to the wall behind it, in rt and "
          "hybrid and with both ray backends; with the test off or an opaque fence the wall is hidden") {
    test::GpuTest gpu;
    const scene::Scene masked = fenceScene(scene::AlphaMode::Mask);
    std::vector<std::vector<uint8_t>> rtImages;
    for (const Run& run : tracedRuns(gpu.ctx())) {
        CAPTURE(std::string(passes::modeName(run.mode)));
        CAPTURE(std::string(passes::backendName(run.backend)));
        const std::vector<uint8_t> image = render(gpu.ctx(), masked, run);
        const Colours c = countColours(image);
        CAPTURE(c.red);
        CAPTURE(c.green);
        // The fence's reflection is striped half and half (measured: 4,800 red
        // and 4,800 green pixels in each mode and backend).
        CHECK(c.red > 600u);
        CHECK(c.green > 600u);
        const double share = double(c.green) / double(c.red + c.green);
        CHECK(share > 0.3);
        CHECK(share < 0.7);
        if (run.mode == passes::ReflectionMode::Rt) rtImages.push_back(image);
    }
    // Both backends run the same test on the same data.
    if (rtImages.size() == 2) CHECK(rtImages[0] == rtImages[1]);

    // The same fence traced opaque: with the test switched off, and with an
    // opaque material. The wall is hidden behind it (before alpha-tested
    // geometry was traced, this was every fence's reflection).
    const scene::Scene opaque = fenceScene(scene::AlphaMode::Opaque);
    for (const auto& [s, alphaTest] : {std::pair{&masked, false}, std::pair{&opaque, true}}) {
        CAPTURE(alphaTest);
        const Colours c = countColours(render(gpu.ctx(), *s, {passes::ReflectionMode::Rt, passes::RtBackend::Auto,
                                                              alphaTest}));
        CAPTURE(c.red);
        CHECK(c.red > 1200u);
        CHECK(c.green == 0u);
    }
}

TEST_CASE("shadow rays pass through alpha-tested cut-outs: a floor under a striped canopy, seen in a mirror, is lit "
          "in stripes; with the test off it is all in shadow") {
    test::GpuTest gpu;
    const scene::Scene s = canopyScene();
    std::vector<Run> runs = {{passes::ReflectionMode::Rt, passes::RtBackend::Pipeline, true, false}};
    if (gpu.ctx().caps().rayQuery) {
        runs.push_back({passes::ReflectionMode::Rt, passes::RtBackend::RayQuery, true, false});
    }
    runs.push_back({passes::ReflectionMode::Rt, passes::RtBackend::Auto, false, false});
    // The shadow map holds the canopy's cut-outs too (the G-buffer's masked
    // shadow pipeline): with the map at the hits the stripes are there
    // whatever the rays' alpha test.
    runs.push_back({passes::ReflectionMode::Rt, passes::RtBackend::Auto, false, true});
    for (const Run& run : runs) {
        CAPTURE(std::string(passes::backendName(run.backend)));
        CAPTURE(run.alphaTest);
        CAPTURE(run.shadowMapAtHits);
        const std::vector<uint8_t> image = render(gpu.ctx(), s, run);
        // The floor fills the mirror's lower half: count its sunlit and
        // shadowed pixels below the horizon's haze.
        uint32_t lit = 0, shadowed = 0;
        for (uint32_t y = kSize.y * 5 / 8; y < kSize.y; ++y) {
            for (uint32_t x = 0; x < kSize.x; ++x) {
                const size_t i = (size_t(y) * kSize.x + x) * 4;
                const int luma = (image[i] + image[i + 1] + image[i + 2]) / 3;
                // Measured: sunlit about 245, in shadow (the sky alone) 165.
                lit += luma > 210 ? 1u : 0u;
                shadowed += luma < 190 ? 1u : 0u;
            }
        }
        CAPTURE(lit);
        CAPTURE(shadowed);
        // Measured: 2,259 lit and 2,346 in shadow of 4,608 pixels; with the
        // test off all 4,608 in shadow (as before alpha-tested geometry
        // was traced).
        CHECK(shadowed > 1000u);
        if (run.alphaTest || run.shadowMapAtHits) {
            CHECK(lit > 1000u);
            const double share = double(lit) / double(lit + shadowed);
            CHECK(share > 0.3);
            CHECK(share < 0.7);
        } else {
            CHECK(lit == 0u);
        }
    }
}
