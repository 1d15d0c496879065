// The ray tracer's alpha test data, CPU side (scene/alpha_test.h): per
// triangle the base colour texture's coordinates (transformed, moved by
// whole wrap periods so half floats keep them precise) and the vertex
// alpha; the alpha mask layers resampled from the texture's alpha.

#include "glint/scene/alpha_test.h"

#include <doctest/doctest.h>

#include <glm/gtc/packing.hpp>

#include <cmath>

using namespace glint;
using namespace glint::scene;

namespace {

Scene triangleScene(glm::vec2 uv0, glm::vec2 uv1, glm::vec2 uv2) {
    Scene s;
    Material m;
    m.alphaMode = AlphaMode::Mask;
    m.baseColorFactor = {1.0f, 1.0f, 1.0f, 0.5f};
    m.baseColorTexture.texture = 0;
    s.materials = {m};
    Texture t;
    t.width = t.height = 2;
    t.rgba8.assign(16, 255);
    s.textures = {t};
    Geometry g;
    g.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    g.texcoords0 = {uv0, uv1, uv2};
    g.colors = {{1, 1, 1, 1.0f}, {1, 1, 1, 0.5f}, {1, 1, 1, 0.0f}};
    g.indices = {0, 1, 2};
    Mesh mesh;
    mesh.lods.push_back({{g}});
    s.meshes = {mesh};
    return s;
}

glm::vec2 uvOf(const shader::AlphaTriangle& t, int k) { return glm::unpackHalf2x16(t.uv[k]); }

} // namespace

TEST_CASE("alpha triangles: factor x COLOR_0 alpha per vertex, coordinates moved by whole periods of the wrap") {
    // A triangle far out in a repeating texture's coordinates: 1000.25 is
    // not exact in half floats (steps of 0.5 there), 0.25 is.
    Scene s = triangleScene({1000.25f, -3.75f}, {1000.75f, -3.75f}, {1000.25f, -3.25f});
    REQUIRE(alphaTested(s.materials[0]));
    std::vector<shader::AlphaTriangle> t = alphaTriangles(s, s.meshes[0].lods[0].geometries[0]);
    REQUIRE(t.size() == 1u);
    CHECK((t[0].alpha & 0xFFu) == 128u);          // 0.5 x 1
    CHECK(((t[0].alpha >> 8) & 0xFFu) == 64u);    // 0.5 x 0.5
    CHECK(((t[0].alpha >> 16) & 0xFFu) == 0u);    // 0.5 x 0
    CHECK(uvOf(t[0], 0) == glm::vec2(0.25f, 0.25f));
    CHECK(uvOf(t[0], 1) == glm::vec2(0.75f, 0.25f));
    CHECK(uvOf(t[0], 2) == glm::vec2(0.25f, 0.75f));

    // Mirrored repeat: a period is two copies, so 3.25 moves to 1.25 (still
    // the mirrored copy); clamped: held to [-1, 2].
    s.materials[0].baseColorTexture.wrapS = Wrap::MirroredRepeat;
    s.materials[0].baseColorTexture.wrapT = Wrap::ClampToEdge;
    s.meshes[0].lods[0].geometries[0].texcoords0 = {{3.25f, 5.0f}, {3.5f, 0.5f}, {3.25f, -7.0f}};
    t = alphaTriangles(s, s.meshes[0].lods[0].geometries[0]);
    CHECK(uvOf(t[0], 0) == glm::vec2(1.25f, 2.0f));
    CHECK(uvOf(t[0], 1) == glm::vec2(1.5f, 0.5f));
    CHECK(uvOf(t[0], 2) == glm::vec2(1.25f, -1.0f));
    CHECK(alphaMaskWord(s.materials[0], 3) == (3u | shader::kAlphaWrapMirror << shader::kAlphaWrapShiftU |
                                               shader::kAlphaWrapClamp << shader::kAlphaWrapShiftV));

    // KHR_texture_transform applies before the shift: scale 2 then offset.
    s.materials[0].baseColorTexture.wrapS = s.materials[0].baseColorTexture.wrapT = Wrap::Repeat;
    s.materials[0].baseColorTexture.scale = {2.0f, 2.0f};
    s.materials[0].baseColorTexture.offset = {0.5f, 0.0f};
    s.meshes[0].lods[0].geometries[0].texcoords0 = {{0.0f, 0.0f}, {0.25f, 0.0f}, {0.0f, 0.25f}};
    t = alphaTriangles(s, s.meshes[0].lods[0].geometries[0]);
    CHECK(uvOf(t[0], 0) == glm::vec2(0.5f, 0.0f));
    CHECK(uvOf(t[0], 1) == glm::vec2(1.0f, 0.0f));
    CHECK(uvOf(t[0], 2) == glm::vec2(0.5f, 0.5f));

    // Opaque and blended materials are not alpha-tested by rays.
    s.materials[0].alphaMode = AlphaMode::Opaque;
    CHECK_FALSE(alphaTested(s.materials[0]));
    s.materials[0].alphaMode = AlphaMode::Blend;
    CHECK_FALSE(alphaTested(s.materials[0]));
}

TEST_CASE("alpha mask texels: the texture's alpha resampled to the layer size, the rest of the texel ignored") {
    Texture t;
    t.width = 4;
    t.height = 2;
    // Left half transparent, right half opaque; colours that must not leak.
    for (uint32_t y = 0; y < 2; ++y) {
        for (uint32_t x = 0; x < 4; ++x) {
            t.rgba8.insert(t.rgba8.end(), {uint8_t(60 * x), 200, 17, uint8_t(x < 2 ? 0 : 255)});
        }
    }
    const std::vector<uint8_t> same = alphaMaskTexels(t, 4);  // not square: resampled
    REQUIRE(same.size() == 16u);
    const std::vector<uint8_t> big = alphaMaskTexels(t, 32);
    REQUIRE(big.size() == 32u * 32u);
    for (uint32_t y = 0; y < 32; ++y) {
        CAPTURE(y);
        // Away from the edges (the resize wraps): clear left, opaque right.
        CHECK(big[y * 32 + 4] < 16);
        CHECK(big[y * 32 + 11] < 16);
        CHECK(big[y * 32 + 20] > 239);
        CHECK(big[y * 32 + 27] > 239);
    }
    Texture square;
    square.width = square.height = 2;
    square.rgba8 = {9, 9, 9, 10, 9, 9, 9, 20, 9, 9, 9, 30, 9, 9, 9, 40};
    CHECK(alphaMaskTexels(square, 2) == std::vector<uint8_t>{10, 20, 30, 40});
}
