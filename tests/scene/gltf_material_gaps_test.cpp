// glTF features past the core loader: generated tangents,
// texture coordinate sets, KHR_texture_transform and morph targets, on
// small documents generated here, with the errors their broken variants give.

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/gltf_loader.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/packed_primitives.h"

#include "scene_test_support.h"

#include <glm/gtc/constants.hpp>

// The implementation is in libstb; declarations only.
#include <stb_image_write.h>

#include <functional>
#include <random>

using namespace glint::scene;
using namespace glint::test;

namespace {

// A 2 x 1 PNG: left texel red, right texel green.
std::vector<uint8_t> redGreenPng() {
    const std::vector<uint8_t> pixels = {255, 0, 0, 255, 0, 255, 0, 255};
    std::vector<uint8_t> png;
    stbi_write_png_to_func(
        [](void* context, void* data, int size) {
            auto* out = static_cast<std::vector<uint8_t>*>(context);
            out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
        },
        &png, 2, 1, 4, pixels.data(), 2 * 4);
    REQUIRE(!png.empty());
    return png;
}

// A unit quad in the XY plane facing +Z, glTF-standard UVs (v runs down the
// image, so v = 0 at the top, y = 1), one material sampling the red/green
// texture, one node.
struct QuadFile {
    GltfFixture f;
    int positions = 0;
    int normals = 0;
    int uv0 = 0;
    int uv1 = 0;
    int indices = 0;

    QuadFile() {
        positions = f.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3", 3);
        normals = f.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
        // Set 0 samples the red texel everywhere, set 1 the green one.
        uv0 = f.floats({0.25f, 0.5f, 0.25f, 0.5f, 0.25f, 0.5f, 0.25f, 0.5f}, "VEC2", 2);
        uv1 = f.floats({0.75f, 0.5f, 0.75f, 0.5f, 0.75f, 0.5f, 0.75f, 0.5f}, "VEC2", 2);
        indices = f.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}, 5123, "SCALAR", 1);
        f.doc["images"] = {{{"uri", "data:image/png;base64," + base64(redGreenPng())}}};
        f.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33071}}};  // clamp: texel centres stay exact
        f.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
        f.doc["materials"] = {{{"name", "quad material"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
        f.doc["meshes"] = {{{"name", "quad"},
                            {"primitives",
                             {{{"attributes",
                                {{"POSITION", positions}, {"NORMAL", normals}, {"TEXCOORD_0", uv0}, {"TEXCOORD_1", uv1}}},
                               {"indices", indices},
                               {"material", 0}}}}}};
        f.doc["nodes"] = {{{"mesh", 0}}};
        f.doc["scenes"] = {{{"nodes", {0}}}};
    }

    Json& primitive() { return f.doc["meshes"][0]["primitives"][0]; }
    Json& baseColor() { return f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]; }

    std::filesystem::path write(const std::string& name) const {
        const std::filesystem::path dir = std::filesystem::path(GLINT_TEST_OUTPUT_DIR) / "material-gaps";
        std::filesystem::create_directories(dir);
        writeText(dir / (name + ".gltf"), f.text());
        return dir / (name + ".gltf");
    }
};

void expectError(const std::filesystem::path& file, std::initializer_list<std::string> parts) {
    INFO(file.string());
    try {
        loadGltf(file);
        FAIL("a broken file loaded");
    } catch (const SceneError& e) {
        const std::string what = e.what();
        CHECK_MESSAGE(what.find(file.filename().string()) != std::string::npos, what);
        for (const std::string& part : parts) {
            CHECK_MESSAGE(what.find(part) != std::string::npos, what);
        }
    }
}

glm::vec3 albedoAt(const Scene& scene, uint32_t vertex) {
    const Geometry& g = scene.meshes[0].lods[0].geometries[0];
    return surfaceAtVertex(scene, g, vertex).albedo;
}

} // namespace

// ---------------------------------------------------------------------------
// Tangents
// ---------------------------------------------------------------------------

