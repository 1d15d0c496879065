// A corpus of broken glTF files, generated from the good ones in
// ../shared/scenes under the build tree: truncated, corrupted indices and
// offsets, wrong types and counts, huge declared sizes. Each must give a
// SceneError naming the file (and, where the corruption is targeted, the
// element), never a crash, an out-of-bounds read or a huge allocation; the
// ASan+UBSan build runs this suite too.

#include "glint/scene/error.h"
#include "glint/scene/gltf_loader.h"

#include "scene_test_support.h"

#include <algorithm>
#include <functional>
#include <random>

using namespace glint::scene;
using namespace glint::test;

namespace {

// Loads `file` expecting a SceneError whose message names the file and
// contains every one of `parts`.
void expectError(const std::filesystem::path& file, std::initializer_list<std::string> parts = {},
                 const GltfLoadOptions& options = {}) {
    INFO(file.string());
    try {
        loadGltf(file, options);
        FAIL("a broken file loaded");
    } catch (const SceneError& e) {
        const std::string what = e.what();
        CHECK_MESSAGE(what.find(file.filename().string()) != std::string::npos, what);
        for (const std::string& part : parts) {
            CHECK_MESSAGE(what.find(part) != std::string::npos, what);
        }
    }
}

// Box.gltf variants: edits of its JSON, next to a copy of its buffer.
class BoxVariants {
public:
    BoxVariants() : dir_(outputDir("broken-box")), base_(readJson(scenesDir() / "Box/Box.gltf")) {
        std::filesystem::copy_file(scenesDir() / "Box/Box0.bin", dir_ / "Box0.bin");
    }

    std::filesystem::path make(const std::string& name, const std::function<void(Json&)>& edit) const {
        Json doc = base_;
        edit(doc);
        const std::filesystem::path path = dir_ / (name + ".gltf");
        writeText(path, doc.dump());
        return path;
    }

    const std::filesystem::path& dir() const { return dir_; }
    const Json& base() const { return base_; }

private:
    std::filesystem::path dir_;
    Json base_;
};

} // namespace

TEST_CASE("a missing or empty file is a clear error") {
    const std::filesystem::path dir = outputDir("broken-missing");
    expectError(dir / "nowhere.gltf", {"file not found"});
    writeText(dir / "empty.gltf", "");
    expectError(dir / "empty.gltf");
    writeText(dir / "not-json.gltf", "this is not glTF");
    expectError(dir / "not-json.gltf", {"JSON"});
    writeText(dir / "array.gltf", "[1, 2, 3]");
    expectError(dir / "array.gltf", {"not an object"});
    writeText(dir / "version1.gltf", R"({"asset": {"version": "1.0"}})");
    expectError(dir / "version1.gltf", {"only glTF 2"});
}

TEST_CASE("truncated .gltf and .bin files are errors") {
    const BoxVariants box;
    const std::string text = readJson(scenesDir() / "Box/Box.gltf").dump();
    for (double fraction : {0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 0.999}) {
        const std::filesystem::path path = box.dir() / ("cut-" + std::to_string(int(fraction * 1000)) + ".gltf");
        writeText(path, text.substr(0, size_t(double(text.size()) * fraction)));
        expectError(path);
    }
    // The JSON intact, the buffer cut short.
    const std::filesystem::path dir = outputDir("broken-bin");
    std::vector<uint8_t> bin = readBytes(scenesDir() / "Box/Box0.bin");
    bin.resize(600);
    writeBytes(dir / "Box0.bin", bin);
    std::filesystem::copy_file(scenesDir() / "Box/Box.gltf", dir / "Box.gltf");
    expectError(dir / "Box.gltf", {"buffer 0", "648", "600", "truncated"});
    std::filesystem::remove(dir / "Box0.bin");
    expectError(dir / "Box.gltf", {"buffer 0", "file not found"});
}

