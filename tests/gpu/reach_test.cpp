// One reach for the whole frame (ReflectionFrameSettings::reach): the BVH's
// radius, the rays' length and the SSLR-only distance move together, so a
// larger reach lets a reflection find an object the default one leaves
// out. A mirror floor and a tall wall 150 units ahead of the camera; in rt
// mode, the floor's reflection rays meet the wall about 150 units out.
#include "support/gpu_test.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/animation.h"
#include "glint/scene/procedural_meshes.h"

#include "glint/ray_generation_shared.h"

#include <glm/gtc/matrix_transform.hpp>

#include <doctest/doctest.h>

#include <cstring>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kWidth = 64;
constexpr uint32_t kHeight = 48;

scene::Scene floorAndFarWall() {
    scene::Scene s;
    s.name = "floor and far wall";
    scene::Material mirror;
    mirror.metallicFactor = 1.0f;
    mirror.roughnessFactor = 0.0f;
    s.materials.push_back(mirror);
    scene::Material wall;
    wall.baseColorFactor = {0.8f, 0.3f, 0.2f, 1.0f};
    wall.roughnessFactor = 0.9f;
    s.materials.push_back(wall);
    scene::Mesh floor;
    floor.name = "floor";
    floor.lods.push_back({{scene::makeGrid({60.0f, 60.0f}, {1, 1}, 0)}});
    s.meshes.push_back(floor);
    scene::Mesh box;
    box.name = "wall";
    box.lods.push_back({{scene::makeBox(glm::vec3(400.0f, 120.0f, 2.0f), 1)}});
    s.meshes.push_back(box);
    scene::Instance floorInstance;
    floorInstance.name = "floor";
    floorInstance.mesh = 0;
    s.instances.push_back(floorInstance);
    scene::Instance wallInstance;
    wallInstance.name = "wall";
    wallInstance.mesh = 1;
    wallInstance.transform = wallInstance.previousTransform =
        glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 60.0f, -160.0f));
    s.instances.push_back(wallInstance);
    scene::prepareScene(s);
    return s;
}

// Integrate's hit distances of the floor's pixels after a few rt frames.
std::vector<float> floorHitDistances(gpu::Context& ctx, const scene::Scene& s, float reach) {
    rg::Executor executor(ctx);
    passes::ReflectionRenderer renderer(ctx, s);
    const rg::HostReadback readback(ctx, VkDeviceSize(kWidth) * kHeight * 4, "reach_test.hit_distance");
    scene::Camera camera;
    camera.resolution = {kWidth, kHeight};
    camera.lens = {glm::radians(60.0f), 0.1f, scene::kInfiniteFar};
    camera.jitter = false;
    const scene::CameraPose pose{{0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, -10.0f}, {0, 1, 0}};
    constexpr uint32_t kFrames = 2;
    for (uint32_t i = 0; i < kFrames; ++i) {
        i == 0 ? camera.reset(pose, i) : camera.advance(pose, i);
        passes::ReflectionFrameSettings settings;
        settings.mode = passes::ReflectionMode::Rt;
        settings.reach = reach;
        settings.resetHistory = i == 0;
        rg::Graph graph(executor.queueCaps());
        const passes::ReflectionFrame f = renderer.addFrame(graph, camera, settings);
        rg::FrameResources resources;
        renderer.bind(resources, f);
        if (i + 1 == kFrames) readback.copy(graph, resources, f.integrate.hitDistance);
        executor.run(graph.compile(executor.compileOptions()), resources);
    }
    executor.waitIdle();
    const std::span<const float> all = readback.as<float>();
    // The lower half of the image is floor.
    return {all.begin() + kWidth * (kHeight / 2 + 2), all.begin() + kWidth * kHeight};
}

} // namespace

TEST_CASE("the frame's reach moves the BVH radius and the rays' length together") {
    test::GpuTest gpu;
    const scene::Scene s = floorAndFarWall();
    uint32_t shortHits = 0, longHits = 0, longPixels = 0;
    for (const float d : floorHitDistances(gpu.ctx(), s, 100.0f)) shortHits += d < 0.5f * shader::kMissHitDistance;
    for (const float d : floorHitDistances(gpu.ctx(), s, 200.0f)) {
        ++longPixels;
        if (d < 0.5f * shader::kMissHitDistance) {
            ++longHits;
            CHECK(d > 140.0f);
            CHECK(d < 200.0f);
        }
    }
    // Beyond the default reach the wall is neither in the BVH nor within a
    // ray's length; at 200 the shallow mirror rays of the far floor meet it
    // (the steep ones of the near floor pass over it or run out).
    CHECK(shortHits == 0);
    MESSAGE("reach 200: " << longHits << " of " << longPixels << " floor pixels reflect the wall");
    CHECK(longHits > longPixels / 4);
}

TEST_CASE("a reach or threshold out of range is refused where the frame is declared") {
    test::GpuTest gpu;
    const scene::Scene s = floorAndFarWall();
    passes::ReflectionRenderer renderer(gpu.ctx(), s);
    scene::Camera camera;
    camera.resolution = {kWidth, kHeight};
    camera.lens = {glm::radians(60.0f), 0.1f, scene::kInfiniteFar};
    camera.reset({{0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, -10.0f}, {0, 1, 0}}, 0);
    rg::Graph graph;
    passes::ReflectionFrameSettings settings;
    settings.reach = 0.0f;
    CHECK_THROWS_WITH(renderer.addFrame(graph, camera, settings), doctest::Contains("reach"));
    settings.reach = 100.0f;
    settings.confidenceThreshold = 1.5f;
    CHECK_THROWS_WITH(renderer.addFrame(graph, camera, settings), doctest::Contains("confidenceThreshold"));
}
