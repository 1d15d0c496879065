#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/gltf_loader.h"

#include "scene_test_support.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

using namespace glint::scene;
using glint::test::GltfFixture;

namespace {

glm::vec4 quatVec(const glm::quat& q) {
    return {q.x, q.y, q.z, q.w};
}

bool near(const glm::mat4& a, const glm::mat4& b, float eps = 1e-5f) {
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
            if (std::abs(a[c][r] - b[c][r]) > eps) {
                return false;
            }
        }
    }
    return true;
}

} // namespace

TEST_CASE("linear animation interpolates between keys and clamps outside them") {
    AnimationSampler s;
    s.interpolation = Interpolation::Linear;
    s.times = {0.0f, 1.0f, 3.0f};
    s.values = {{0, 0, 0, 0}, {2, 0, 0, 0}, {2, 4, 0, 0}};
    CHECK(sampleAnimation(s, AnimationPath::Translation, 0.5f).x == doctest::Approx(1.0f));
    CHECK(sampleAnimation(s, AnimationPath::Translation, 2.0f).y == doctest::Approx(2.0f));
    CHECK(sampleAnimation(s, AnimationPath::Translation, -1.0f) == s.values[0]);
    CHECK(sampleAnimation(s, AnimationPath::Translation, 10.0f) == s.values[2]);
    CHECK(sampleAnimation(s, AnimationPath::Translation, std::nanf("")) == s.values[0]);
}

TEST_CASE("step animation holds each key until the next") {
    AnimationSampler s;
    s.interpolation = Interpolation::Step;
    s.times = {0.0f, 1.0f, 2.0f};
    s.values = {{1, 1, 1, 0}, {2, 2, 2, 0}, {3, 3, 3, 0}};
    CHECK(sampleAnimation(s, AnimationPath::Scale, 0.99f).x == 1.0f);
    CHECK(sampleAnimation(s, AnimationPath::Scale, 1.0f).x == 2.0f);
    CHECK(sampleAnimation(s, AnimationPath::Scale, 1.5f).x == 2.0f);
}

TEST_CASE("rotations slerp along the shorter arc") {
    AnimationSampler s;
    s.times = {0.0f, 1.0f};
    const glm::quat quarter = glm::angleAxis(glm::half_pi<float>(), glm::vec3(0, 1, 0));
    // The same end rotation stored with the opposite sign: interpolating the
    // raw components would swing the long way round.
    s.values = {quatVec(glm::quat(1, 0, 0, 0)), quatVec(-quarter)};
    const glm::vec4 v = sampleAnimation(s, AnimationPath::Rotation, 0.5f);
    const glm::quat q(v.w, v.x, v.y, v.z);
    CHECK(std::abs(glm::length(v) - 1.0f) < 1e-5f);
    const glm::vec3 x = q * glm::vec3(1, 0, 0);
    const glm::vec3 expected = glm::angleAxis(glm::quarter_pi<float>(), glm::vec3(0, 1, 0)) * glm::vec3(1, 0, 0);
    CHECK(glm::length(x - expected) < 1e-4f);
}

TEST_CASE("cubic spline animation follows the Hermite basis with tangents scaled by the key interval") {
    AnimationSampler s;
    s.interpolation = Interpolation::CubicSpline;
    s.times = {1.0f, 3.0f};
    // in-tangent, value, out-tangent per key
    s.values = {{9, 9, 9, 0}, {1, 0, 0, 0}, {0.5f, 0, 0, 0}, {-1, 0, 0, 0}, {4, 0, 0, 0}, {9, 9, 9, 0}};
    const float dt = 2.0f;
    for (float t : {1.0f, 1.5f, 2.0f, 2.7f, 3.0f}) {
        const float u = (t - 1.0f) / dt;
        const float u2 = u * u, u3 = u2 * u;
        const float expected = (2 * u3 - 3 * u2 + 1) * 1.0f + (u3 - 2 * u2 + u) * dt * 0.5f +
                               (-2 * u3 + 3 * u2) * 4.0f + (u3 - u2) * dt * -1.0f;
        CHECK(sampleAnimation(s, AnimationPath::Translation, t).x == doctest::Approx(expected));
    }
}