TEST_CASE("accessors out of their bufferView, with bad strides, types or counts are errors naming the accessor") {
    const BoxVariants box;
    // accessor 2 is POSITION: VEC3 FLOAT, bufferView 1 (576 bytes, stride 12), byteOffset 288, count 24.
    expectError(box.make("offset", [](Json& d) { d["accessors"][2]["byteOffset"] = 1200; }),
                {"accessor 2 (mesh 'Mesh' primitive 0 POSITION)",
                 "byteOffset 1200 + count 24 * stride 12 exceeds bufferView 1 (576 bytes)"});
    expectError(box.make("count", [](Json& d) { d["accessors"][2]["count"] = 100; }),
                {"accessor 2", "count 100", "exceeds bufferView 1"});
    expectError(box.make("huge-count", [](Json& d) { d["accessors"][2]["count"] = 4000000000000ull; }),
                {"accessor 2", "count 4000000000000"});
    expectError(box.make("zero-count", [](Json& d) { d["accessors"][2]["count"] = 0; }), {"accessor 2", "count 0"});
    expectError(box.make("stride", [](Json& d) { d["bufferViews"][1]["byteStride"] = 8; }),
                {"accessor", "byteStride 8", "smaller than the element size 12"});
    expectError(box.make("stride-256", [](Json& d) { d["bufferViews"][1]["byteStride"] = 256; }), {"byteStride"});
    expectError(box.make("component", [](Json& d) { d["accessors"][2]["componentType"] = 5121; }),
                {"accessor 2", "UNSIGNED_BYTE (5121) is not allowed for POSITION"});
    expectError(box.make("double", [](Json& d) { d["accessors"][2]["componentType"] = 5130; }),
                {"accessor 2", "DOUBLE"});
    expectError(box.make("type", [](Json& d) { d["accessors"][2]["type"] = "VEC2"; }),
                {"accessor 2", "type VEC2 is not allowed for POSITION"});
    expectError(box.make("float-indices", [](Json& d) { d["accessors"][0]["componentType"] = 5126; }),
                {"accessor 0 (mesh 'Mesh' primitive 0 indices)", "not allowed for indices"});
    expectError(box.make("index-count", [](Json& d) { d["accessors"][0]["count"] = 35; }),
                {"accessor 0", "not a multiple of 3"});
    expectError(box.make("no-accessor", [](Json& d) { d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 7; }),
                {"mesh 'Mesh' primitive 0 POSITION", "accessor 7 out of range (3 accessors)"});
    expectError(box.make("normal-count", [](Json& d) { d["accessors"][1]["count"] = 23; }),
                {"accessor 1", "NORMAL count 23 differs from POSITION count 24"});
    expectError(box.make("no-view", [](Json& d) { d["accessors"][2]["bufferView"] = 9; }),
                {"accessor 2", "bufferView 9 out of range"});
    expectError(box.make("negative-view", [](Json& d) { d["accessors"][2]["bufferView"] = -5; }),
                {"accessor 2", "bufferView -5 out of range"});
    expectError(box.make("view-length", [](Json& d) { d["bufferViews"][1]["byteLength"] = 5000; }),
                {"bufferView 1 (byteOffset 0 + byteLength 5000) exceeds buffer 0 (648 bytes)"});
    expectError(box.make("view-offset", [](Json& d) { d["bufferViews"][1]["byteOffset"] = 1000000000000000ull; }),
                {"bufferView 1", "exceeds buffer 0"});
}

