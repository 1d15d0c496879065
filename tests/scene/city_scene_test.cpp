#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/error.h"

#include "scene_test_support.h"

#include <algorithm>
#include <set>
#include <string>

using namespace glint::scene;

namespace {

// A small city keeps these fast: the layout does not depend on the detail.
constexpr std::string_view kSmall = "city:instances=16,triangles=2000";

size_t buildings(const Scene& s) {
    return size_t(std::count_if(s.instances.begin(), s.instances.end(),
                                [](const Instance& i) { return i.name.rfind("building ", 0) == 0; }));
}

std::string errorOf(std::string_view spec) {
    try {
        makeBuiltinScene(spec);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST_CASE("city options parse, and bad ones are refused naming the key") {
    const CityOptions defaults = parseCityOptions("city");
    CHECK(defaults.instances == CityOptions{}.instances);
    const CityOptions o = parseCityOptions("city:instances=256,triangles=5000,seed=7");
    CHECK(o.instances == 256);
    CHECK(o.triangles == 5000);
    CHECK(o.seed == 7);
    CHECK(isBuiltinScene("city:instances=16"));
    CHECK(errorOf("city:instances=8").find("instances") != std::string::npos);
    CHECK(errorOf("city:instances=5000").find("4096") != std::string::npos);
    CHECK(errorOf("city:instances=12x").find("12x") != std::string::npos);
    CHECK(errorOf("city:lanes=3").find("lanes") != std::string::npos);
    CHECK(errorOf("city:instances").find("KEY=VALUE") != std::string::npos);
    CHECK(errorOf("city:triangles=10").find("triangles") != std::string::npos);
}

TEST_CASE("the city has as many buildings as asked, of several kinds, and grows along and across streets") {
    const Scene small = makeBuiltinScene(kSmall);
    CHECK(buildings(small) == 16);
    std::set<uint32_t> kinds;
    for (const Instance& i : small.instances) {
        if (i.name.rfind("building ", 0) == 0) kinds.insert(i.mesh);
    }
    CHECK(kinds.size() >= 3);
    validateScene(small);

    const Scene large = makeBuiltinScene("city:instances=256,triangles=2000");
    CHECK(buildings(large) == 256);
    const auto buildingBounds = [](const Scene& scene) {
        Aabb box;
        for (const Instance& i : scene.instances) {
            if (i.name.rfind("building ", 0) == 0) box.extend(instanceBounds(scene, i));
        }
        return box;
    };
    const Aabb a = buildingBounds(small), b = buildingBounds(large);
    // Not one longer street: more streets side by side as well.
    CHECK(b.size().x > 2.0f * a.size().x);
    CHECK(b.size().z > a.size().z);
    // Cars and lamps come with the size; the buildings dominate the triangles.
    CHECK(instancedTriangleCount(large) > 10 * instancedTriangleCount(small) / 2);
}

TEST_CASE("the city's buildings are tessellated to the triangle budget, the reflection LOD coarser") {
    const Scene coarse = makeBuiltinScene("city:instances=16,triangles=2000");
    const Scene fine = makeBuiltinScene("city:instances=16,triangles=60000");
    uint32_t checked = 0;
    for (size_t m = 0; m < fine.meshes.size(); ++m) {
        const Mesh& mesh = fine.meshes[m];
        if (mesh.lods.size() != 2) continue;  // the building kinds have two LODs
        ++checked;
        const uint64_t lod0 = triangleCount(mesh.lods[0]);
        CAPTURE(mesh.name);
        CHECK(lod0 <= 60000 + 2000);  // facade cells within the budget; trim and roof on top
        CHECK(lod0 > 60000 / 3);
        CHECK(triangleCount(mesh.lods[1]) < lod0 / 2);
        CHECK(reflectionLodIndex(mesh) == 1);
        // (A kind's coarsest tessellation, one quad per panel, can exceed a small budget.)
        CHECK(triangleCount(coarse.meshes[m].lods[0]) < lod0 / 2);
    }
    CHECK(checked == 6);
    // The default is a large scene: about 2.0 million instanced triangles.
    const Scene standard = makeCity();
    CHECK(instancedTriangleCount(standard) > 1'500'000);
    CHECK(instancedTriangleCount(standard) < 4'000'000);
}

TEST_CASE("the city's street is wet and its traffic moves rigidly along the streets") {
    Scene s = makeBuiltinScene(kSmall);
    // Mirror-smooth puddles in the road's roughness texture, glossy asphalt around them.
    const auto road = std::find_if(s.materials.begin(), s.materials.end(),
                                   [](const Material& m) { return m.name == "wet asphalt"; });
    REQUIRE(road != s.materials.end());
    const Texture& roughness = s.textures.at(size_t(road->metallicRoughnessTexture.texture));
    float lowest = 1.0f;
    uint32_t glossy = 0, all = 0;
    for (uint32_t y = 0; y < roughness.height; y += 3) {
        for (uint32_t x = 0; x < roughness.width; x += 3) {
            const float r = roughness.texel(x, y).g;
            lowest = std::min(lowest, r);
            glossy += r < 0.22f ? 1u : 0u;  // traced at the default roughness cutoff
            ++all;
        }
    }
    CHECK(lowest < 0.05f);
    CHECK(glossy > all * 95 / 100);  // all but the lane markings
    // Mirror glass on some facades: what is behind the camera shows there.
    CHECK(std::any_of(s.materials.begin(), s.materials.end(),
                      [](const Material& m) { return m.metallicFactor == 1.0f && m.roughnessFactor < 0.05f; }));

    std::vector<glm::vec3> start;
    for (const Instance& i : s.instances) start.push_back(glm::vec3(i.transform[3]));
    advanceScene(s, 0.5f);
    size_t moved = 0;
    for (size_t i = 0; i < s.instances.size(); ++i) {
        const Instance& inst = s.instances[i];
        const glm::vec3 now(inst.transform[3]);
        if (inst.motion == Motion::Static) {
            CHECK(now == start[i]);
            continue;
        }
        ++moved;
        CHECK(inst.deformVersion == 0);
        // Half a second at 9 m/s, along Z only.
        CHECK(std::abs(now.x - start[i].x) < 1e-3f);
        CHECK(std::abs(std::abs(now.z - start[i].z) - 4.5f) < 0.1f);
    }
    CHECK(moved >= 4);
}

TEST_CASE("the city's camera path stays in the main street, and the same options give the same city") {
    const Scene s = makeBuiltinScene(kSmall);
    for (uint32_t f = 0; f < 100; ++f) {
        const CameraPose pose = s.cameraPath.atFrame(f, 100);
        CHECK(std::abs(pose.position.x) < 5.0f);  // the road is 10 m wide
        CHECK(pose.position.y > 1.0f);
    }
    for (const char* view : {"down-street", "facades", "puddles", "overlook"}) {
        CHECK_NOTHROW(findView(s, view));
    }
    const Scene again = makeBuiltinScene(kSmall);
    REQUIRE(again.instances.size() == s.instances.size());
    for (size_t i = 0; i < s.instances.size(); ++i) {
        CHECK(again.instances[i].mesh == s.instances[i].mesh);
    }
    const Scene other = makeBuiltinScene("city:instances=16,triangles=2000,seed=2");
    bool differs = false;
    for (size_t i = 0; i < std::min(other.instances.size(), s.instances.size()); ++i) {
        differs = differs || other.instances[i].mesh != s.instances[i].mesh;
    }
    CHECK(differs);
}
