// Every scene in ../shared/scenes loads with the counts and bounds its JSON
// declares. The expected numbers come from the files' JSON read here with
// nlohmann::json (accessor counts and POSITION min/max), not from the loader.

#include "glint/scene/builtin_scenes.h"
#include "glint/scene/error.h"
#include "glint/scene/gltf_loader.h"

#include "scene_test_support.h"

#include <glm/gtc/matrix_transform.hpp>

// The implementation is in libstb; declarations only.
#include <stb_image_write.h>

#include <set>

using namespace glint::scene;
using namespace glint::test;

namespace {

struct Expected {
    size_t meshes = 0;
    size_t materials = 0;
    uint64_t triangles = 0;  // each mesh once
    size_t instances = 0;    // nodes with a mesh reachable from the default scene
    size_t textures = 0;     // distinct images referenced by materials
    std::vector<Aabb> meshBounds;
};

Expected expectFromJson(const Json& doc) {
    Expected e;
    e.meshes = doc["meshes"].size();
    e.materials = doc.contains("materials") ? doc["materials"].size() : 0;
    bool needsDefault = false;
    for (const Json& mesh : doc["meshes"]) {
        Aabb box;
        for (const Json& prim : mesh["primitives"]) {
            const Json& position = doc["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
            const size_t vertices = position["count"];
            const size_t indices = prim.contains("indices")
                                       ? doc["accessors"][prim["indices"].get<size_t>()]["count"].get<size_t>()
                                       : vertices;
            REQUIRE(prim.value("mode", 4) == 4);  // the shared scenes are triangle lists
            e.triangles += indices / 3;
            needsDefault = needsDefault || !prim.contains("material");
            box.extend(glm::vec3(position["min"][0], position["min"][1], position["min"][2]));
            box.extend(glm::vec3(position["max"][0], position["max"][1], position["max"][2]));
        }
        e.meshBounds.push_back(box);
    }
    e.materials += needsDefault ? 1 : 0;
    std::vector<size_t> stack;
    for (const Json& n : doc["scenes"][doc.value("scene", 0)]["nodes"]) {
        stack.push_back(n);
    }
    while (!stack.empty()) {
        const Json& node = doc["nodes"][stack.back()];
        stack.pop_back();
        e.instances += node.contains("mesh") ? 1 : 0;
        for (const Json& c : node.value("children", Json::array())) {
            stack.push_back(c);
        }
    }
    std::set<size_t> images;
    for (const Json& m : doc.value("materials", Json::array())) {
        for (const char* slot : {"baseColorTexture", "metallicRoughnessTexture"}) {
            if (m.contains("pbrMetallicRoughness") && m["pbrMetallicRoughness"].contains(slot)) {
                images.insert(
                    doc["textures"][m["pbrMetallicRoughness"][slot]["index"].get<size_t>()]["source"].get<size_t>());
            }
        }
        for (const char* slot : {"normalTexture", "emissiveTexture", "occlusionTexture"}) {
            if (m.contains(slot)) {
                images.insert(doc["textures"][m[slot]["index"].get<size_t>()]["source"].get<size_t>());
            }
        }
    }
    e.textures = images.size();
    return e;
}

void checkScene(const std::filesystem::path& path, const Json& doc) {
    INFO(path.string());
    const Expected e = expectFromJson(doc);
    const Scene scene = loadGltf(path);
    CHECK(scene.meshes.size() == e.meshes);
    CHECK(scene.materials.size() == e.materials);
    CHECK(meshTriangleCount(scene) == e.triangles);
    CHECK(scene.instances.size() == e.instances);
    CHECK(scene.textures.size() == e.textures);
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        // The accessor min/max of POSITION bound exactly what was read.
        const Aabb& got = scene.meshes[m].bounds;
        const Aabb& want = e.meshBounds[m];
        const float tolerance = 1e-5f * std::max(1.0f, glm::length(want.size()));
        CHECK(glm::length(got.min - want.min) <= tolerance);
        CHECK(glm::length(got.max - want.max) <= tolerance);
    }
    for (const Mesh& mesh : scene.meshes) {
        for (const Geometry& g : mesh.lods[0].geometries) {
            REQUIRE(g.normals.size() == g.positions.size());
            REQUIRE(g.tangents.size() == g.positions.size());  // from the file or generated
            for (size_t v = 0; v < g.normals.size(); ++v) {
                REQUIRE(std::abs(glm::length(g.normals[v]) - 1.0f) < 1e-4f);
            }
        }
    }
    CHECK_FALSE(scene.cameraPath.keys.empty());
    CHECK(scene.lens.nearPlane > 0.0f);
}

} // namespace