TEST_CASE("out-of-range indices and references are errors naming the element") {
    const BoxVariants box;
    {
        // Index 5 of the index buffer (UNSIGNED_SHORT at byte 576) set to 65535.
        std::vector<uint8_t> bin = readBytes(scenesDir() / "Box/Box0.bin");
        bin[576 + 2 * 5] = 0xFF;
        bin[576 + 2 * 5 + 1] = 0xFF;
        const std::filesystem::path dir = outputDir("broken-index");
        writeBytes(dir / "Box0.bin", bin);
        std::filesystem::copy_file(scenesDir() / "Box/Box.gltf", dir / "Box.gltf");
        expectError(dir / "Box.gltf",
                    {"accessor 0 (mesh 'Mesh' primitive 0 indices)", "index 65535 at position 5 >= vertex count 24"});
    }
    expectError(box.make("material", [](Json& d) { d["meshes"][0]["primitives"][0]["material"] = 4; }),
                {"mesh 'Mesh' primitive 0", "material 4 out of range (1 materials)"});
    expectError(box.make("node-mesh", [](Json& d) { d["nodes"][1]["mesh"] = 3; }), {"node 1", "mesh 3 out of range"});
    expectError(box.make("cycle", [](Json& d) { d["nodes"][1]["children"] = {0}; }), {"cycle"});
    expectError(box.make("two-parents",
                         [](Json& d) {
                             d["nodes"].push_back({{"children", {1}}});
                         }),
                {"node 1", "two parents"});
    expectError(box.make("child",
                         [](Json& d) {
                             d["nodes"][0]["children"] = {1, 40};
                         }),
                {"node 0", "child 40 out of range"});
    expectError(box.make("scene-node", [](Json& d) { d["scenes"][0]["nodes"] = {1}; }), {"scene 0", "not a root"});
    expectError(box.make("default-scene", [](Json& d) { d["scene"] = 5; }), {"default scene 5 out of range"});
    expectError(box.make("translation",
                         [](Json& d) {
                             d["nodes"][1]["translation"] = {1.0, 2.0};
                         }),
                {"node 1", "translation has 2 numbers (expected 3)"});
    expectError(box.make("zero-rotation",
                         [](Json& d) {
                             d["nodes"][1]["rotation"] = {0.0, 0.0, 0.0, 0.0};
                         }),
                {"node 1", "zero quaternion"});
    expectError(box.make("texture",
                         [](Json& d) {
                             d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 3}};
                         }),
                {"material 0", "baseColorTexture", "texture 3 out of range (0 textures)"});
    {
        // A schema slip tinygltf recovers from: the default, and one warning.
        LogCapture log;
        const Scene scene = loadGltf(box.make("base-color", [](Json& d) {
            d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1.0, 0.5};
        }));
        CHECK(scene.materials[0].baseColorFactor == glm::vec4(1.0f));
        const std::vector<std::string> warnings = log.lines("warning");
        REQUIRE(warnings.size() == 1);
        CHECK(warnings[0].find("baseColorFactor") != std::string::npos);
        CHECK(warnings[0].find("base-color.gltf") != std::string::npos);
    }
    expectError(box.make("overflow",
                         [](Json& d) {
                             d["nodes"][1]["translation"] = {1.0, std::numeric_limits<double>::max(), 0.0};
                         }),
                {"node 1", "translation is not finite"});
    expectError(box.make("required", [](Json& d) { d["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }),
                {"extensionsRequired", "KHR_draco_mesh_compression"});
}

TEST_CASE("huge declared sizes are refused before anything is allocated") {
    const BoxVariants box;
    expectError(box.make("buffer-size", [](Json& d) { d["buffers"][0]["byteLength"] = 1ull << 40; }),
                {"buffer 0", "1099511627776", "648"});
    expectError(box.make("buffer-negative", [](Json& d) { d["buffers"][0]["byteLength"] = -1; }),
                {"buffer 0", "byteLength must be a non-negative integer"});
    // A data URI buffer claiming more than it holds.
    expectError(
        box.make("data-uri",
                 [](Json& d) {
                     d["buffers"][0] = {{"byteLength", 1 << 30}, {"uri", "data:application/octet-stream;base64,AAAA"}};
                 }),
        {"buffer 0", "data URI holds 3 bytes but byteLength is 1073741824"});
    expectError(
        box.make("bad-base64",
                 [](Json& d) {
                     d["buffers"][0] = {{"byteLength", 3}, {"uri", "data:application/octet-stream;base64,A*A="}};
                 }),
        {"buffer 0", "not valid base64"});
    // A bufferView-less accessor reads as zeros: a huge count would be a huge
    // allocation, stopped by the decoded-bytes limit.
    expectError(box.make("zeros",
                         [](Json& d) {
                             d["accessors"][2].erase("bufferView");
                             d["accessors"][2]["count"] = 2000000000;
                         }),
                {"accessor 2", "limit"});
    // Limits are options: a file bigger than allowed, geometry beyond the cap.
    expectError(scenesDir() / "Box/Box.gltf", {"more than the limit"}, {.maxFileBytes = 100});
    expectError(scenesDir() / "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.glb",
                {"limit of 1048576 decoded bytes"}, {.maxDecodedBytes = 1 << 20});
    // JSON nested a million deep would recurse through the parsers.
    const std::string bomb =
        R"({"asset": {"version": "2.0"}, "extras": )" + std::string(1000000, '[') + std::string(1000000, ']') + "}";
    writeText(box.dir() / "nesting.gltf", bomb);
    expectError(box.dir() / "nesting.gltf", {"JSON", "nesting deeper than 64"});
}

TEST_CASE("broken skins and animations are errors naming the part") {
    const auto build = [](const std::string& name, const std::function<void(GltfFixture&, Json&)>& edit) {
        GltfFixture f;
        const int positions = f.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
        const int joints = f.accessor(std::vector<uint16_t>{0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, 5123, "VEC4", 4);
        const int weights = f.floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4", 4);
        const int times = f.floats({0, 1, 2}, "SCALAR", 1);
        const int values = f.floats({0, 0, 0, 1, 0, 0, 2, 0, 0}, "VEC3", 3);
        f.doc["meshes"] = {
            {{"primitives",
              {{{"attributes", {{"POSITION", positions}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}}}}}}};
        f.doc["nodes"] = {{{"mesh", 0}, {"skin", 0}}, {{"name", "j0"}, {"children", {2}}}, {{"name", "j1"}}};
        f.doc["skins"] = {{{"joints", {1, 2}}}};
        f.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", values}}}},
                                {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}}}}}};
        f.doc["scenes"] = {{{"nodes", {0, 1}}}};
        Json& doc = f.doc;
        edit(f, doc);
        const std::filesystem::path dir = std::filesystem::path(GLINT_TEST_OUTPUT_DIR) / "broken-animation";
        std::filesystem::create_directories(dir);
        writeText(dir / (name + ".gltf"), f.text());
        return dir / (name + ".gltf");
    };
    CHECK(loadGltf(build("good", [](GltfFixture&, Json&) {})).instances[0].motion == Motion::Skinned);
    expectError(build("joint-node",
                      [](GltfFixture&, Json& d) {
                          d["skins"][0]["joints"] = {1, 9};
                      }),
                {"skin 0", "joint node 9 out of range"});
    expectError(build("vertex-joint", [](GltfFixture&, Json& d) { d["skins"][0]["joints"] = {1}; }),
                {"node 0", "uses joint 1 but skin 0 has 1 joints"});
    expectError(build("ibm-count",
                      [](GltfFixture& f, Json& d) {
                          d["skins"][0]["inverseBindMatrices"] = f.floats(std::vector<float>(16, 0.0f), "MAT4", 16);
                      }),
                {"inverseBindMatrices", "1 matrices for 2 joints"});
    expectError(build("times",
                      [](GltfFixture& f, Json& d) {
                          d["animations"][0]["samplers"][0]["input"] = f.floats({0, 2, 1}, "SCALAR", 1);
                      }),
                {"animation 0", "key times decrease at key 2"});
    expectError(build("outputs",
                      [](GltfFixture& f, Json& d) {
                          d["animations"][0]["samplers"][0]["output"] = f.floats({0, 0, 0, 1, 0, 0}, "VEC3", 3);
                      }),
                {"animation 0", "2 values for 3 keys"});
    expectError(build("cubic", [](GltfFixture&,
                                  Json& d) { d["animations"][0]["samplers"][0]["interpolation"] = "CUBICSPLINE"; }),
                {"CUBICSPLINE needs 3 per key"});
    expectError(
        build("channel-node", [](GltfFixture&, Json& d) { d["animations"][0]["channels"][0]["target"]["node"] = 12; }),
        {"animation 0 channel 0", "target node 12 out of range"});
    expectError(
        build("channel-sampler", [](GltfFixture&, Json& d) { d["animations"][0]["channels"][0]["sampler"] = 3; }),
        {"animation 0 channel 0", "sampler 3 out of range"});
    expectError(build("matrix-node",
                      [](GltfFixture&, Json& d) {
                          d["nodes"][1]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
                      }),
                {"animation 0 channel 0", "has a matrix"});
    expectError(build("rotation-type",
                      [](GltfFixture&, Json& d) { d["animations"][0]["channels"][0]["target"]["path"] = "rotation"; }),
                {"animation 0", "type VEC3 is not allowed for output"});
    expectError(build("joints-weights",
                      [](GltfFixture&, Json& d) { d["meshes"][0]["primitives"][0]["attributes"].erase("WEIGHTS_0"); }),
                {"JOINTS_0 and WEIGHTS_0 must come together"});
    expectError(build("joints-float",
                      [](GltfFixture& f, Json& d) {
                          d["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
                              f.floats(std::vector<float>(12, 0.0f), "VEC4", 4);
                      }),
                {"JOINTS_0", "FLOAT (5126)", "not allowed"});
    expectError(build("image-view",
                      [](GltfFixture&, Json& d) {
                          d["images"] = {{{"bufferView", 0}, {"mimeType", "image/png"}}};
                          d["bufferViews"][0]["byteOffset"] = 1 << 30;
                      }),
                {"image 0", "exceeds buffer 0"});
}