TEST_CASE("generated tangents form orthonormal right-handed glTF frames on a quad with known UVs") {
    Geometry g;
    g.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    g.normals.assign(4, {0, 0, 1});
    g.indices = {0, 1, 2, 0, 2, 3};
    // glTF UVs: u along +x, v down the image, so along -y.
    g.texcoords0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    // Set 1 mirrors u: the frame's handedness flips.
    g.texcoords1 = {{1, 1}, {0, 1}, {0, 0}, {1, 0}};

    generateTangents(g, 0);
    for (const glm::vec4& t : g.tangents) {
        const glm::vec3 n(0, 0, 1);
        const glm::vec3 tangent(t);
        const glm::vec3 bitangent = glm::cross(n, tangent) * t.w;
        CHECK(glm::length(tangent) == doctest::Approx(1.0f));
        CHECK(glm::dot(tangent, n) == doctest::Approx(0.0f));
        CHECK(t.x == doctest::Approx(1.0f));  // dP/du
        CHECK(t.w == 1.0f);
        // glTF's bitangent points up the image (decreasing v): +y here.
        CHECK(bitangent.y == doctest::Approx(1.0f));
        CHECK(glm::dot(glm::cross(tangent, bitangent), n) == doctest::Approx(1.0f));  // right-handed
    }

    generateTangents(g, 1);
    for (const glm::vec4& t : g.tangents) {
        CHECK(t.x == doctest::Approx(-1.0f));
        CHECK(t.w == -1.0f);  // mirrored mapping
        CHECK((glm::cross(glm::vec3(0, 0, 1), glm::vec3(t)) * t.w).y == doctest::Approx(1.0f));
    }
}

TEST_CASE("the loader generates tangents from the normal texture's coordinate set and keeps a file's TANGENTs") {
    QuadFile q;
    q.f.doc["materials"][0]["normalTexture"] = {{"index", 0}, {"texCoord", 1}, {"scale", 0.5}};
    // Set 1 mirrored in u, so tangents from it point along -x.
    q.primitive()["attributes"]["TEXCOORD_1"] = q.f.floats({1, 1, 0, 1, 0, 0, 1, 0}, "VEC2", 2);
    const Scene generated = loadGltf(q.write("tangents-set1"));
    const Geometry& g = generated.meshes[0].lods[0].geometries[0];
    REQUIRE(g.tangents.size() == 4);
    CHECK(g.tangents[0].x == doctest::Approx(-1.0f));
    CHECK(g.tangents[0].w == -1.0f);
    CHECK(generated.materials[0].normalScale == 0.5f);
    CHECK(generated.materials[0].normalTexture.texCoord == 1);

    // A TANGENT attribute wins; xyz renormalised, w snapped to +-1.
    q.primitive()["attributes"]["TANGENT"] = q.f.floats({0, 2, 0, 0.5f, 0, 2, 0, 1, 0, 2, 0, -3, 0, 2, 0, 1}, "VEC4", 4);
    const Scene given = loadGltf(q.write("tangents-given"));
    const Geometry& h = given.meshes[0].lods[0].geometries[0];
    CHECK(h.tangents[0] == glm::vec4(0, 1, 0, 1));
    CHECK(h.tangents[2] == glm::vec4(0, 1, 0, -1));
}

// ---------------------------------------------------------------------------
// Texture coordinate sets
// ---------------------------------------------------------------------------

TEST_CASE("a texture's texCoord 1 samples the second coordinate set") {
    QuadFile q;
    const Scene set0 = loadGltf(q.write("texcoord0"));
    CHECK(albedoAt(set0, 0).r == doctest::Approx(1.0f));
    CHECK(albedoAt(set0, 0).g == doctest::Approx(0.0f));

    q.baseColor()["texCoord"] = 1;
    const Scene set1 = loadGltf(q.write("texcoord1"));
    CHECK(set1.materials[0].baseColorTexture.texCoord == 1);
    CHECK(albedoAt(set1, 0).r == doctest::Approx(0.0f));
    CHECK(albedoAt(set1, 0).g == doctest::Approx(1.0f));
}