TEST_CASE("every shared glTF scene loads with the counts and bounds its JSON declares") {
    const std::filesystem::path dir = scenesDir();
    for (const char* file :
         {"Box/Box.gltf", "CornellBox-Vinc3r/cornellBox-2.80-Eevee-gltf.gltf", "DamagedHelmet/DamagedHelmet.gltf",
          "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf", "WaterBottle/WaterBottle.gltf"}) {
        checkScene(dir / file, readJson(dir / file));
    }
    for (const char* file : {"CornellBox-MetalSuzanne-fazil47/cornell-box.glb",
                             "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.glb"}) {
        checkScene(dir / file, readGlbJson(dir / file));
    }
}

TEST_CASE("the shared scenes give the triangle counts written down by hand") {
    // Independent of any JSON reading: numbers from the files' accessors,
    // recorded once. A loader that drops or duplicates geometry fails here.
    const std::filesystem::path dir = scenesDir();
    CHECK(meshTriangleCount(loadGltf(dir / "Box/Box.gltf")) == 12);
    CHECK(meshTriangleCount(loadGltf(dir / "DamagedHelmet/DamagedHelmet.gltf", {.loadTextures = false})) == 15452);
    CHECK(meshTriangleCount(loadGltf(dir / "WaterBottle/WaterBottle.gltf", {.loadTextures = false})) == 4510);
    CHECK(meshTriangleCount(loadGltf(dir / "CornellBox-MetalSuzanne-fazil47/cornell-box.glb")) == 1040);
}

TEST_CASE("the glTF and GLB versions of a scene load to the same geometry") {
    const std::filesystem::path dir = scenesDir() / "MetalRoughSpheresNoTextures";
    const Scene a = loadGltf(dir / "MetalRoughSpheresNoTextures.gltf");
    const Scene b = loadGltf(dir / "MetalRoughSpheresNoTextures.glb");
    REQUIRE(a.meshes.size() == b.meshes.size());
    for (size_t m = 0; m < a.meshes.size(); ++m) {
        REQUIRE(a.meshes[m].lods[0].geometries.size() == b.meshes[m].lods[0].geometries.size());
        for (size_t g = 0; g < a.meshes[m].lods[0].geometries.size(); ++g) {
            CHECK(a.meshes[m].lods[0].geometries[g].positions == b.meshes[m].lods[0].geometries[g].positions);
            CHECK(a.meshes[m].lods[0].geometries[g].indices == b.meshes[m].lods[0].geometries[g].indices);
        }
    }
    CHECK(a.instances.size() == b.instances.size());
}

TEST_CASE("textures decode at their file sizes and materials point at them") {
    const Scene helmet = loadGltf(scenesDir() / "DamagedHelmet/DamagedHelmet.gltf");
    REQUIRE(helmet.textures.size() == 5);
    for (const Texture& t : helmet.textures) {
        CHECK(t.width == 2048);
        CHECK(t.height == 2048);
        CHECK(t.valid());
    }
    const Material& m = helmet.materials[0];
    CHECK(m.baseColorTexture.valid());
    CHECK(m.metallicRoughnessTexture.valid());
    CHECK(m.normalTexture.valid());
    CHECK(m.emissiveTexture.valid());
    CHECK(m.occlusionTexture.valid());
    CHECK(m.emissiveFactor == glm::vec3(1.0f));
}

