// The G-buffer's occlusion culling (GBufferSettings::occlusionCulling,
// glint/occlusion_shared.h) on a real device, validation and
// synchronization validation on: boxes behind a wall are not drawn, those
// that come out from behind it are drawn the frame they do, and every
// target is bit for bit what the G-buffer draws without the cull.
#include "gbuffer_harness.h"
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/passes/gbuffer.h"
#include "glint/scene/animation.h"
#include "glint/scene/procedural_meshes.h"

#include "glint/occlusion_shared.h"

#include <glm/gtc/matrix_transform.hpp>

#include <string>
#include <vector>

using namespace glint;

namespace {

// A floor, a wall 4 m wide and 4 m tall 4 m in front of the camera
// (testCamera at 1 m height looking down -z), a box beside the wall, and
// two boxes behind it: one the camera sees once it has moved 4 m to the
// right, one it sees from neither place.
constexpr size_t kInstances = 5;
constexpr uint32_t kHiddenFromBoth = 1;  // boxes behind the wall from both places

scene::Scene wallScene() {
    scene::Scene s;
    s.name = "occlusion-test";
    scene::Material grey;
    grey.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    grey.roughnessFactor = 0.6f;
    s.materials.push_back(grey);
    const auto add = [&](scene::Geometry geometry, glm::vec3 at) {
        scene::Mesh mesh;
        mesh.name = "mesh" + std::to_string(s.meshes.size());
        mesh.lods.push_back({{std::move(geometry)}});
        s.meshes.push_back(std::move(mesh));
        scene::Instance inst;
        inst.mesh = uint32_t(s.meshes.size() - 1);
        inst.transform = inst.previousTransform = glm::translate(glm::mat4(1.0f), at);
        s.instances.push_back(inst);
    };
    add(test::square({0.0f, 0.0f, -8.0f}, {1, 0, 0}, {0, 0, -1}, 12.0f), glm::vec3(0.0f));  // floor
    add(scene::makeBox({4.0f, 4.0f, 0.4f}, 0), {0.0f, 2.0f, -4.0f});                      // wall
    add(scene::makeBox({1.0f, 1.0f, 1.0f}, 0), {4.5f, 0.5f, -6.0f});                      // beside it
    add(scene::makeBox({1.0f, 1.0f, 1.0f}, 0), {0.0f, 0.5f, -8.0f});                      // comes out
    add(scene::makeBox({1.0f, 1.0f, 1.0f}, 0), {-3.0f, 0.5f, -12.0f});                    // stays behind
    scene::prepareScene(s);
    return s;
}

passes::GBufferSettings withCull(bool on) {
    passes::GBufferSettings settings;
    settings.occlusionCulling = on;
    return settings;
}

} // namespace

TEST_CASE("the Hi-Z's levels halve exactly from half the screen's power-of-two ceiling") {
    using namespace shader;
    CHECK(hizBaseSize(uvec2(1920, 1080)) == uvec2(1024, 1024));
    CHECK(hizBaseSize(uvec2(64, 64)) == uvec2(32, 32));
    CHECK(hizBaseSize(uvec2(1, 1)) == uvec2(1, 1));
    CHECK(hizLevelSize(uvec2(1024, 256), 9) == uvec2(2, 1));
    // Texels the screen reaches: level 0 of 1920 x 1080 is 960 x 540.
    CHECK(hizValidSize(uvec2(1920, 1080), 0) == uvec2(960, 540));
    CHECK(hizValidSize(uvec2(1920, 1080), 4) == uvec2(60, 34));
    // The finest level whose texels hold the rectangle in 2 x 2.
    CHECK(hizTestLevel(uvec2(0, 0), uvec2(3, 3), 10) == 0u);
    CHECK(hizTestLevel(uvec2(1, 1), uvec2(4, 4), 10) == 1u);
    CHECK(hizTestLevel(uvec2(0, 0), uvec2(1919, 1079), 10) == 9u);  // two 1,024-pixel texels
    CHECK(hizTestLevel(uvec2(1000, 0), uvec2(3100, 10), 10) == 10u);  // three of them: none
    CHECK(hizTestLevel(uvec2(1000, 0), uvec2(3100, 10), 11) == 10u);
}