TEST_CASE("truncated and corrupted GLB containers are errors") {
    const std::filesystem::path source = scenesDir() / "CornellBox-MetalSuzanne-fazil47/cornell-box.glb";
    const std::vector<uint8_t> glb = readBytes(source);
    const std::filesystem::path dir = outputDir("broken-glb");
    uint32_t jsonLength = 0;
    std::memcpy(&jsonLength, glb.data() + 12, 4);
    const size_t jsonEnd = 20 + jsonLength;
    std::vector<size_t> cuts = {0,
                                3,
                                4,
                                11,
                                12,
                                16,
                                19,
                                20,
                                21,
                                100,
                                jsonEnd - 1,
                                jsonEnd,
                                jsonEnd + 4,
                                jsonEnd + 8,
                                jsonEnd + 9,
                                glb.size() / 2,
                                glb.size() - 4,
                                glb.size() - 1};
    for (size_t k = 1; k < 16; ++k) {
        cuts.push_back(glb.size() * k / 16);
    }
    for (size_t cut : cuts) {
        const std::filesystem::path path = dir / ("cut-" + std::to_string(cut) + ".glb");
        writeBytes(path, glb.data(), cut);
        expectError(path);
    }
    const auto variant = [&](const std::string& name, const std::function<void(std::vector<uint8_t>&)>& edit) {
        std::vector<uint8_t> bytes = glb;
        edit(bytes);
        const std::filesystem::path path = dir / (name + ".glb");
        writeBytes(path, bytes);
        return path;
    };
    const auto put32 = [](std::vector<uint8_t>& b, size_t at, uint32_t v) { std::memcpy(b.data() + at, &v, 4); };
    expectError(variant("length", [&](auto& b) { put32(b, 8, uint32_t(b.size() + 100)); }),
                {"GLB header", "truncated"});
    expectError(variant("version", [&](auto& b) { put32(b, 4, 1); }), {"GLB header", "version 1"});
    expectError(variant("json-length", [&](auto& b) { put32(b, 12, 0xFFFFFFF0u); }), {"GLB chunk 0", "4294967280"});
    expectError(variant("bin-length", [&](auto& b) { put32(b, jsonEnd, 0xFFFFFFF0u); }), {"GLB chunk 1"});
    expectError(variant("bin-unaligned", [&](auto& b) { put32(b, jsonEnd, uint32_t(b.size() - jsonEnd - 8 - 2)); }),
                {"GLB chunk 1", "multiple of 4"});
    expectError(variant("first-chunk", [&](auto& b) { put32(b, 16, 0x004E4942u); }), {"GLB chunk 0", "must be JSON"});
    // An unknown chunk between JSON and BIN is legal (glTF 2.0 4.4.3.1):
    // the file still loads, through the rebuilt container.
    const std::filesystem::path extra = variant("extra-chunk", [&](auto& b) {
        std::vector<uint8_t> chunk(16, 0);
        put32(chunk, 0, 8);
        put32(chunk, 4, 0x54534554u);  // "TEST"
        b.insert(b.begin() + std::ptrdiff_t(jsonEnd), chunk.begin(), chunk.end());
        put32(b, 8, uint32_t(b.size()));
    });
    CHECK(meshTriangleCount(loadGltf(extra)) == meshTriangleCount(loadGltf(source)));
    // The buffer claims more than the BIN chunk holds.
    Json doc = readGlbJson(source);
    doc["buffers"][0]["byteLength"] = doc["buffers"][0]["byteLength"].get<uint64_t>() + 4096;
    std::string text = doc.dump();
    text.resize((text.size() + 3) & ~size_t(3), ' ');
    const std::filesystem::path claim = variant("claim", [&](auto& b) {
        std::vector<uint8_t> out(glb.begin(), glb.begin() + 12);
        std::vector<uint8_t> header(8);
        put32(header, 0, uint32_t(text.size()));
        put32(header, 4, 0x4E4F534Au);
        out.insert(out.end(), header.begin(), header.end());
        out.insert(out.end(), text.begin(), text.end());
        out.insert(out.end(), glb.begin() + std::ptrdiff_t(jsonEnd), glb.end());
        put32(out, 8, uint32_t(out.size()));
        b = out;
    });
    expectError(claim, {"buffer 0", "exceeds the GLB BIN chunk"});
}