TEST_CASE("node transforms place instances in the world") {
    // Box.gltf's root node carries a matrix (a quarter turn about X) and its
    // child the mesh: the instance gets exactly that matrix.
    const Scene box = loadGltf(scenesDir() / "Box/Box.gltf");
    REQUIRE(box.instances.size() == 1);
    const Json doc = readJson(scenesDir() / "Box/Box.gltf");
    std::vector<float> m;
    for (const Json& v : doc["nodes"][0]["matrix"]) {
        m.push_back(v.get<float>());
    }
    REQUIRE(m.size() == 16);
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
            CHECK(box.instances[0].transform[c][r] == doctest::Approx(m[size_t(c * 4 + r)]));
        }
    }
}

TEST_CASE("a missing texture falls back to flat factors with one warning") {
    const std::filesystem::path src = scenesDir() / "CornellBox-Vinc3r";
    const std::filesystem::path dir = outputDir("missing-texture");
    for (const char* file :
         {"cornellBox-2.80-Eevee-gltf.gltf", "cornellBox-2.80-Eevee-gltf.bin", "checker-meter.png"}) {
        std::filesystem::copy_file(src / file, dir / file);
    }
    LogCapture log;
    const Scene scene = loadGltf(dir / "cornellBox-2.80-Eevee-gltf.gltf");
    const std::vector<std::string> warnings = log.lines("warning");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("checkerBJS.png") != std::string::npos);
    CHECK(warnings[0].find("cornellBox-2.80-Eevee-gltf.gltf") != std::string::npos);
    CHECK(scene.textures.size() == 1);
    // The material that used the missing image keeps its factors only.
    const Material& bloc = scene.materials[0];
    CHECK(bloc.name == "bloc.000");
    CHECK_FALSE(bloc.baseColorTexture.valid());
    CHECK(meshTriangleCount(scene) == 4410);
}

TEST_CASE("optional extensions are ignored with one log line; required unsupported ones are errors") {
    const std::filesystem::path dir = outputDir("extensions");
    Json doc = readJson(scenesDir() / "Box/Box.gltf");
    std::filesystem::copy_file(scenesDir() / "Box/Box0.bin", dir / "Box0.bin");
    doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_clearcoat",
                             "KHR_texture_transform"};
    writeText(dir / "optional.gltf", doc.dump());
    {
        LogCapture log;
        CHECK(loadGltf(dir / "optional.gltf").meshes.size() == 1);
        const std::vector<std::string> info = log.lines("info");
        CHECK(info.size() == 2);  // supported KHR_texture_transform is not "ignored"
        for (const std::string& line : info) {
            CHECK(line.find("KHR_texture_transform") == std::string::npos);
        }
        CHECK(log.lines("warning").empty());
    }
    doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    writeText(dir / "draco.gltf", doc.dump());
    try {
        loadGltf(dir / "draco.gltf");
        FAIL("a file requiring Draco loaded");
    } catch (const SceneError& e) {
        const std::string what = e.what();
        CHECK(what.find("draco.gltf") != std::string::npos);
        CHECK(what.find("KHR_draco_mesh_compression") != std::string::npos);
        CHECK(e.element() == "extensionsRequired");
    }
}