TEST_CASE("texCoord 2 and above are dropped with one warning naming file and material") {
    QuadFile q;
    q.baseColor()["texCoord"] = 2;
    LogCapture log;
    const std::filesystem::path file = q.write("texcoord2");
    const Scene scene = loadGltf(file);
    CHECK_FALSE(scene.materials[0].baseColorTexture.valid());
    const std::vector<std::string> warnings = log.lines("warning");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find(file.filename().string()) != std::string::npos);
    CHECK(warnings[0].find("material 0 ('quad material') baseColorTexture") != std::string::npos);
    CHECK(warnings[0].find("TEXCOORD_2") != std::string::npos);
}

TEST_CASE("alphaMode BLEND and MASK load as glTF says, without warnings") {
    QuadFile q;
    q.f.doc["materials"][0]["alphaMode"] = "BLEND";
    LogCapture log;
    const Scene scene = loadGltf(q.write("blend"));
    CHECK(scene.materials[0].alphaMode == AlphaMode::Blend);
    CHECK(blended(scene, scene.meshes[0].lods[0].geometries[0]));
    q.f.doc["materials"][0]["alphaMode"] = "MASK";
    const Scene masked = loadGltf(q.write("mask"));
    CHECK(masked.materials[0].alphaMode == AlphaMode::Mask);
    CHECK_FALSE(blended(masked, masked.meshes[0].lods[0].geometries[0]));
    CHECK(log.lines("warning").empty());
}

TEST_CASE("a texture whose coordinate set the primitive lacks is an error naming the primitive and material") {
    QuadFile q;
    q.baseColor()["texCoord"] = 1;
    q.primitive()["attributes"].erase("TEXCOORD_1");
    expectError(q.write("texcoord1-missing"),
                {"mesh 'quad' primitive 0", "material 0 ('quad material') baseColorTexture uses TEXCOORD_1"});
    QuadFile r;
    r.baseColor()["texCoord"] = -1;
    expectError(r.write("texcoord-negative"), {"baseColorTexture", "texCoord -1"});
}

// ---------------------------------------------------------------------------
// KHR_texture_transform
// ---------------------------------------------------------------------------

TEST_CASE("KHR_texture_transform maps a known UV as the extension's matrix T * R * S does") {
    using glint::shader::applyUvTransform;
    using glint::shader::makeUvTransform;
    // The extension's README example: offset, then rotation, then scale.
    const glm::vec2 uv(1.0f, 0.5f);
    const float r = glm::half_pi<float>();
    const glm::vec2 out = applyUvTransform(makeUvTransform({0.5f, 0.25f}, r, {2.0f, 4.0f}), uv);
    // S: (2, 2); R (cos 0, sin 1 / -sin, cos): (0*2 + 1*2, -1*2 + 0*2) = (2, -2); T: + offset.
    CHECK(out.x == doctest::Approx(2.5f));
    CHECK(out.y == doctest::Approx(-1.75f));
    CHECK(applyUvTransform(glint::shader::identityUvTransform(), uv) == uv);
}

TEST_CASE("KHR_texture_transform on a texture reference moves its samples and counts as supported") {
    QuadFile q;
    q.f.doc["extensionsUsed"] = {"KHR_texture_transform"};
    // TEXCOORD_0 = (0.25, 0.5) is red; offset 0.5 moves it onto green.
    q.baseColor()["extensions"] = {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}}}};
    LogCapture log;
    const Scene moved = loadGltf(q.write("transform-offset"));
    CHECK(log.lines("info").empty());  // not "ignoring glTF extension"
    CHECK(moved.materials[0].baseColorTexture.offset == glm::vec2(0.5f, 0.0f));
    CHECK(albedoAt(moved, 0).g == doctest::Approx(1.0f));

    // The extension's texCoord overrides the textureInfo's; scale 0 with an
    // offset pins every sample to one point.
    q.baseColor()["extensions"] = {
        {"KHR_texture_transform", {{"texCoord", 1}, {"scale", {0.0, 0.0}}, {"offset", {0.2, 0.5}}, {"rotation", 1.0}}}};
    const Scene pinned = loadGltf(q.write("transform-texcoord"));
    CHECK(pinned.materials[0].baseColorTexture.texCoord == 1);
    CHECK(pinned.materials[0].baseColorTexture.rotation == 1.0f);
    CHECK(albedoAt(pinned, 0).r == doctest::Approx(1.0f));

    q.baseColor()["extensions"] = {{"KHR_texture_transform", {{"offset", {0.5}}}}};
    expectError(q.write("transform-offset-length"), {"baseColorTexture", "offset is not an array of two numbers"});
    q.baseColor()["extensions"] = {{"KHR_texture_transform", {{"texCoord", 1.5}}}};
    expectError(q.write("transform-texcoord-fraction"), {"baseColorTexture", "texCoord must be a non-negative integer"});
    q.baseColor()["extensions"] = {{"KHR_texture_transform", {{"rotation", "a lot"}}}};
    expectError(q.write("transform-rotation-type"), {"baseColorTexture", "rotation is not a number"});
}