TEST_CASE("an image whose header claims enormous dimensions falls back with one warning and no allocation") {
    const std::filesystem::path src = scenesDir() / "CornellBox-Vinc3r";
    const std::filesystem::path dir = outputDir("broken-image");
    for (const char* file : {"cornellBox-2.80-Eevee-gltf.gltf", "cornellBox-2.80-Eevee-gltf.bin"}) {
        std::filesystem::copy_file(src / file, dir / file);
    }
    // PNG signatures and IHDRs only: 20000 x 1000 (wider than the 16384
    // limit) and 100000 x 100000 RGBA (40 GB decoded; stb_image refuses to read its header).
    const auto pngHeader = [](uint32_t w, uint32_t h) {
        std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
        for (uint32_t v : {w, h}) {
            for (int shift = 24; shift >= 0; shift -= 8) {
                png.push_back(uint8_t(v >> shift));
            }
        }
        png.insert(png.end(), {8, 6, 0, 0, 0, 0, 0, 0, 0});
        return png;
    };
    writeBytes(dir / "checker-meter.png", pngHeader(20000, 1000));
    writeBytes(dir / "checkerBJS.png", pngHeader(100000, 100000));
    LogCapture log;
    const Scene scene = loadGltf(dir / "cornellBox-2.80-Eevee-gltf.gltf");
    const std::vector<std::string> warnings = log.lines("warning");
    REQUIRE(warnings.size() == 2);
    const auto warned = [&](const char* a, const char* b) {
        return std::any_of(warnings.begin(), warnings.end(), [&](const std::string& w) {
            return w.find(a) != std::string::npos && w.find(b) != std::string::npos;
        });
    };
    CHECK(warned("checker-meter.png", "20000 x 1000, beyond the limit of 16384"));
    CHECK(warned("checkerBJS.png", "cannot decode image"));
    CHECK(scene.textures.empty());
}

