// Blended surfaces (glTF alphaMode BLEND, passes/transparent.h) on a real
// device through the whole reflection frame, validation on: panes of known
// emission and coverage over a known wall composite as premultiplied
// "over", sorted back to front whatever the scene's order, hidden behind
// opaque geometry; and they are absent from the reflections in rt and in
// hybrid mode (the G-buffer and the BVH leave them out), where the same pane
// opaque is reflected.
#include "support/gpu_test.h"
#include "support/frame_render.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/animation.h"
#include "glint/scene/procedural_meshes.h"

#include "glint/packing.h"

#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <optional>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr glm::uvec2 kSize{128, 96};

// An unlit emitter: black base colour, no specular (reflectance 0), so its
// radiance is its emission in every direction and light.
scene::Material emitter(glm::vec3 emission, float alpha, scene::AlphaMode mode) {
    scene::Material m;
    m.baseColorFactor = {0.0f, 0.0f, 0.0f, alpha};
    m.metallicFactor = 0.0f;
    m.roughnessFactor = 1.0f;
    m.reflectance = 0.0f;
    m.emissiveFactor = emission;
    m.alphaMode = mode;
    return m;
}

// A `size` rectangle facing +Z (towards a camera looking down -Z) centred
// at `centre`, of material `material`: one mesh and one instance.
void addPane(scene::Scene& s, const std::string& name, glm::vec3 centre, glm::vec2 size, uint32_t material) {
    scene::Mesh mesh;
    mesh.name = name;
    mesh.lods.push_back({{scene::makeGrid(size, {1, 1}, material)}});
    s.meshes.push_back(mesh);
    scene::Instance inst;
    inst.name = name;
    inst.mesh = uint32_t(s.meshes.size() - 1);
    // The grid's +Y normal turned to +Z.
    inst.transform = glm::rotate(glm::translate(glm::mat4(1.0f), centre), glm::radians(90.0f), glm::vec3(1, 0, 0));
    inst.previousTransform = inst.transform;
    s.instances.push_back(inst);
}

// No sun, a black sky: every colour is emission.
void darken(scene::Scene& s) {
    s.sun.illuminance = 0.0f;
    s.environment.sky.zenithColor = s.environment.sky.horizonColor = s.environment.sky.groundColor = glm::vec3(0.0f);
}

// The camera at the origin looking down -Z at a green wall 10 m away; in
// front of it, listed nearest first (so a pass that did not sort would draw
// them in the wrong order), a red pane over the view's left half at 5 m and
// a blue pane over its lower half at 7 m, each of coverage 0.5; and a yellow
// opaque-looking pane (coverage 1) behind the wall, which must not show.
scene::Scene panesScene() {
    scene::Scene s;
    s.name = "panes";
    s.materials = {emitter({0.0f, 0.5f, 0.0f}, 1.0f, scene::AlphaMode::Opaque),
                   emitter({0.8f, 0.0f, 0.0f}, 0.5f, scene::AlphaMode::Blend),
                   emitter({0.0f, 0.0f, 0.8f}, 0.5f, scene::AlphaMode::Blend),
                   emitter({0.8f, 0.8f, 0.0f}, 1.0f, scene::AlphaMode::Blend)};
    addPane(s, "red pane", {-10.0f, 0.0f, -5.0f}, {20.0f, 20.0f}, 1);
    addPane(s, "blue pane", {0.0f, -10.0f, -7.0f}, {40.0f, 20.0f}, 2);
    addPane(s, "wall", {0.0f, 0.0f, -10.0f}, {60.0f, 60.0f}, 0);
    addPane(s, "yellow pane behind the wall", {0.0f, 0.0f, -12.0f}, {60.0f, 60.0f}, 3);
    darken(s);
    s.lens.verticalFovRadians = glm::radians(50.0f);
    s.cameraPath.keys.push_back({0.0f, glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, -1.0f)});
    scene::prepareScene(s);
    return s;
}

// A mirror floor and a green wall 8 m ahead; a red pane 4 m ahead stands
// above the top of the view (the camera looks down steeply), so only the
// floor's reflection could show it. `pane`: its alpha mode, or none.
scene::Scene mirrorScene(std::optional<scene::AlphaMode> pane) {
    scene::Scene s;
    s.name = "pane over a mirror";
    scene::Material floor;
    floor.baseColorFactor = {0.9f, 0.9f, 0.9f, 1.0f};
    floor.metallicFactor = 1.0f;
    floor.roughnessFactor = 0.0f;
    s.materials = {floor, emitter({0.0f, 0.8f, 0.0f}, 1.0f, scene::AlphaMode::Opaque),
                   emitter({0.9f, 0.0f, 0.0f}, 0.8f, pane.value_or(scene::AlphaMode::Opaque))};
    scene::Mesh floorMesh;
    floorMesh.name = "floor";
    floorMesh.lods.push_back({{scene::makeGrid({80.0f, 80.0f}, {1, 1}, 0)}});
    s.meshes.push_back(floorMesh);
    s.instances.push_back({.name = "floor", .mesh = 0});
    addPane(s, "wall", {0.0f, 30.0f, -8.0f}, {80.0f, 60.0f}, 1);
    if (pane) addPane(s, "pane", {0.0f, 15.0f, -4.0f}, {40.0f, 30.0f}, 2);
    darken(s);
    s.lens.verticalFovRadians = glm::radians(50.0f);
    s.cameraPath.keys.push_back({0.0f, glm::vec3(0.0f, 2.5f, 0.0f), glm::vec3(0.0f, 0.0f, -1.0f)});
    scene::prepareScene(s);
    return s;
}