TEST_CASE("instances behind a wall are not drawn, and the G-buffer is the same as without the cull") {
    test::GpuTest gpu;
    const scene::Scene scene = wallScene();
    REQUIRE(scene.instances.size() == kInstances);
    const scene::Camera camera = test::testCamera({0.0f, 1.0f, 0.0f});
    std::vector<uint32_t> first, second, steady;
    gbuffer_test::render(gpu, scene, {camera}, nullptr, withCull(true), &first);
    gbuffer_test::render(gpu, scene, {camera, camera}, nullptr, withCull(true), &second);
    passes::GBufferStats stats;
    const gbuffer_test::GBufferImage culled =
        gbuffer_test::render(gpu, scene, {camera, camera, camera}, &stats, withCull(true), &steady);
    const gbuffer_test::GBufferImage all = gbuffer_test::render(gpu, scene, {camera, camera, camera}, nullptr,
                                                                withCull(false));
    REQUIRE(first.size() == shader::kOcclusionStatWords);
    REQUIRE(second.size() == shader::kOcclusionStatWords);
    REQUIRE(steady.size() == shader::kOcclusionStatWords);
    // The first frame has no history: nothing is drawn early, so the
    // depth pyramid is empty and every instance is drawn late.
    CHECK(first[shader::kOcclusionStatEarly] == 0u);
    CHECK(first[shader::kOcclusionStatLate] == kInstances);
    CHECK(first[shader::kOcclusionStatOccluded] == 0u);
    // The second draws all five early; against their depth the two behind
    // the wall are found hidden, for the next frame.
    CHECK(second[shader::kOcclusionStatEarly] == kInstances);
    // From the third on, the three visible are drawn early, nothing is left
    // to add, and the two hidden are drawn in neither phase.
    CHECK(steady[shader::kOcclusionStatEarly] == 3u);
    CHECK(steady[shader::kOcclusionStatLate] == 0u);
    CHECK(steady[shader::kOcclusionStatOccluded] == 2u);
    // Recorded: every instance is in the frustum (one draw each).
    CHECK(stats.instancesCulled == 0u);
    CHECK(stats.draws == kInstances);
    // Two 12-triangle boxes are not drawn.
    CHECK(steady[shader::kOcclusionStatTriangles] == stats.triangles - 24u);
    gbuffer_test::checkSameTargets(culled, all);
}

TEST_CASE("a box that comes out from behind the wall is drawn the frame it does") {
    test::GpuTest gpu;
    const scene::Scene scene = wallScene();
    const scene::Camera before = test::testCamera({0.0f, 1.0f, 0.0f});
    const scene::Camera after = test::testCamera({4.0f, 1.0f, 0.0f});
    const std::vector<scene::Camera> path = {before, before, after};
    std::vector<uint32_t> counts;
    const gbuffer_test::GBufferImage culled = gbuffer_test::render(gpu, scene, path, nullptr, withCull(true), &counts);
    const gbuffer_test::GBufferImage all = gbuffer_test::render(gpu, scene, path, nullptr, withCull(false));
    REQUIRE(counts.size() == shader::kOcclusionStatWords);
    // Not visible last frame, so not drawn early: the late phase finds it.
    CHECK(counts[shader::kOcclusionStatLate] >= 1u);
    CHECK(counts[shader::kOcclusionStatOccluded] == kHiddenFromBoth);
    gbuffer_test::checkSameTargets(culled, all);
    // And it is there: the box's grey covers pixels the wall's edge no
    // longer hides (compared against a run without the box that comes out).
    scene::Scene without = scene;
    without.instances.erase(without.instances.begin() + 3);
    scene::prepareScene(without);
    const gbuffer_test::GBufferImage empty = gbuffer_test::render(gpu, without, path, nullptr, withCull(true));
    CHECK(culled.depth != empty.depth);
}