TEST_CASE("randomly corrupted files load or fail with a SceneError, nothing else") {
    // Deterministic mutations: byte flips anywhere in a GLB (headers, JSON,
    // binary data), and digit changes in a .gltf's JSON, which keep it
    // parseable and so reach the accessor checks.
    std::mt19937 rng(1234);
    const std::filesystem::path dir = outputDir("broken-random");
    LogCapture quiet;  // mutants that load may warn (skipped primitives, defaults)
    size_t loaded = 0, refused = 0;
    const auto attempt = [&](const std::filesystem::path& path) {
        try {
            loadGltf(path, {.maxDecodedBytes = 256ull << 20});
            ++loaded;
        } catch (const SceneError& e) {
            CHECK_MESSAGE(std::string(e.what()).find(path.filename().string()) != std::string::npos, e.what());
            ++refused;
        }
    };
    const std::vector<uint8_t> glb = readBytes(scenesDir() / "CornellBox-MetalSuzanne-fazil47/cornell-box.glb");
    for (int i = 0; i < 300; ++i) {
        std::vector<uint8_t> bytes = glb;
        const int flips = 1 + int(rng() % 4);
        for (int k = 0; k < flips; ++k) {
            // Half of the flips land in the first 64 bytes, where the
            // container headers are.
            const size_t at = (rng() % 2) ? rng() % 64 : rng() % bytes.size();
            bytes[at] = uint8_t(rng());
        }
        const std::filesystem::path path = dir / ("glb-" + std::to_string(i) + ".glb");
        writeBytes(path, bytes);
        attempt(path);
    }
    std::filesystem::copy_file(scenesDir() / "Box/Box0.bin", dir / "Box0.bin");
    const std::string text = readJson(scenesDir() / "Box/Box.gltf").dump();
    std::vector<size_t> digits;
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] >= '0' && text[i] <= '9') {
            digits.push_back(i);
        }
    }
    for (int i = 0; i < 300; ++i) {
        std::string mutated = text;
        for (int k = 0; k < 1 + int(rng() % 3); ++k) {
            mutated[digits[rng() % digits.size()]] = char('0' + rng() % 10);
        }
        const std::filesystem::path path = dir / ("box-" + std::to_string(i) + ".gltf");
        writeText(path, mutated);
        attempt(path);
    }
    MESSAGE(loaded << " mutants loaded, " << refused << " refused with a SceneError");
    CHECK(refused > 100);
}