std::vector<uint8_t> render(gpu::Context& ctx, const scene::Scene& s, passes::ReflectionMode mode) {
    passes::ReflectionFrameSettings settings;
    settings.mode = mode;
    // Linear values in, the same values (sRGB-encoded) out.
    settings.composite.tonemap = passes::Tonemap::Clamp;
    return test::renderComposited(ctx, s, kSize, 3, settings);
}

// The linear colour at (x, y) of an sRGB-encoded RGBA8 image.
glm::vec3 linearAt(const std::vector<uint8_t>& rgba, uint32_t x, uint32_t y) {
    const size_t i = (size_t(y) * kSize.x + x) * 4;
    return {shader::srgbToLinear(rgba[i] / 255.0f), shader::srgbToLinear(rgba[i + 1] / 255.0f),
            shader::srgbToLinear(rgba[i + 2] / 255.0f)};
}

uint32_t redPixels(const std::vector<uint8_t>& rgba) {
    uint32_t red = 0;
    for (size_t i = 0; i < rgba.size(); i += 4) {
        red += rgba[i] > rgba[i + 1] + 50 && rgba[i] > rgba[i + 2] + 50 ? 1u : 0u;
    }
    return red;
}

} // namespace

TEST_CASE("blended panes composite back to front as premultiplied 'over' the opaque image, whatever the scene's "
          "order, and not through opaque geometry, in every mode") {
    test::GpuTest gpu;
    const scene::Scene s = panesScene();
    const glm::vec3 wall(0.0f, 0.5f, 0.0f);
    const auto over = [](glm::vec3 emission, float alpha, glm::vec3 behind) {
        return emission * alpha + (1.0f - alpha) * behind;
    };
    const glm::vec3 red(0.8f, 0.0f, 0.0f), blue(0.0f, 0.0f, 0.8f);
    struct Quadrant {
        const char* what;
        glm::uvec2 pixel;
        glm::vec3 expected;
    };
    // The red pane ends at x = 0 (the view's centre column), the blue one
    // at y = 0 (its centre row); sample each quadrant's middle.
    const std::vector<Quadrant> quadrants = {
        {"the wall alone", {kSize.x * 3 / 4, kSize.y / 4}, wall},
        {"red over the wall", {kSize.x / 4, kSize.y / 4}, over(red, 0.5f, wall)},
        {"blue over the wall", {kSize.x * 3 / 4, kSize.y * 3 / 4}, over(blue, 0.5f, wall)},
        // Drawn in the scene's order (red first) this would be
        // (0.2, 0.125, 0.4).
        {"red over blue over the wall", {kSize.x / 4, kSize.y * 3 / 4}, over(red, 0.5f, over(blue, 0.5f, wall))},
    };
    for (const passes::ReflectionMode mode :
         {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Rt, passes::ReflectionMode::Ssr}) {
        CAPTURE(std::string(passes::modeName(mode)));
        const std::vector<uint8_t> image = render(gpu.ctx(), s, mode);
        for (const Quadrant& q : quadrants) {
            CAPTURE(std::string(q.what));
            const glm::vec3 got = linearAt(image, q.pixel.x, q.pixel.y);
            CAPTURE(got.x);
            CAPTURE(got.y);
            CAPTURE(got.z);
            // 8-bit sRGB steps are under 0.005 in linear here.
            for (int c = 0; c < 3; ++c) CHECK(std::abs(got[c] - q.expected[c]) < 0.01f);
        }
    }
}

TEST_CASE("a blended pane is absent from the reflections in rt and hybrid mode; the same pane opaque is reflected") {
    test::GpuTest gpu;
    const scene::Scene none = mirrorScene(std::nullopt);
    const scene::Scene blended = mirrorScene(scene::AlphaMode::Blend);
    const scene::Scene opaque = mirrorScene(scene::AlphaMode::Opaque);
    for (const passes::ReflectionMode mode : {passes::ReflectionMode::Rt, passes::ReflectionMode::Hybrid}) {
        CAPTURE(std::string(passes::modeName(mode)));
        const std::vector<uint8_t> without = render(gpu.ctx(), none, mode);
        const std::vector<uint8_t> withPane = render(gpu.ctx(), blended, mode);
        const std::vector<uint8_t> withOpaque = render(gpu.ctx(), opaque, mode);
        // The pane is out of the direct view: the images are the same.
        CHECK(redPixels(without) == 0u);
        CHECK(withPane == without);
        // Opaque, the pane hides the wall in the floor's reflection
        // (thousands of red pixels): the blended one would have shown.
        CHECK(redPixels(withOpaque) > 1000u);
    }
}

TEST_CASE("the transparent passes are declared only when a blended surface is in view, or for their debug view") {
    test::GpuTest gpu;
    const auto declare = [&](const scene::Scene& s, const char* debugView) {
        rg::Executor executor(gpu.ctx());
        passes::ReflectionRenderer renderer(gpu.ctx(), s);
        scene::Camera camera;
        camera.resolution = kSize;
        camera.lens = s.lens;
        camera.reset(s.cameraPath.evaluate(0.0f), 0);
        rg::Graph graph(executor.queueCaps());
        passes::ReflectionFrameSettings settings;
        settings.debugView = debugView;
        const passes::ReflectionFrame f = renderer.addFrame(graph, camera, settings);
        const rg::Plan plan = graph.compile(executor.compileOptions());
        const bool declared = plan.findPass("transparent") != nullptr && plan.findPass("transparent.clear") != nullptr;
        CHECK(declared == f.transparent.valid());
        return declared;
    };
    CHECK(declare(panesScene(), "final"));
    // The pane stands above the view: nothing to draw, nothing declared.
    const scene::Scene outOfView = mirrorScene(scene::AlphaMode::Blend);
    CHECK_FALSE(declare(outOfView, "final"));
    CHECK(declare(outOfView, "transparent"));
}