TEST_CASE("with one instance in view the cull does not run: nothing could hide behind it") {
    test::GpuTest gpu;
    scene::Scene scene = wallScene();
    scene.instances.resize(2);  // the floor and the wall
    scene::prepareScene(scene);
    std::vector<uint32_t> counts;
    // Looking 45 degrees up from 3 m, only the wall's top is in view.
    scene::Camera camera = test::testCamera({0.0f, 3.0f, 0.0f});
    camera.reset({{0.0f, 3.0f, 0.0f}, {0.0f, 4.0f, -1.0f}, {0, 1, 0}}, 0);
    passes::GBufferStats stats;
    gbuffer_test::render(gpu, scene, {camera, camera}, &stats, withCull(true), &counts);
    CHECK(stats.instancesCulled == 1u);
    CHECK(counts.empty());
    // Both in view: it runs.
    gbuffer_test::render(gpu, scene, {test::testCamera({0.0f, 1.0f, 0.0f})}, &stats, withCull(true), &counts);
    CHECK(stats.instancesCulled == 0u);
    CHECK(counts.size() == shader::kOcclusionStatWords);
}

TEST_CASE("draws in runs of several chunks: each chunk keeps its drawn commands, in order") {
    // Behind the wall's scene, a 40 x 20 grid of small boxes, every other
    // one red and double-sided (another state: albedo is per vertex, the
    // facing is not), every seventh mirrored: four runs, two of them longer
    // than a chunk, so the cull pads and compacts runs over chunk
    // boundaries. Some boxes stand behind the wall.
    test::GpuTest gpu;
    scene::Scene scene = wallScene();
    scene::Material red = scene.materials[0];
    red.baseColorFactor = glm::vec4(0.8f, 0.1f, 0.1f, 1.0f);
    red.doubleSided = true;
    scene.materials.push_back(red);
    for (uint32_t material = 0; material < 2; ++material) {
        scene::Mesh mesh;
        mesh.name = "small" + std::to_string(material);
        mesh.lods.push_back({{scene::makeBox({0.15f, 0.15f, 0.15f}, material)}});
        scene.meshes.push_back(std::move(mesh));
    }
    const uint32_t firstSmall = uint32_t(scene.meshes.size() - 2);
    uint32_t boxes = 0;
    for (uint32_t row = 0; row < 20; ++row) {
        for (uint32_t column = 0; column < 40; ++column, ++boxes) {
            scene::Instance inst;
            inst.mesh = firstSmall + (boxes % 2);
            glm::mat4 t = glm::translate(glm::mat4(1.0f), {-3.0f + 0.15f * float(column), 0.1f, -2.5f - 0.5f * float(row)});
            if (boxes % 7 == 0) t = glm::scale(t, {-1.0f, 1.0f, 1.0f});
            inst.transform = inst.previousTransform = t;
            scene.instances.push_back(inst);
        }
    }
    scene::prepareScene(scene);
    const scene::Camera camera = test::testCamera({0.0f, 1.0f, 0.0f});
    const std::vector<scene::Camera> path(3, camera);
    passes::GBufferStats stats;
    std::vector<uint32_t> counts;
    const gbuffer_test::GBufferImage culled = gbuffer_test::render(gpu, scene, path, &stats, withCull(true), &counts);
    const gbuffer_test::GBufferImage all = gbuffer_test::render(gpu, scene, path, nullptr, withCull(false));
    REQUIRE(counts.size() == shader::kOcclusionStatWords);
    // Grey and red, each mirrored or not (the wall's scene is grey).
    CHECK(stats.runs == 4u);
    const uint32_t inView = stats.draws;  // one draw per instance
    CHECK(inView > 2 * shader::kOcclusionGroupSize);
    CHECK(counts[shader::kOcclusionStatOccluded] > 0u);
    CHECK(counts[shader::kOcclusionStatEarly] + counts[shader::kOcclusionStatLate] +
              counts[shader::kOcclusionStatOccluded] ==
          inView);
    gbuffer_test::checkSameTargets(culled, all);
}