TEST_CASE("world transforms compose parents before children whatever the node order") {
    std::vector<Node> nodes(3);
    nodes[0].parent = 2;
    nodes[0].translation = {0, 0, 1};
    nodes[2].parent = 1;
    nodes[2].rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(0, 1, 0));
    nodes[1].translation = {5, 0, 0};
    const std::vector<glm::mat4> world = worldTransforms(nodes);
    const glm::vec3 origin0 = glm::vec3(world[0][3]);
    CHECK(glm::length(origin0 - glm::vec3(6, 0, 0)) < 1e-5f);  // (0,0,1) turned 90 degrees about Y is (1,0,0)
}

TEST_CASE("a parent cycle is an error, not a hang") {
    std::vector<Node> nodes(3);
    nodes[0].parent = 1;
    nodes[1].parent = 2;
    nodes[2].parent = 0;
    CHECK_THROWS_AS(worldTransforms(nodes), SceneError);
}

TEST_CASE("joint matrices are identity at rest, follow the joints, and bump deformVersion only when they change") {
    Scene scene;
    scene.name = "skin test";
    scene.materials.emplace_back();
    Geometry g;
    g.positions = {{0, 0, 0}, {0, 1, 0}, {0.1f, 2, 0}};
    g.normals.assign(3, {0, 0, 1});
    g.joints = {{0, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}};
    g.weights.assign(3, {1, 0, 0, 0});
    g.indices = {0, 1, 2};
    Mesh mesh;
    mesh.lods.push_back({{g}});
    scene.meshes.push_back(mesh);
    scene.nodes.resize(3);
    scene.nodes[0].translation = {10, 0, 0};  // the instance node
    scene.nodes[1].parent = 0;                // joint 0 at the instance origin
    scene.nodes[2].parent = 1;
    scene.nodes[2].translation = {0, 1, 0};  // joint 1, 1 m up
    Skin skin;
    skin.joints = {1, 2};
    skin.inverseBindMatrices = {glm::mat4(1.0f), glm::translate(glm::mat4(1.0f), {0, -1, 0})};
    scene.skins.push_back(skin);
    Instance inst;
    inst.mesh = 0;
    inst.node = 0;
    inst.skin = 0;
    inst.motion = Motion::Skinned;
    scene.instances.push_back(inst);
    Animation bend;
    AnimationSampler sampler;
    sampler.times = {0.0f, 1.0f};
    sampler.values = {quatVec(glm::quat(1, 0, 0, 0)),
                      quatVec(glm::angleAxis(glm::half_pi<float>(), glm::vec3(0, 0, 1)))};
    bend.samplers.push_back(sampler);
    bend.channels.push_back({0, 2, AnimationPath::Rotation});
    scene.animations.push_back(bend);
    scene.playbacks.push_back({0, 1.0f, false});

    prepareScene(scene);
    REQUIRE(scene.jointMatrices.size() == 2);
    CHECK(near(scene.jointMatrices[0], glm::mat4(1.0f)));
    CHECK(near(scene.jointMatrices[1], glm::mat4(1.0f)));
    CHECK(scene.instances[0].deformVersion == 0);
    CHECK(glm::vec3(scene.instances[0].transform[3]) == glm::vec3(10, 0, 0));

    advanceScene(scene, 1.0);
    // Joint 1 turned 90 degrees about Z around its position (0, 1, 0):
    // the vertex at (0.1, 2, 0) goes to (-1, 1.1, 0), in object space.
    const glm::vec3 moved = glm::vec3(scene.jointMatrices[1] * glm::vec4(0.1f, 2, 0, 1));
    CHECK(glm::length(moved - glm::vec3(-1.0f, 1.1f, 0.0f)) < 1e-5f);
    CHECK(near(scene.previousJointMatrices[1], glm::mat4(1.0f)));
    CHECK(scene.instances[0].deformVersion == 1);
    // Past the last key, the pose holds: no deformation, no new version.
    advanceScene(scene, 2.0);
    CHECK(scene.instances[0].deformVersion == 1);
    // Bounds of a skinned instance cover the bent pose.
    const Aabb bounds = instanceBounds(scene, scene.instances[0]);
    CHECK(bounds.min.x <= 10.0f - 1.0f + 1e-4f);
}

