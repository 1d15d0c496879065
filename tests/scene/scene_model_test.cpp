// The scene model's own logic: texture sampling, validation, the
// environment mapping and HDR loading, and the CPU reference of the packed
// primitive pass.

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/image_io.h"
#include "glint/scene/packed_primitives.h"
#include "glint/scene/procedural_meshes.h"
#include "glint/scene/scene.h"

#include "scene_test_support.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

// The implementation is in libstb; declarations only.
#include <stb_image_write.h>

using namespace glint::scene;

namespace {

Texture rgba8(uint32_t width, uint32_t height, std::vector<uint8_t> texels) {
    Texture t;
    t.width = width;
    t.height = height;
    t.rgba8 = std::move(texels);
    return t;
}

} // namespace

TEST_CASE("bilinear sampling repeats, clamps and mirrors like glTF's sampler wrap modes") {
    // Two texels: red 0 and red 1.
    const Texture t = rgba8(2, 1, {0, 0, 0, 255, 255, 0, 0, 255});
    const auto red = [&](float u, Wrap wrap) { return sampleBilinear(t, {u, 0.5f}, wrap, Wrap::Repeat).r; };
    CHECK(red(0.25f, Wrap::ClampToEdge) == doctest::Approx(0.0f));
    CHECK(red(0.75f, Wrap::ClampToEdge) == doctest::Approx(1.0f));
    CHECK(red(0.5f, Wrap::ClampToEdge) == doctest::Approx(0.5f));
    CHECK(red(-0.25f, Wrap::Repeat) == doctest::Approx(1.0f));
    CHECK(red(1.25f, Wrap::Repeat) == doctest::Approx(0.0f));
    CHECK(red(0.0f, Wrap::Repeat) == doctest::Approx(0.5f));  // halfway between texel 1 (wrapped) and 0
    CHECK(red(-0.25f, Wrap::ClampToEdge) == doctest::Approx(0.0f));
    CHECK(red(1.25f, Wrap::ClampToEdge) == doctest::Approx(1.0f));
    CHECK(red(1.25f, Wrap::MirroredRepeat) == doctest::Approx(1.0f));
    CHECK(red(1.75f, Wrap::MirroredRepeat) == doctest::Approx(0.0f));
    CHECK(red(-0.25f, Wrap::MirroredRepeat) == doctest::Approx(0.0f));
    for (float u : {1e30f, -1e30f, std::numeric_limits<float>::infinity(), std::nanf("")}) {
        for (Wrap w : {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat}) {
            const float r = red(u, w);
            CHECK(r >= 0.0f);
            CHECK(r <= 1.0f);
        }
    }
}

TEST_CASE("validateScene names the scene and the element that is wrong") {
    Scene s;
    s.name = "hand-made";
    s.materials.emplace_back();
    Mesh m;
    m.name = "quad";
    m.lods.push_back({{makeGrid({1, 1}, {1, 1}, 0)}});
    s.meshes.push_back(m);
    s.instances.push_back({});
    validateScene(s);
    s.meshes[0].lods[0].geometries[0].indices[4] = 99;
    try {
        validateScene(s);
        FAIL("an index beyond the vertices passed");
    } catch (const SceneError& e) {
        CHECK(e.file() == "hand-made");
        CHECK(e.element() == "mesh 0 ('quad') lod 0 geometry 0");
        CHECK(std::string(e.what()).find("index 99 at position 4 >= vertex count 4") != std::string::npos);
    }
    s.meshes[0].lods[0].geometries[0].indices[4] = 0;
    s.instances[0].motion = Motion::Skinned;
    CHECK_THROWS_AS(validateScene(s), SceneError);  // skinned without a skin
    s.instances[0].motion = Motion::Static;
    s.instances[0].mesh = 3;
    CHECK_THROWS_AS(validateScene(s), SceneError);
}

TEST_CASE("equirectangular coordinates round-trip directions with -Z at the image centre and +Y at the top") {
    CHECK(glm::length(equirectUv({0, 0, -1}) - glm::vec2(0.5f, 0.5f)) < 1e-6f);
    CHECK(equirectUv({0, 1, 0}).y == doctest::Approx(0.0f));
    CHECK(equirectUv({0, -1, 0}).y == doctest::Approx(1.0f));
    CHECK(equirectUv({1, 0, 0}).x == doctest::Approx(0.75f));
    for (const glm::vec3& d : {glm::vec3(0.3f, 0.4f, -0.2f), glm::vec3(-1, 0.1f, 0.2f), glm::vec3(0.1f, -0.9f, 0.4f)}) {
        CHECK(glm::length(equirectDirection(equirectUv(d)) - glm::normalize(d)) < 1e-5f);
    }
}