TEST_CASE("KHR_materials_emissive_strength, KHR_materials_ior and a KHR_lights_punctual sun are read") {
    const std::filesystem::path dir = outputDir("supported-extensions");
    Json doc = readJson(scenesDir() / "Box/Box.gltf");
    std::filesystem::copy_file(scenesDir() / "Box/Box0.bin", dir / "Box0.bin");
    doc["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_lights_punctual", "KHR_materials_ior"};
    doc["materials"][0]["emissiveFactor"] = {1.0, 0.5, 0.25};
    doc["materials"][0]["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8.0}}},
                                         {"KHR_materials_ior", {{"ior", 1.5}}}};
    doc["extensions"] = {
        {"KHR_lights_punctual",
         {{"lights",
           {{{"type", "point"}}, {{"type", "directional"}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 1234.0}}}}}}};
    // A node pitched down 90 degrees: its -Z (the light's direction) is -Y.
    const float s = std::sqrt(0.5f);
    doc["nodes"].push_back({{"rotation", {-s, 0, 0, s}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 2);
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    writeText(dir / "extensions.gltf", doc.dump());
    const Scene scene = loadGltf(dir / "extensions.gltf");
    CHECK(scene.materials[0].emissiveStrength == 8.0f);
    CHECK(scene.materials[0].emissiveFactor == glm::vec3(1.0f, 0.5f, 0.25f));
    // ior 1.5 -> f0 0.04 -> Filament reflectance 0.5.
    CHECK(scene.materials[0].reflectance == doctest::Approx(0.5f).epsilon(1e-4));
    CHECK(glm::length(scene.sun.directionToLight - glm::vec3(0, 1, 0)) < 1e-5f);
    CHECK(scene.sun.illuminance == 1234.0f);
    CHECK(scene.sun.color == glm::vec3(1.0f, 0.9f, 0.8f));
}

TEST_CASE("flat normals and tangents are generated when a primitive has none") {
    const std::filesystem::path dir = outputDir("flat-normals");
    Json doc = readJson(scenesDir() / "Box/Box.gltf");
    std::filesystem::copy_file(scenesDir() / "Box/Box0.bin", dir / "Box0.bin");
    doc["meshes"][0]["primitives"][0]["attributes"].erase("NORMAL");
    writeText(dir / "flat.gltf", doc.dump());
    const Scene scene = loadGltf(dir / "flat.gltf");
    const Geometry& g = scene.meshes[0].lods[0].geometries[0];
    REQUIRE(g.positions.size() == 36);  // unwelded: three vertices per triangle
    for (uint32_t t = 0; t < g.triangleCount(); ++t) {
        const glm::vec3 a = g.positions[g.indices[3 * t]];
        const glm::vec3 b = g.positions[g.indices[3 * t + 1]];
        const glm::vec3 c = g.positions[g.indices[3 * t + 2]];
        const glm::vec3 face = glm::normalize(glm::cross(b - a, c - a));
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = g.indices[3 * t + k];
            CHECK(glm::length(g.normals[v] - face) < 1e-5f);
            CHECK(std::abs(glm::dot(glm::vec3(g.tangents[v]), face)) < 1e-5f);
            CHECK(std::abs(glm::length(glm::vec3(g.tangents[v])) - 1.0f) < 1e-5f);
        }
    }
}

TEST_CASE("loadScene takes built-in names and glTF paths alike") {
    CHECK(loadScene("plaza").name == "plaza");
    CHECK(loadScene("hard-cases").name == "hard-cases");
    CHECK(loadScene((scenesDir() / "Box/Box.gltf").string()).meshes.size() == 1);
    CHECK_THROWS_AS(loadScene("no-such-scene"), SceneError);
    CHECK_THROWS_AS(makeBuiltinScene("no-such-scene"), SceneError);
}