// ---------------------------------------------------------------------------
// Morph targets
// ---------------------------------------------------------------------------

namespace {

// A triangle with one morph target lifting every vertex by 2 along z and
// turning its normals from +z to +x, with an animation of the weight from
// 0 at t = 0 to 1 at t = 1.
struct MorphFile {
    GltfFixture f;
    int lift = 0;

    MorphFile() {
        const int positions = f.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
        const int normals = f.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
        lift = f.floats({0, 0, 2, 0, 0, 2, 0, 0, 2}, "VEC3", 3);
        const int turn = f.floats({1, 0, -1, 1, 0, -1, 1, 0, -1}, "VEC3", 3);
        const int times = f.floats({0, 1}, "SCALAR", 1);
        const int values = f.floats({0, 1}, "SCALAR", 1);
        f.doc["meshes"] = {{{"name", "blob"},
                            {"primitives",
                             {{{"attributes", {{"POSITION", positions}, {"NORMAL", normals}}},
                               {"targets", {{{"POSITION", lift}, {"NORMAL", turn}}}}}}},
                            {"weights", {0.25}}}};
        f.doc["nodes"] = {{{"mesh", 0}}};
        f.doc["scenes"] = {{{"nodes", {0}}}};
        f.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", values}}}},
                                {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}}}}};
    }

    std::filesystem::path write(const std::string& name) const {
        const std::filesystem::path dir = std::filesystem::path(GLINT_TEST_OUTPUT_DIR) / "morph";
        std::filesystem::create_directories(dir);
        writeText(dir / (name + ".gltf"), f.text());
        return dir / (name + ".gltf");
    }
};

} // namespace

TEST_CASE("morph weight 0.5 puts positions and normals halfway between the base and the target") {
    MorphFile m;
    m.f.doc.erase("animations");
    m.f.doc["nodes"][0]["weights"] = {0.5};
    const Scene scene = loadGltf(m.write("static"));
    REQUIRE(scene.meshes[0].morphWeights == std::vector<float>{0.25f});  // the mesh's default
    const Instance& inst = scene.instances[0];
    REQUIRE(inst.morphWeights == std::vector<float>{0.5f});              // the node's own
    CHECK(inst.motion == Motion::Dynamic);  // not the shared BLAS of the base shape
    const Geometry& base = scene.meshes[0].lods[0].geometries[0];
    REQUIRE(base.morphTargets.size() == 1);
    const Geometry morphed = morphedGeometry(base, inst.morphWeights);
    for (uint32_t v = 0; v < 3; ++v) {
        CHECK(morphed.positions[v].z == doctest::Approx(1.0f));
        CHECK(morphed.positions[v].x == base.positions[v].x);
        // (0, 0, 1) + 0.5 (1, 0, -1) = (0.5, 0, 0.5), renormalised.
        CHECK(morphed.normals[v].x == doctest::Approx(std::sqrt(0.5f)));
        CHECK(morphed.normals[v].z == doctest::Approx(std::sqrt(0.5f)));
    }
    CHECK(morphed.bounds.max.z == doctest::Approx(1.0f));
    // The mesh's bounds cover the target at full weight.
    CHECK(scene.meshes[0].bounds.max.z == doctest::Approx(2.0f));
    CHECK(scene.meshes[0].bounds.min.z == doctest::Approx(0.0f));
}

