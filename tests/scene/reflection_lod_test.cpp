// Reflection LODs generated for loaded meshes (scene/reflection_lod.h):
// fewer triangles within the error bound, the kept vertices' attributes
// exactly the full-detail mesh's, seams and small meshes left alone, and
// the BVH planner building from them (or from full detail when told to).

#include "glint/scene/bvh_planner.h"
#include "glint/scene/gltf_loader.h"
#include "glint/scene/procedural_meshes.h"
#include "glint/scene/reflection_lod.h"

#include "scene_test_support.h"

#include <doctest/doctest.h>

#include <glm/glm.hpp>

#include <cmath>
#include <map>
#include <tuple>

using namespace glint::scene;

namespace {

// A vertex's attributes as a comparable key.
using VertexKey = std::tuple<float, float, float, float, float, float, float, float>;
VertexKey keyOf(const Geometry& g, uint32_t v) {
    return {g.positions[v].x, g.positions[v].y, g.positions[v].z, g.normals[v].x,
            g.normals[v].y,   g.normals[v].z,   g.texcoords0[v].x, g.texcoords0[v].y};
}

} // namespace

TEST_CASE("a sphere of 32k triangles simplifies to about a quarter within 1% of its size, its vertices the "
          "original ones with their attributes") {
    const float radius = 1.0f;
    const Geometry sphere = makeSphere(radius, 128, 128, 0);
    REQUIRE(sphere.triangleCount() > 30000u);
    ReflectionLodSettings settings;
    float error = 0.0f;
    const Geometry lod = simplifyGeometry(sphere, settings, &error);
    CAPTURE(lod.triangleCount());
    CAPTURE(error);
    CHECK(lod.triangleCount() <= sphere.triangleCount() / 4 + 16);
    CHECK(lod.triangleCount() >= sphere.triangleCount() / 8);
    CHECK(error <= settings.maxError);
    // Only vertices a triangle uses, every one of them an original vertex
    // with every attribute as it was.
    std::map<VertexKey, int> original;
    for (uint32_t v = 0; v < sphere.vertexCount(); ++v) original[keyOf(sphere, v)] = 1;
    std::vector<bool> used(lod.vertexCount(), false);
    for (const uint32_t i : lod.indices) {
        REQUIRE(i < lod.vertexCount());
        used[i] = true;
    }
    for (uint32_t v = 0; v < lod.vertexCount(); ++v) {
        CHECK(used[v]);
        CHECK(original.count(keyOf(lod, v)) == 1u);
    }
    CHECK(lod.tangents.size() == lod.vertexCount());
    // Its surface stays within the bound: triangle centroids lie within 1%
    // of the 2 m diameter of the sphere (its chords are inside it).
    float deepest = 0.0f;
    for (uint32_t t = 0; t < lod.triangleCount(); ++t) {
        const glm::vec3 c = (lod.positions[lod.indices[3 * t]] + lod.positions[lod.indices[3 * t + 1]] +
                             lod.positions[lod.indices[3 * t + 2]]) /
                            3.0f;
        deepest = std::max(deepest, radius - glm::length(c));
    }
    CAPTURE(deepest);
    CHECK(deepest <= 0.01f * 2.0f * radius);
    CHECK(lod.bounds.max.x <= sphere.bounds.max.x);
}

TEST_CASE("reflection LODs go to meshes with one LOD; small geometries, authored LODs and explicit choices stay") {
    Scene s;
    s.name = "lod test";
    s.materials.resize(2);
    Mesh big;
    big.name = "big";
    big.lods.push_back({{makeSphere(1.0f, 64, 64, 0), makeBox(glm::vec3(1.0f), 1)}});
    Mesh small;
    small.name = "small";
    small.lods.push_back({{makeBox(glm::vec3(1.0f), 0)}});
    Mesh authored;
    authored.name = "authored";
    authored.lods.push_back({{makeSphere(1.0f, 64, 64, 0)}});
    authored.lods.push_back({{makeSphere(1.0f, 8, 8, 0)}});
    Mesh pinned;
    pinned.name = "pinned";
    pinned.lods.push_back({{makeSphere(1.0f, 64, 64, 0)}});
    pinned.reflectionLod = 0;
    s.meshes = {big, small, authored, pinned};
    const ReflectionLodStats stats = generateReflectionLods(s);
    CHECK(stats.meshes == 1u);
    REQUIRE(s.meshes[0].lods.size() == 2u);
    // The sphere simplified, the box (12 triangles) copied as it is.
    CHECK(s.meshes[0].lods[1].geometries[0].triangleCount() < s.meshes[0].lods[0].geometries[0].triangleCount() / 2);
    CHECK(s.meshes[0].lods[1].geometries[1].indices == s.meshes[0].lods[0].geometries[1].indices);
    CHECK(s.meshes[0].lods[1].geometries[1].material == 1u);
    CHECK(reflectionLodIndex(s.meshes[0]) == 1u);
    CHECK(s.meshes[1].lods.size() == 1u);
    CHECK(s.meshes[2].lods.size() == 2u);
    CHECK(s.meshes[2].lods[1].geometries[0].triangleCount() == authored.lods[1].geometries[0].triangleCount());
    CHECK(s.meshes[3].lods.size() == 1u);
    CHECK(stats.trianglesAfter < stats.trianglesBefore);
    CHECK_THROWS_AS(generateReflectionLods(s, {0.0f, 0.01f, 256}), std::invalid_argument);
    CHECK_THROWS_AS(generateReflectionLods(s, {0.5f, 2.0f, 256}), std::invalid_argument);
}

TEST_CASE("a loaded glTF mesh gets a reflection LOD the BVH builds from; with the option unset, or the planner told "
          "so, full detail") {
    const std::filesystem::path helmet = std::filesystem::path(GLINT_SCENES_DIR) / "DamagedHelmet/DamagedHelmet.gltf";
    GltfLoadOptions options;
    options.loadTextures = false;
    const Scene withLods = loadGltf(helmet, options);
    options.reflectionLods.reset();
    const Scene fullDetail = loadGltf(helmet, options);
    REQUIRE(fullDetail.meshes.size() == 1u);
    CHECK(fullDetail.meshes[0].lods.size() == 1u);
    REQUIRE(withLods.meshes[0].lods.size() == 2u);
    const uint64_t full = triangleCount(withLods.meshes[0].lods[0]);
    const uint64_t reduced = triangleCount(withLods.meshes[0].lods[1]);
    CAPTURE(full);
    CAPTURE(reduced);
    CHECK(reduced < full / 2);
    CHECK(full == triangleCount(fullDetail.meshes[0].lods[0]));

    BvhPlanner planner;
    const BvhPlan plan = planner.plan(withLods, {0, 0, 0}, 0);
    REQUIRE(plan.blases.size() == 1u);
    CHECK(plan.blases[0].lod == 1u);
    CHECK(plan.blases[0].triangleCount == reduced);
    BvhSettings reference;
    reference.reflectionLods = false;
    BvhPlanner referencePlanner(reference);
    const BvhPlan referencePlan = referencePlanner.plan(withLods, {0, 0, 0}, 0);
    CHECK(referencePlan.blases[0].lod == 0u);
    CHECK(referencePlan.blases[0].triangleCount == full);
}