TEST_CASE("an equirectangular HDR loads as float RGBA; a broken or non-2:1 one is an error") {
    const std::filesystem::path dir = glint::test::outputDir("hdr");
    std::vector<float> rgb(8 * 4 * 3);
    for (size_t i = 0; i < rgb.size(); ++i) {
        rgb[i] = 0.25f * float(i % 7) + 10.0f * float(i % 3 == 0);  // HDR values well above 1
    }
    REQUIRE(stbi_write_hdr((dir / "sky.hdr").string().c_str(), 8, 4, 3, rgb.data()));
    const Environment env = loadEquirectangularEnvironment(dir / "sky.hdr");
    CHECK(env.kind == EnvironmentKind::EquirectangularImage);
    REQUIRE(env.image.width == 8);
    REQUIRE(env.image.height == 4);
    REQUIRE(env.image.format == TextureFormat::Rgba32Float);
    for (uint32_t p = 0; p < 32; ++p) {
        for (int c = 0; c < 3; ++c) {
            // RGBE keeps 8 bits of mantissa per pixel: within 1% of the brightest channel.
            const float bright = std::max({rgb[p * 3], rgb[p * 3 + 1], rgb[p * 3 + 2]});
            CHECK(std::abs(env.image.rgba32f[p * 4 + c] - rgb[p * 3 + c]) <= 0.01f * bright + 1e-6f);
        }
    }
    REQUIRE(stbi_write_hdr((dir / "square.hdr").string().c_str(), 4, 4, 3, rgb.data()));
    CHECK_THROWS_AS(loadEquirectangularEnvironment(dir / "square.hdr"), SceneError);
    const std::vector<uint8_t> bytes = glint::test::readBytes(dir / "sky.hdr");
    glint::test::writeBytes(dir / "cut.hdr", bytes.data(), 20);
    CHECK_THROWS_AS(loadEquirectangularEnvironment(dir / "cut.hdr"), SceneError);
    CHECK_THROWS_AS(loadEquirectangularEnvironment(dir / "missing.hdr"), SceneError);
    ImageLimits tiny;
    tiny.maxDimension = 4;
    CHECK_THROWS_AS(loadEquirectangularEnvironment(dir / "sky.hdr", tiny), SceneError);
}

TEST_CASE("packed primitives carry the material sampled at each vertex") {
    Scene s;
    s.name = "packing";
    // 2 x 2 textures; the quad's corners sit on texel centres.
    s.textures.push_back(rgba8(2, 2, {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 128, 128, 128, 255}));
    s.textures.push_back(rgba8(2, 2, {255, 51, 0, 255, 255, 102, 255, 255, 255, 204, 0, 255, 255, 255, 255, 255}));
    Material m;
    m.baseColorFactor = {0.5f, 1.0f, 1.0f, 1.0f};
    m.roughnessFactor = 1.0f;
    m.metallicFactor = 1.0f;
    m.reflectance = 0.7f;
    m.baseColorTexture.texture = 0;
    m.metallicRoughnessTexture.texture = 1;
    s.materials.push_back(m);
    Geometry g;
    g.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    g.normals = {{0, 0, 1}, {0, 0, 1}, {0.6f, 0, 0.8f}, {0, 0, 1}};
    g.texcoords0 = {{0.25f, 0.25f}, {0.75f, 0.25f}, {0.25f, 0.75f}, {0.75f, 0.75f}};
    g.indices = {0, 1, 2, 2, 1, 3};
    const UnwrappedGeometry u = unwrapGeometry(s, g);
    REQUIRE(u.primitives.size() == 2);
    REQUIRE(u.positions.size() == 6);
    CHECK(u.positions[5] == glm::vec3(1, 1, 0));
    const auto vertex = [&](int prim, int k) {
        return glint::shader::unpackVertex(u.primitives[size_t(prim)].vertices[k]);
    };
    const float code = 1.0f / 255.0f;
    // Vertex 0: red texel times factor 0.5: linear albedo 0.5.
    CHECK(vertex(0, 0).albedo.r == doctest::Approx(0.5f).epsilon(0.01));
    CHECK(vertex(0, 0).albedo.g == doctest::Approx(0.0f));
    CHECK(vertex(0, 0).roughness == doctest::Approx(0.2f).epsilon(code));
    CHECK(vertex(0, 0).metallic == doctest::Approx(0.0f));
    CHECK(vertex(0, 0).reflectance == doctest::Approx(0.7f).epsilon(code));
    // Vertex 1: green texel, roughness 0.4, metallic 1.
    CHECK(vertex(0, 1).albedo.g == doctest::Approx(1.0f).epsilon(0.01));
    CHECK(vertex(0, 1).roughness == doctest::Approx(0.4f).epsilon(code));
    CHECK(vertex(0, 1).metallic == doctest::Approx(1.0f));
    // Vertex 2: its own normal survives the octahedral encoding.
    CHECK(glm::length(vertex(0, 2).normal - glm::vec3(0.6f, 0, 0.8f)) < 0.012f);
    // Vertex 3: sRGB grey 128 is linear 0.2158, times factor 0.5 in red.
    CHECK(vertex(1, 2).albedo.r == doctest::Approx(0.5f * 0.2158f).epsilon(0.02));
    CHECK(vertex(1, 2).albedo.g == doctest::Approx(0.2158f).epsilon(0.02));

    // Skinned: each vertex follows its joint's matrix; normals rotate too.
    g.joints = {{0, 0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 0}, {0, 1, 0, 0}};
    g.weights = {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {0.5f, 0.5f, 0, 0}};
    const std::vector<glm::mat4> joints = {glm::translate(glm::mat4(1.0f), {0, 0, 2}),
                                           glm::rotate(glm::mat4(1.0f), glm::half_pi<float>(), {0, 1, 0})};
    const UnwrappedGeometry skinned = unwrapGeometry(s, g, joints);
    CHECK(glm::length(skinned.positions[0] - glm::vec3(0, 0, 2)) < 1e-6f);
    CHECK(glm::length(skinned.positions[1] - glm::vec3(0, 0, -1)) < 1e-6f);  // (1,0,0) turned about Y
    CHECK(glm::length(skinned.positions[5] - 0.5f * (glm::vec3(1, 1, 2) + glm::vec3(0, 1, -1))) < 1e-6f);
    const glm::vec3 turned = glint::shader::unpackVertex(skinned.primitives[0].vertices[1]).normal;
    CHECK(glm::length(turned - glm::vec3(1, 0, 0)) < 0.012f);  // +Z turned 90 degrees about Y
}