TEST_CASE("embedded images in a GLB bufferView and in a data URI decode like external ones") {
    // A 3 x 2 PNG, encoded here.
    const std::vector<uint8_t> pixels = {255, 0,  0,  255, 0,  255, 0,  255, 0,  0,  255, 255,
                                         10,  20, 30, 255, 40, 50,  60, 255, 70, 80, 90,  255};
    std::vector<uint8_t> png;
    stbi_write_png_to_func(
        [](void* context, void* data, int size) {
            auto* out = static_cast<std::vector<uint8_t>*>(context);
            out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
        },
        &png, 3, 2, 4, pixels.data(), 3 * 4);
    REQUIRE(!png.empty());

    GltfFixture f;
    const int positions = f.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int uvs = f.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    const size_t imageOffset = f.bin.size();
    f.bin.insert(f.bin.end(), png.begin(), png.end());
    f.bin.resize((f.bin.size() + 3) & ~size_t(3));
    f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", imageOffset}, {"byteLength", png.size()}});
    f.doc["images"] = {{{"bufferView", f.doc["bufferViews"].size() - 1}, {"mimeType", "image/png"}},
                       {{"uri", "data:image/png;base64," + base64(png)}}};
    f.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
    f.doc["materials"] = {
        {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}, {"emissiveTexture", {{"index", 1}}}}};
    f.doc["meshes"] = {
        {{"primitives", {{{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}}, {"material", 0}}}}}};
    f.doc["nodes"] = {{{"mesh", 0}}};
    f.doc["scenes"] = {{{"nodes", {0}}}};

    // As a GLB: the JSON chunk, then the buffer as the BIN chunk.
    Json doc = f.doc;
    doc["buffers"] = {{{"byteLength", f.bin.size()}}};
    std::string json = doc.dump();
    json.resize((json.size() + 3) & ~size_t(3), ' ');
    std::vector<uint8_t> glb;
    const auto put32 = [&](uint32_t v) {
        for (int i = 0; i < 4; ++i) {
            glb.push_back(uint8_t(v >> (8 * i)));
        }
    };
    put32(0x46546C67u);
    put32(2);
    put32(uint32_t(12 + 8 + json.size() + 8 + f.bin.size()));
    put32(uint32_t(json.size()));
    put32(0x4E4F534Au);
    glb.insert(glb.end(), json.begin(), json.end());
    put32(uint32_t(f.bin.size()));
    put32(0x004E4942u);
    glb.insert(glb.end(), f.bin.begin(), f.bin.end());
    const std::filesystem::path dir = outputDir("embedded-images");
    writeBytes(dir / "embedded.glb", glb);
    writeText(dir / "embedded.gltf", f.text());

    for (const char* file : {"embedded.glb", "embedded.gltf"}) {
        INFO(file);
        LogCapture log;
        const Scene scene = loadGltf(dir / file);
        CHECK(log.lines("warning").empty());
        REQUIRE(scene.textures.size() == 2);
        for (const Texture& t : scene.textures) {
            REQUIRE(t.width == 3);
            REQUIRE(t.height == 2);
            CHECK(t.rgba8 == pixels);
        }
        CHECK(scene.materials[0].baseColorTexture.valid());
        CHECK(scene.materials[0].emissiveTexture.valid());
    }
}