TEST_CASE("glTF animations and skins load and evaluate at known times") {
    GltfFixture f;
    // A 2-joint skinned triangle strip standing on node 1 (the skin root).
    const int positions = f.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3", 3);
    const int joints =
        f.accessor(std::vector<uint8_t>{0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, 5121, "VEC4", 4);
    const int weights = f.floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4", 4);
    const int ibm = f.floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,  //
                              1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                             "MAT4", 16);
    const int times = f.floats({0, 2}, "SCALAR", 1);
    const int moves = f.floats({0, 0, 0, 2, 0, 0}, "VEC3", 3);
    const int stepTimes = f.floats({0, 1, 2}, "SCALAR", 1);
    const float s = std::sqrt(0.5f);
    const int turns = f.floats({0, 0, 0, 1, 0, s, 0, s, 0, 1, 0, 0}, "VEC4", 4);
    const int cubicTimes = f.floats({0, 1}, "SCALAR", 1);
    const int cubicScale = f.floats({0, 0, 0, 1, 1, 1, 0, 0, 0, /**/ 0, 0, 0, 3, 3, 3, 0, 0, 0}, "VEC3", 3);
    f.doc["meshes"] = {
        {{"name", "strip"},
         {"primitives",
          {{{"attributes", {{"POSITION", positions}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}}, {"mode", 5}}}}}};
    f.doc["nodes"] = {
        {{"name", "mover"}, {"children", {1, 4}}},
        {{"name", "skinned"}, {"mesh", 0}, {"skin", 0}, {"children", {2}}},
        {{"name", "joint0"}, {"children", {3}}},
        {{"name", "joint1"}, {"translation", {0, 1, 0}}},
        {{"name", "scaled"}, {"mesh", 0}, {"translation", {5, 0, 0}}},
    };
    f.doc["skins"] = {{{"joints", {2, 3}}, {"inverseBindMatrices", ibm}}};
    f.doc["animations"] = {{{"name", "all"},
                            {"samplers",
                             {{{"input", times}, {"output", moves}, {"interpolation", "LINEAR"}},
                              {{"input", stepTimes}, {"output", turns}, {"interpolation", "STEP"}},
                              {{"input", cubicTimes}, {"output", cubicScale}, {"interpolation", "CUBICSPLINE"}}}},
                            {"channels",
                             {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}},
                              {{"sampler", 1}, {"target", {{"node", 3}, {"path", "rotation"}}}},
                              {{"sampler", 2}, {"target", {{"node", 4}, {"path", "scale"}}}}}}}};
    f.doc["scenes"] = {{{"nodes", {0}}}};
    f.doc["scene"] = 0;
    const auto dir = glint::test::outputDir("animation");
    glint::test::writeText(dir / "animated.gltf", f.text());

    Scene scene = loadGltf(dir / "animated.gltf");
    REQUIRE(scene.instances.size() == 2);
    REQUIRE(scene.animations.size() == 1);
    CHECK(scene.meshes[0].lods[0].geometries[0].triangleCount() == 2);  // the strip became a list
    const Instance& skinned = scene.instances[0];
    const Instance& scaled = scene.instances[1];
    CHECK(skinned.motion == Motion::Skinned);
    CHECK(scaled.motion == Motion::Dynamic);  // below the animated "mover"

    advanceScene(scene, 1.0);
    CHECK(glm::length(glm::vec3(scene.instances[0].transform[3]) - glm::vec3(1, 0, 0)) < 1e-5f);
    // joint1 rotation: STEP at t = 1 holds key 1, 90 degrees about Y.
    const glm::quat q = scene.nodes[3].rotation;
    CHECK(std::abs(std::abs(q.y) - s) < 1e-5f);
    CHECK(std::abs(std::abs(q.w) - s) < 1e-5f);
    // Cubic spline with zero tangents at its last key: the value exactly.
    CHECK(scene.nodes[4].scale.x == doctest::Approx(3.0f));
    advanceScene(scene, 0.5 + 2.0);  // loops: t = 0.5 into the 2 s animation
    CHECK(scene.nodes[0].translation.x == doctest::Approx(0.5f));
    // Hermite at u = 0.5 with zero tangents: halfway between 1 and 3.
    CHECK(scene.nodes[4].scale.y == doctest::Approx(2.0f));
    CHECK(scene.instances[0].deformVersion >= 1);
}
