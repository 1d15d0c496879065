#include "glint/scene/builtin_scenes.h"
#include "glint/scene/gltf_loader.h"
#include "glint/scene/gltf_writer.h"

#include "scene_test_support.h"

using namespace glint::scene;

namespace {

void checkRoundTrip(const Scene& original, const std::string& name) {
    INFO(name);
    const std::filesystem::path dir = glint::test::outputDir("writer-" + name);
    writeGltf(original, dir / (name + ".gltf"));
    CHECK(std::filesystem::exists(dir / (name + ".bin")));
    const Scene loaded = loadGltf(dir / (name + ".gltf"), {.loadTextures = false});
    CHECK(loaded.meshes.size() == original.meshes.size());
    CHECK(loaded.materials.size() == original.materials.size());
    CHECK(loaded.instances.size() == original.instances.size());
    CHECK(meshTriangleCount(loaded) == meshTriangleCount(original));
    CHECK(instancedTriangleCount(loaded) == instancedTriangleCount(original));
    const Aabb a = sceneBounds(original);
    const Aabb b = sceneBounds(loaded);
    const float tolerance = 1e-5f * std::max(1.0f, glm::length(a.max) + glm::length(a.min));
    CHECK(glm::length(a.min - b.min) <= tolerance);
    CHECK(glm::length(a.max - b.max) <= tolerance);
    for (size_t m = 0; m < original.materials.size(); ++m) {
        CHECK(loaded.materials[m].baseColorFactor == original.materials[m].baseColorFactor);
        CHECK(loaded.materials[m].roughnessFactor == original.materials[m].roughnessFactor);
        CHECK(loaded.materials[m].metallicFactor == original.materials[m].metallicFactor);
        CHECK(loaded.materials[m].emissiveStrength == original.materials[m].emissiveStrength);
    }
    CHECK(glm::length(loaded.sun.directionToLight - original.sun.directionToLight) < 1e-5f);
}

} // namespace

TEST_CASE("writing a scene as glTF and loading it back keeps counts, bounds and factors") {
    checkRoundTrip(makePlaza(), "plaza");
    checkRoundTrip(makeHardCases(), "hard-cases");
    checkRoundTrip(loadGltf(glint::test::scenesDir() / "CornellBox-MetalSuzanne-fazil47/cornell-box.glb"), "cornell");
}

TEST_CASE("the written glTF is plain JSON with POSITION bounds, as other tools require") {
    const std::filesystem::path dir = glint::test::outputDir("writer-json");
    writeGltf(makeHardCases(), dir / "scene.gltf");
    const glint::test::Json doc = glint::test::readJson(dir / "scene.gltf");
    CHECK(doc["asset"]["version"] == "2.0");
    for (const auto& mesh : doc["meshes"]) {
        for (const auto& prim : mesh["primitives"]) {
            const auto& position = doc["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
            CHECK(position.contains("min"));
            CHECK(position.contains("max"));
        }
    }
    CHECK(doc["buffers"][0]["byteLength"].get<uint64_t>() == std::filesystem::file_size(dir / "scene.bin"));
}