TEST_CASE("a file's first perspective camera becomes the scene's view; without one the view frames the bounds") {
    const std::filesystem::path dir = outputDir("camera");
    std::filesystem::copy_file(scenesDir() / "Box/Box.gltf", dir / "framed.gltf");
    std::filesystem::copy_file(scenesDir() / "Box/Box0.bin", dir / "Box0.bin");
    Json doc = readJson(scenesDir() / "Box/Box.gltf");
    doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.05}}}},
                      {{"type", "perspective"}, {"name", "top"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}};
    doc["nodes"].push_back({{"camera", 0}, {"translation", {0.0, 1.0, 6.0}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    // Looking straight down: the node's -Z rotated onto -Y.
    doc["nodes"].push_back(
        {{"camera", 1}, {"translation", {0.0, 9.0, 0.0}}, {"rotation", {-0.7071068, 0.0, 0.0, 0.7071068}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    writeText(dir / "camera.gltf", doc.dump());

    const Scene withCamera = loadGltf(dir / "camera.gltf");
    CHECK(withCamera.lens.verticalFovRadians == doctest::Approx(0.8f));
    CHECK(withCamera.lens.nearPlane == doctest::Approx(0.05f));
    CHECK(std::isinf(withCamera.lens.farPlane));  // no zfar: infinite
    const CameraPose pose = withCamera.cameraPath.evaluate(0.0f);
    CHECK(pose.position == glm::vec3(0, 1, 6));
    CHECK(glm::length(glm::normalize(pose.target - pose.position) - glm::vec3(0, 0, -1)) < 1e-6f);

    // Every camera is a named view, by name or index (glint-render --camera).
    REQUIRE(withCamera.views.size() == 2);
    CHECK(withCamera.views[0].name == "camera 0");
    const SceneView& top = findView(withCamera, "top");
    CHECK(&top == &findView(withCamera, "1"));
    CHECK(top.lens.verticalFovRadians == doctest::Approx(0.5f));
    CHECK(top.position == glm::vec3(0, 9, 0));
    CHECK(glm::length(glm::normalize(top.target - top.position) - glm::vec3(0, -1, 0)) < 1e-6f);
    CHECK_THROWS_WITH_AS(findView(withCamera, "side"), doctest::Contains("no such camera (available: 0 'camera 0', 1 'top')"),
                         SceneError);
    Scene moved = withCamera;
    useView(moved, top);
    CHECK(moved.cameraPath.keys.size() == 1);
    CHECK(moved.cameraPath.evaluate(0.0f).position == glm::vec3(0, 9, 0));
    CHECK(moved.lens.verticalFovRadians == doctest::Approx(0.5f));

    const Scene framed = loadGltf(dir / "framed.gltf");
    const CameraPose view = framed.cameraPath.evaluate(0.0f);
    const Aabb bounds = sceneBounds(framed);
    CHECK(glm::length(view.target - bounds.center()) < 1e-5f);
    CHECK(distanceToBounds(bounds, view.position) > framed.lens.nearPlane);  // the whole box is past the near plane
}

TEST_CASE("KHR_mesh_quantization admits integer positions and normals; without it they are an error") {
    GltfFixture f;
    const int positions = f.accessor(std::vector<int16_t>{0, 0, 0, 0, 100, 0, 0, 0, 0, 100, 0, 0}, 5122, "VEC3", 3);
    f.doc["accessors"][size_t(positions)]["min"] = {0, 0, 0};
    f.doc["accessors"][size_t(positions)]["max"] = {100, 100, 0};
    const int normals = f.accessor(std::vector<int8_t>{0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0}, 5120, "VEC3", 3);
    f.doc["accessors"][size_t(normals)]["normalized"] = true;
    // Three VEC3 of SHORT are 6 bytes each; glTF wants vertex elements 4-byte aligned, so give a stride of 8.
    f.doc["bufferViews"][0]["byteStride"] = 8;
    f.doc["accessors"][size_t(positions)]["count"] = 3;
    f.doc["bufferViews"][1]["byteStride"] = 4;
    f.doc["accessors"][size_t(normals)]["count"] = 3;
    f.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", positions}, {"NORMAL", normals}}}}}}}};
    f.doc["nodes"] = {{{"mesh", 0}}};
    f.doc["scenes"] = {{{"nodes", {0}}}};
    const std::filesystem::path dir = outputDir("quantized");
    writeText(dir / "plain.gltf", f.text());
    CHECK_THROWS_AS(loadGltf(dir / "plain.gltf"), SceneError);
    f.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
    f.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
    writeText(dir / "quantized.gltf", f.text());
    const Scene scene = loadGltf(dir / "quantized.gltf");
    const Geometry& g = scene.meshes[0].lods[0].geometries[0];
    REQUIRE(g.positions.size() == 3);
    CHECK(g.positions[1] == glm::vec3(100, 0, 0));
    CHECK(g.positions[2] == glm::vec3(0, 100, 0));
    CHECK(g.normals[0] == glm::vec3(0, 0, 1));
}
