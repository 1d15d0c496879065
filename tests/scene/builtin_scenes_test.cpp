#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/error.h"

#include "scene_test_support.h"

#include <algorithm>
#include <set>

using namespace glint::scene;

namespace {

size_t countInstances(const Scene& s, Motion motion) {
    return size_t(
        std::count_if(s.instances.begin(), s.instances.end(), [&](const Instance& i) { return i.motion == motion; }));
}

// Closest distance from any camera-path position to the instance bounds.
float closestApproach(const Scene& s, const Instance& inst) {
    float best = std::numeric_limits<float>::infinity();
    for (uint32_t f = 0; f < 200; ++f) {
        best = std::min(best, distanceToBounds(instanceBounds(s, inst), s.cameraPath.atFrame(f, 200).position));
    }
    return best;
}

uint64_t positionHash(const Scene& s) {
    uint64_t h = 1469598103934665603ull;
    for (const Mesh& m : s.meshes) {
        for (const MeshLod& lod : m.lods) {
            for (const Geometry& g : lod.geometries) {
                for (const glm::vec3& p : g.positions) {
                    for (int k = 0; k < 3; ++k) {
                        uint32_t bits;
                        std::memcpy(&bits, &p[k], 4);
                        h = (h ^ bits) * 1099511628211ull;
                    }
                }
            }
        }
    }
    return h;
}

} // namespace

TEST_CASE("plaza has the mix the reflections demo needs") {
    const Scene s = makePlaza();
    validateScene(s);
    MESSAGE("plaza: " << meshTriangleCount(s) << " triangles in " << s.meshes.size() << " meshes, "
                      << instancedTriangleCount(s) << " drawn by " << s.instances.size() << " instances");
    // Modest for lavapipe (~1 Mray/s), yet not a toy.
    CHECK(instancedTriangleCount(s) >= 10000);
    CHECK(instancedTriangleCount(s) <= 80000);

    CHECK(countInstances(s, Motion::Static) > 20);
    CHECK(countInstances(s, Motion::Dynamic) >= 3);
    // More skinned objects than the 12-per-frame budget, so the cap matters.
    CHECK(countInstances(s, Motion::Skinned) > 12);
    CHECK(std::count_if(s.instances.begin(), s.instances.end(), [](const Instance& i) { return i.firstPerson; }) == 1);
    CHECK(std::count_if(s.instances.begin(), s.instances.end(), [](const Instance& i) { return i.longRange; }) > 0);
    CHECK_FALSE(s.particles.empty());

    // Near and far: objects within a few metres of the path and objects that
    // never come within the 100 m BVH radius.
    size_t near = 0, far = 0;
    for (const Instance& inst : s.instances) {
        if (inst.longRange || inst.firstPerson) {
            continue;
        }
        const float d = closestApproach(s, inst);
        near += d < 5.0f ? 1 : 0;
        far += d > 100.0f ? 1 : 0;
    }
    CHECK(near >= 3);
    CHECK(far >= 2);

    // Mirror-like and rough, metal and dielectric.
    const auto has = [&](auto predicate) { return std::any_of(s.materials.begin(), s.materials.end(), predicate); };
    CHECK(has([](const Material& m) { return m.metallicFactor == 1.0f && m.roughnessFactor <= 0.05f; }));
    CHECK(has([](const Material& m) { return m.metallicFactor == 0.0f && m.roughnessFactor <= 0.05f; }));
    CHECK(has([](const Material& m) { return m.metallicFactor == 0.0f && m.roughnessFactor >= 0.85f; }));
    CHECK(has([](const Material& m) { return m.emissiveStrength > 1.0f; }));

    // The puddle mask: the paving's roughness texture holds both mirror-like
    // puddles and rough dry stone.
    const auto paving = std::find_if(s.materials.begin(), s.materials.end(),
                                     [](const Material& m) { return m.metallicRoughnessTexture.valid(); });
    REQUIRE(paving != s.materials.end());
    const Texture& mr = s.textures[size_t(paving->metallicRoughnessTexture.texture)];
    size_t wet = 0, dry = 0;
    for (uint32_t y = 0; y < mr.height; ++y) {
        for (uint32_t x = 0; x < mr.width; ++x) {
            const float roughness = mr.texel(x, y).g;
            wet += roughness < 0.06f ? 1 : 0;
            dry += roughness > 0.4f ? 1 : 0;
        }
    }
    CHECK(wet > mr.width * mr.height / 20);
    CHECK(dry > mr.width * mr.height / 4);

    // Reflection LODs exist for the big meshes.
    CHECK(std::any_of(s.meshes.begin(), s.meshes.end(), [](const Mesh& m) { return m.lods.size() > 1; }));
    CHECK(s.cameraPath.duration() > 10.0f);
    CHECK(s.cameraNode != kNone);
}