TEST_CASE("an animated weights channel drives the instance's morph weights, bumps deformVersion and the BLAS follows") {
    MorphFile m;
    Scene scene = loadGltf(m.write("animated"));
    Instance& inst = scene.instances[0];
    CHECK(inst.motion == Motion::Dynamic);  // own BLAS, rebuilt on deformation
    CHECK(inst.morphWeights == std::vector<float>{0.0f});
    const uint64_t before = inst.deformVersion;
    advanceScene(scene, 0.5);
    REQUIRE(inst.morphWeights.size() == 1);
    CHECK(inst.morphWeights[0] == doctest::Approx(0.5f));
    CHECK(inst.deformVersion == before + 1);
    advanceScene(scene, 0.5);
    CHECK(inst.deformVersion == before + 1);  // unchanged weights: no rebuild

    // The CPU reference of the primitive pool unwraps the morphed shape.
    BvhPlanner planner;
    const BvhPlan plan = planner.plan(scene, glm::vec3(0.0f), 1);
    REQUIRE(plan.blases.size() == 1);
    CHECK(plan.blases[0].instance == 0);
    const std::vector<glint::shader::PackedPrimitive> pool = buildPrimitivePool(scene, plan);
    REQUIRE(pool.size() == 1);
    const glm::vec3 normal = glint::shader::unpackOctNormal(pool[0].vertices[0].normalMetallicReflectance & 0xFFFFu);
    CHECK(normal.x == doctest::Approx(std::sqrt(0.5f)).epsilon(0.02));
}