TEST_CASE("plaza animates: rigid objects move without deforming, skinned ones deform, the arm follows the camera") {
    Scene s = makePlaza();
    std::vector<glm::mat4> start;
    for (const Instance& inst : s.instances) {
        start.push_back(inst.transform);
    }
    Camera camera;
    camera.reset(s.cameraPath.evaluate(0.0f), 0);
    for (int frame = 1; frame <= 30; ++frame) {
        const float t = float(frame) / 30.0f;
        camera.advance(s.cameraPath.evaluate(t), uint64_t(frame));
        advanceScene(s, t, &camera);
    }
    for (size_t i = 0; i < s.instances.size(); ++i) {
        const Instance& inst = s.instances[i];
        INFO(inst.name);
        switch (inst.motion) {
        case Motion::Static: CHECK(inst.transform == start[i]); break;
        case Motion::Dynamic:
            CHECK(inst.transform != start[i]);
            CHECK(inst.deformVersion == 0);
            break;
        case Motion::Skinned:
            CHECK(inst.deformVersion == 30);  // every frame of the second deformed it
            break;
        }
        if (inst.firstPerson) {
            // Hanging below the camera node: camera space stays put.
            const glm::mat4 inCamera = camera.view * inst.transform;
            const glm::vec3 offset(inCamera[3]);
            CHECK(offset.z < 0.0f);  // in front of the camera
            CHECK(glm::length(offset) < 1.0f);
        }
    }
}

TEST_CASE("hard-cases sits 10^4 m out with thin walls, degenerate triangles and a huge depth range") {
    const Scene s = makeHardCases();
    validateScene(s);
    MESSAGE("hard-cases: " << meshTriangleCount(s) << " triangles in " << s.meshes.size() << " meshes, "
                           << instancedTriangleCount(s) << " drawn by " << s.instances.size() << " instances");
    CHECK(s.lens.nearPlane == doctest::Approx(0.01f));
    CHECK(std::isinf(s.lens.farPlane));
    const glm::vec3 camera = s.cameraPath.evaluate(0.0f).position;
    CHECK(glm::length(camera) > 1.0e4f);
    float thinnest = std::numeric_limits<float>::infinity();
    float nearest = std::numeric_limits<float>::infinity();
    float farthest = 0.0f;
    size_t degenerate = 0;
    for (const Instance& inst : s.instances) {
        const Aabb b = instanceBounds(s, inst);
        const glm::vec3 size = b.size();
        thinnest = std::min(thinnest, std::min({size.x, size.y, size.z}));
        nearest = std::min(nearest, distanceToBounds(b, camera));
        farthest = std::max(farthest, glm::length(b.center() - camera));
    }
    for (const Mesh& m : s.meshes) {
        for (const Geometry& g : m.lods[0].geometries) {
            for (uint32_t t = 0; t < g.triangleCount(); ++t) {
                const glm::vec3 a = g.positions[g.indices[3 * t]], b = g.positions[g.indices[3 * t + 1]],
                                c = g.positions[g.indices[3 * t + 2]];
                degenerate += glm::length(glm::cross(b - a, c - a)) == 0.0f ? 1 : 0;
            }
        }
    }
    CHECK(thinnest <= 0.002f + 1e-6f);
    CHECK(nearest < 0.05f);
    CHECK(farthest > 8000.0f);
    CHECK(degenerate >= 3);
    CHECK(std::any_of(s.materials.begin(), s.materials.end(),
                      [](const Material& m) { return m.roughnessFactor == 0.0f; }));
    CHECK(std::any_of(s.materials.begin(), s.materials.end(),
                      [](const Material& m) { return m.roughnessFactor == 1.0f; }));
}

TEST_CASE("built-in scenes name their camera presets") {
    const Scene plaza = makePlaza();
    for (const char* name : {"entrance", "puddles", "street", "far-buildings", "puddle-low"}) {
        CAPTURE(name);
        const SceneView& v = findView(plaza, name);
        CHECK(glm::length(v.target - v.position) > 0.1f);
        CHECK(v.lens.verticalFovRadians == plaza.lens.verticalFovRadians);
    }
    // The "puddles" preset is the path at 3 s, glint-render's default view.
    CHECK(glm::length(findView(plaza, "puddles").position - plaza.cameraPath.evaluate(3.0f).position) < 1e-6f);
    const Scene hard = makeHardCases();
    CHECK(findView(hard, "grazing-floor").position.x > 9000.0f);
    CHECK_THROWS_AS(findView(hard, "99"), SceneError);
}

TEST_CASE("built-in scenes are the same on every build") {
    CHECK(positionHash(makePlaza()) == positionHash(makePlaza()));
    CHECK(positionHash(makeHardCases()) == positionHash(makeHardCases()));
    CHECK(builtinSceneNames().size() == 4);
    CHECK(isBuiltinScene(kDefaultSceneName));
    try {
        makeBuiltinScene("atrium");
        FAIL("unknown built-in scene accepted");
    } catch (const SceneError& e) {
        CHECK(std::string(e.what()).find("atrium") != std::string::npos);
    }
}