TEST_CASE("broken morph targets are errors naming the mesh, target and accessor") {
    {
        MorphFile m;
        m.f.doc["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = m.f.floats({0, 0, 2, 0, 0, 2}, "VEC3", 3);
        expectError(m.write("target-count"), {"mesh 'blob' primitive 0 target 0 POSITION", "count 2 differs"});
    }
    {
        MorphFile m;
        m.f.doc["meshes"][0]["primitives"][0]["targets"][0]["NORMAL"] = m.f.floats({0, 0, 0, 0, 0, 0}, "VEC2", 2);
        expectError(m.write("target-type"), {"target 0 NORMAL", "type VEC2 is not allowed"});
    }
    {
        MorphFile m;
        m.f.doc["meshes"][0]["weights"] = {0.5, 0.5};
        expectError(m.write("mesh-weights"), {"mesh 0 ('blob')", "weights has 2 numbers for 1 morph targets"});
    }
    {
        MorphFile m;
        m.f.doc["nodes"][0]["weights"] = {0.5, 0.5, 0.5};
        expectError(m.write("node-weights"), {"node 0", "weights has 3 numbers for the 1 morph targets"});
    }
    {
        MorphFile m;
        m.f.doc["animations"][0]["samplers"][0]["output"] = m.f.floats({0, 1, 2}, "SCALAR", 1);
        expectError(m.write("weights-output"), {"animation 0", "3 values for 2 keys of 1 morph target weights"});
    }
    {
        MorphFile m;
        m.f.doc["meshes"][0]["primitives"][0].erase("targets");
        m.f.doc["meshes"][0].erase("weights");
        expectError(m.write("weights-no-targets"), {"animation 0 channel 0", "whose mesh has no morph targets"});
    }
    {
        MorphFile m;
        Json second = m.f.doc["meshes"][0]["primitives"][0];
        second.erase("targets");
        m.f.doc["meshes"][0]["primitives"].push_back(second);
        expectError(m.write("target-mismatch"), {"primitive 1", "0 morph targets, but primitive 0 has 1"});
    }
}

TEST_CASE("tangents generated for WaterBottle agree with the MikkTSpace TANGENTs the file carries") {
    // The file's tangents come from its exporter's MikkTSpace; ours are not
    // full MikkTSpace (mesh_tools.h), but handedness must agree everywhere
    // the UV mapping is not degenerate, and directions nearly so.
    const Scene scene = loadGltf(scenesDir() / "WaterBottle/WaterBottle.gltf");
    size_t vertices = 0, sameSign = 0, aligned = 0;
    for (const Mesh& mesh : scene.meshes) {
        for (const Geometry& file : mesh.lods[0].geometries) {
            REQUIRE(file.tangents.size() == file.vertexCount());
            Geometry generated = file;
            const Material& material = scene.materials[file.material];
            generateTangents(generated, material.normalTexture.valid() ? material.normalTexture.texCoord : 0);
            for (uint32_t v = 0; v < file.vertexCount(); ++v) {
                ++vertices;
                sameSign += generated.tangents[v].w == file.tangents[v].w;
                aligned += glm::dot(glm::vec3(generated.tangents[v]), glm::vec3(file.tangents[v])) > 0.9f;
            }
        }
    }
    REQUIRE(vertices > 0);
    MESSAGE(vertices << " vertices: " << sameSign << " same handedness, " << aligned << " within 26 degrees");
    CHECK(double(sameSign) / double(vertices) > 0.99);
    CHECK(double(aligned) / double(vertices) > 0.95);
}

TEST_CASE("randomly corrupted morph-target and texture-transform documents load or fail with a SceneError") {
    // Digit changes in the JSON (indices, counts, offsets, weights, texCoord
    // and transform numbers, and the base64 buffer) of a document using
    // every feature of this file; mutants that load are animated and
    // morphed too, so the sanitiser build checks the evaluation as well.
    MorphFile m;
    const int uvs = m.f.floats({0.25f, 0.5f, 0.75f, 0.5f, 0.25f, 0.5f}, "VEC2", 2);
    m.f.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uvs;
    m.f.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = uvs;
    m.f.doc["meshes"][0]["primitives"][0]["material"] = 0;
    m.f.doc["images"] = {{{"uri", "data:image/png;base64," + base64(redGreenPng())}}};
    m.f.doc["textures"] = {{{"source", 0}}};
    m.f.doc["materials"] = {
        {{"pbrMetallicRoughness",
          {{"baseColorTexture",
            {{"index", 0},
             {"texCoord", 1},
             {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0.25}}, {"rotation", 0.3}, {"scale", {2, 3}}}}}}}}}},
         {"normalTexture", {{"index", 0}, {"scale", 0.7}}}}};
    m.f.doc["extensionsUsed"] = {"KHR_texture_transform"};
    m.f.doc["animations"][0]["samplers"][0]["interpolation"] = "STEP";
    const std::string text = Json::parse(m.f.text()).dump();
    std::vector<size_t> digits;
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] >= '0' && text[i] <= '9') digits.push_back(i);
    }
    const std::filesystem::path dir = outputDir("morph-random");
    std::mt19937 rng(4321);
    LogCapture quiet;
    size_t loaded = 0, refused = 0;
    for (int i = 0; i < 300; ++i) {
        std::string mutated = text;
        for (int k = 0; k < 1 + int(rng() % 3); ++k) {
            mutated[digits[rng() % digits.size()]] = char('0' + rng() % 10);
        }
        const std::filesystem::path path = dir / ("morph-" + std::to_string(i) + ".gltf");
        writeText(path, mutated);
        try {
            Scene scene = loadGltf(path, {.maxDecodedBytes = 64ull << 20});
            for (const double t : {0.25, 0.75, 3.0}) {
                advanceScene(scene, t);
                for (const Instance& inst : scene.instances) {
                    for (const Geometry& g : scene.meshes[inst.mesh].lods[0].geometries) {
                        const Geometry morphed = morphedGeometry(g, inst.morphWeights);
                        for (uint32_t v = 0; v < morphed.vertexCount(); ++v) {
                            (void)surfaceAtVertex(scene, morphed, v);
                        }
                    }
                }
            }
            ++loaded;
        } catch (const SceneError& e) {
            CHECK_MESSAGE(std::string(e.what()).find(path.filename().string()) != std::string::npos, e.what());
            ++refused;
        }
    }
    MESSAGE(loaded << " mutants loaded, " << refused << " refused with a SceneError");
    CHECK(loaded > 30);
    CHECK(refused > 30);
}
