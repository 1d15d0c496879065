// The G-buffer pass (passes/gbuffer.h) on a real device, validation and
// synchronization validation on: planes at known places give the analytic
// reversed-Z depth, normal and material; moving objects and a moving camera
// give the analytic motion in pixels; the plaza renders finite and covered;
// textures are sampled through their coordinate sets and transforms. The
// sun's shadow map has its own file (gbuffer_shadow_test.cpp).
#include "gbuffer_harness.h"
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/gbuffer.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/procedural_meshes.h"

#include "glint/packing.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <string>

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr float kNear = test::kPassTestNear;
using test::square;
using test::testCamera;
using gbuffer_test::GBufferImage;
using gbuffer_test::Readback;
using gbuffer_test::render;

// One material, one mesh of the given geometry, one static instance.
scene::Scene singleObjectScene(scene::Geometry geometry, const scene::Material& material) {
    scene::Scene s;
    s.name = "gbuffer-test";
    s.materials.push_back(material);
    scene::Mesh mesh;
    mesh.name = "object";
    mesh.lods.push_back({{std::move(geometry)}});
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "object";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}


bool finite(glm::vec4 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

int srgbByte(float linear) {
    return int(shader::encodeUnorm8(shader::linearToSrgb(linear)));
}

} // namespace

TEST_CASE("a plane facing the camera gives the reversed-Z depth, its normal and its material everywhere") {
    test::GpuTest gpu;
    scene::Material material;
    material.baseColorFactor = {0.8f, 0.4f, 0.2f, 1.0f};
    material.roughnessFactor = 0.3f;
    material.metallicFactor = 0.7f;
    constexpr float kDistance = 5.0f;
    const scene::Scene scene =
        singleObjectScene(square({0, 0, -kDistance}, {1, 0, 0}, {0, 1, 0}, 20.0f), material);
    const GBufferImage img = render(gpu, scene, {testCamera()});

    // Infinite far plane: depth = near / distance (glint/scene/camera.cpp).
    const float expectedDepth = kNear / kDistance;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y);
            const size_t i = img.at(x, y);
            REQUIRE(std::abs(img.depth[i] - expectedDepth) < 1e-5f);
            REQUIRE(std::abs(img.normal[i].x) < 1e-3f);
            REQUIRE(std::abs(img.normal[i].y) < 1e-3f);
            REQUIRE(std::abs(img.normal[i].z - 1.0f) < 1e-3f);
            REQUIRE(img.normal[i].w == 1.0f);
            REQUIRE(std::abs(int(img.albedo[i].r) - srgbByte(0.8f)) <= 1);
            REQUIRE(std::abs(int(img.albedo[i].g) - srgbByte(0.4f)) <= 1);
            REQUIRE(std::abs(int(img.albedo[i].b) - srgbByte(0.2f)) <= 1);
            REQUIRE(std::abs(int(img.roughnessMetal[i].r) - int(shader::encodeUnorm8(0.3f))) <= 1);
            REQUIRE(std::abs(int(img.roughnessMetal[i].g) - int(shader::encodeUnorm8(0.7f))) <= 1);
            REQUIRE(img.motion[i] == glm::vec2(0.0f));  // nothing moved
            REQUIRE(finite(img.lit[i]));
            REQUIRE(img.lit[i].r > 0.0f);
        }
    }
}

TEST_CASE("a constant tilted normal map tilts the G-buffer normal of a plane by its tangent frame and scale") {
    // The tangent-space normal (0.5, -0.3, 0.81) stored as 8-bit texels; the
    // plane faces +Z with glTF UVs (u along +x, v down the image, so along
    // -y): generated tangent +x, bitangent +y.
    const glm::vec3 tilted = glm::normalize(glm::vec3(0.5f, -0.3f, 0.81f));
    const glm::u8vec4 texel(glm::round((tilted * 0.5f + 0.5f) * 255.0f), 255);
    const glm::vec3 stored = glm::vec3(texel) / 255.0f * 2.0f - 1.0f;  // what the sampler returns, decoded

    for (const float scale : {1.0f, 0.5f}) {
        INFO("normalTexture.scale " << scale);
        test::GpuTest gpu;
        scene::Geometry plane = square({0, 0, -5}, {1, 0, 0}, {0, 1, 0}, 20.0f);
        for (const glm::vec3& p : plane.positions) {
            plane.texcoords0.push_back({p.x / 40.0f + 0.5f, 0.5f - p.y / 40.0f});
        }
        scene::generateTangents(plane);
        scene::Material material;
        material.normalTexture.texture = 0;
        material.normalScale = scale;
        scene::Scene scene = [&] {
            scene::Scene s;
            s.name = "gbuffer-normal-map-test";
            scene::Texture texture;
            texture.name = "tilted";
            texture.width = texture.height = 4;
            for (int i = 0; i < 16; ++i) texture.rgba8.insert(texture.rgba8.end(), {texel.r, texel.g, texel.b, 255});
            s.textures.push_back(texture);
            s.materials.push_back(material);
            scene::Mesh mesh;
            mesh.lods.push_back({{plane}});
            s.meshes.push_back(std::move(mesh));
            s.instances.push_back({});
            scene::prepareScene(s);
            return s;
        }();
        passes::GBufferStats stats;
        const GBufferImage img = render(gpu, scene, {testCamera()}, &stats);
        CHECK(stats.normalMaps == 1);
        CHECK(stats.normalMappedDraws == 1);

        const glm::vec3 expected = glm::normalize(glm::vec3(stored.x * scale, stored.y * scale, stored.z));
        // Against the unquantised normal too: within 8-bit quantisation.
        const glm::vec3 ideal = glm::normalize(glm::vec3(tilted.x * scale, tilted.y * scale, tilted.z));
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("pixel " << x << ", " << y);
                const glm::vec3 n(img.normal[img.at(x, y)]);
                REQUIRE(glm::length(n - expected) < 2e-3f);  // half-float output
                REQUIRE(glm::length(n - ideal) < 2.0f / 255.0f * 2.0f);
            }
        }
    }
}

TEST_CASE("the normal map is sampled through its texture reference's coordinate set and KHR_texture_transform") {
    // Two texels: left tilted, right flat. Constant UVs sit on texel centres
    // (u = 0.25 left, 0.75 right), so bilinear filtering returns one texel.
    const glm::vec3 tilted = glm::normalize(glm::vec3(0.6f, 0.0f, 0.8f));
    const glm::u8vec4 left(glm::round((tilted * 0.5f + 0.5f) * 255.0f), 255);
    const glm::u8vec4 right(128, 128, 255, 255);
    struct Case {
        const char* what;
        uint32_t texCoord;
        glm::vec2 offset;
        bool expectTilted;
    };
    for (const Case& c : {Case{"set 0, identity", 0, {0.0f, 0.0f}, true},
                          Case{"set 0, offset half a texture", 0, {0.5f, 0.0f}, false},
                          Case{"set 1, identity", 1, {0.0f, 0.0f}, false},
                          Case{"set 1, offset back", 1, {-0.5f, 0.0f}, true}}) {
        INFO(c.what);
        test::GpuTest gpu;
        scene::Geometry plane = square({0, 0, -5}, {1, 0, 0}, {0, 1, 0}, 20.0f);
        plane.texcoords0.assign(4, {0.25f, 0.5f});
        plane.texcoords1.assign(4, {0.75f, 0.5f});
        plane.tangents.assign(4, {1.0f, 0.0f, 0.0f, 1.0f});
        scene::Scene s;
        s.name = "gbuffer-normal-map-uv-test";
        scene::Texture texture;
        texture.name = "left tilted, right flat";
        texture.width = 2;
        texture.height = 1;
        texture.rgba8 = {left.r, left.g, left.b, 255, right.r, right.g, right.b, 255};
        s.textures.push_back(texture);
        scene::Material material;
        material.normalTexture.texture = 0;
        material.normalTexture.texCoord = c.texCoord;
        material.normalTexture.offset = c.offset;
        s.materials.push_back(material);
        scene::Mesh mesh;
        mesh.lods.push_back({{plane}});
        s.meshes.push_back(std::move(mesh));
        s.instances.push_back({});
        scene::prepareScene(s);
        const GBufferImage img = render(gpu, s, {testCamera()});
        const glm::vec3 expected = c.expectTilted ? glm::vec3(glm::vec3(left) / 255.0f * 2.0f - 1.0f) : glm::vec3(0, 0, 1);
        const glm::vec3 n(img.normal[img.at(kSize / 2, kSize / 2)]);
        CHECK(glm::length(n - glm::normalize(expected)) < 0.01f);
    }
}

TEST_CASE("a morphing plane is drawn, and casts its shadow, where its morph weights put it") {
    // A plane at distance 5 whose one morph target moves it 2 towards the
    // camera: weight 0.5 puts it at distance 4, weight 0 leaves it at 5.
    for (const float weight : {0.0f, 0.5f}) {
        INFO("weight " << weight);
        test::GpuTest gpu;
        scene::Geometry plane = square({0, 0, -5}, {1, 0, 0}, {0, 1, 0}, 20.0f);
        scene::MorphTarget target;
        target.positions.assign(4, {0, 0, 2});
        plane.morphTargets.push_back(target);
        scene::Scene s;
        s.name = "gbuffer-morph-test";
        s.materials.emplace_back();
        scene::Mesh mesh;
        mesh.lods.push_back({{plane}});
        mesh.morphWeights = {weight};
        s.meshes.push_back(std::move(mesh));
        s.instances.push_back({});
        scene::prepareScene(s);
        passes::GBufferStats stats;
        const GBufferImage img = render(gpu, s, {testCamera()}, &stats);
        CHECK(stats.shadowDraws == 1);
        const float expectedDepth = kNear / (5.0f - 2.0f * weight);
        for (uint32_t y = 0; y < kSize; y += 7) {
            for (uint32_t x = 0; x < kSize; x += 7) {
                INFO("pixel " << x << ", " << y);
                REQUIRE(std::abs(img.depth[img.at(x, y)] - expectedDepth) < 1e-5f);
            }
        }
    }
}

TEST_CASE("a plane the sun grazes is lit by the sky alone: albedo / pi times the hemisphere irradiance") {
    test::GpuTest gpu;
    scene::Material material;
    material.baseColorFactor = {0.5f, 0.6f, 0.7f, 1.0f};
    material.metallicFactor = 0.0f;
    scene::Scene scene = singleObjectScene(square({0, 0, -5}, {1, 0, 0}, {0, 1, 0}, 20.0f), material);
    // The sun straight up is parallel to the plane (normal +Z): N.L = 0.
    scene.sun.directionToLight = {0, 1, 0};
    scene.environment.sky.zenithColor = {0.2f, 0.3f, 0.6f};
    scene.environment.sky.horizonColor = {0.8f, 0.7f, 0.6f};
    scene.environment.sky.groundColor = {0.1f, 0.1f, 0.1f};
    const GBufferImage img = render(gpu, scene, {testCamera()});

    // glint/brdf.glsl skyIrradiance for n.y = 0: the mean of the upward
    // (pi * mean of horizon and zenith) and downward (pi * ground) irradiance.
    const scene::ProceduralSky& sky = scene.environment.sky;
    const glm::vec3 up = glm::pi<float>() * 0.5f * (sky.horizonColor + sky.zenithColor);
    const glm::vec3 down = glm::pi<float>() * sky.groundColor;
    const glm::vec3 expected = glm::vec3(material.baseColorFactor) / glm::pi<float>() * 0.5f * (up + down);
    for (size_t i = 0; i < img.lit.size(); ++i) {
        INFO("pixel " << i % kSize << ", " << i / kSize);
        for (int c = 0; c < 3; ++c) {
            REQUIRE(std::abs(img.lit[i][c] - expected[c]) < 2e-3f * expected[c]);  // half precision
        }
    }
}

TEST_CASE("the nearer of two overlapping planes wins whichever is drawn first") {
    test::GpuTest gpu;
    scene::Scene scene;
    scene.name = "gbuffer-test-two-planes";
    scene::Material red, blue;
    red.baseColorFactor = {1, 0, 0, 1};
    blue.baseColorFactor = {0, 0, 1, 1};
    scene.materials = {red, blue};
    // Drawn in instance order; the subcases draw them both ways round.
    for (const float distance : {3.0f, 6.0f}) {
        scene::Geometry g = square({0, 0, -distance}, {1, 0, 0}, {0, 1, 0}, 50.0f);
        g.material = distance < 4.0f ? 0 : 1;
        scene::Mesh mesh;
        mesh.name = "plane";
        mesh.lods.push_back({{std::move(g)}});
        scene.meshes.push_back(std::move(mesh));
    }
    scene::Instance nearPlane, farPlane;
    nearPlane.mesh = 0;
    farPlane.mesh = 1;
    SUBCASE("near first") { scene.instances = {nearPlane, farPlane}; }
    SUBCASE("far first") { scene.instances = {farPlane, nearPlane}; }
    scene::prepareScene(scene);
    const GBufferImage img = render(gpu, scene, {testCamera()});
    for (size_t i = 0; i < img.depth.size(); ++i) {
        INFO("pixel " << i % kSize << ", " << i / kSize);
        REQUIRE(std::abs(img.depth[i] - kNear / 3.0f) < 1e-5f);
        REQUIRE(img.albedo[i] == glm::u8vec4(255, 0, 0, 255));
    }
}

TEST_CASE("a floor below the camera has the analytic depth per pixel, and the sky fills the rest") {
    test::GpuTest gpu;
    const scene::Scene scene = singleObjectScene(square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f), {});
    const GBufferImage img = render(gpu, scene, {testCamera()});

    uint32_t floorPixels = 0, skyPixels = 0;
    for (uint32_t y = 0; y < kSize; ++y) {
        // Pixel centre in NDC; +y is down the image (the projection flips Y).
        const float ndcY = (float(y) + 0.5f) / float(kSize) * 2.0f - 1.0f;
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y);
            const size_t i = img.at(x, y);
            if (ndcY > 0.0f) {
                // The view ray (ndcX, -ndcY, -1) (tan 45 = 1) meets y = -1 at
                // view distance 1 / ndcY, so depth = near * ndcY.
                REQUIRE(std::abs(img.depth[i] - kNear * ndcY) < 1e-5f);
                REQUIRE(std::abs(img.normal[i].y - 1.0f) < 1e-3f);
                ++floorPixels;
            } else {
                REQUIRE(img.depth[i] == 0.0f);
                REQUIRE(img.normal[i].w == 0.0f);  // no surface
                REQUIRE(finite(img.lit[i]));
                REQUIRE(img.lit[i].b > 0.0f);  // sky radiance
                ++skyPixels;
            }
        }
    }
    CHECK(floorPixels == kSize * kSize / 2);
    CHECK(skyPixels == kSize * kSize / 2);
}

TEST_CASE("an object moving sideways gives its motion in pixels, from this frame back to the last") {
    test::GpuTest gpu;
    constexpr float kDistance = 4.0f;
    scene::Scene scene = singleObjectScene(square({0, 0, -kDistance}, {1, 0, 0}, {0, 1, 0}, 1.0f), {});
    // Moved +1 in x since last frame: last frame it was 1 unit to the left.
    scene.instances[0].transform = glm::translate(glm::mat4(1.0f), glm::vec3(1.0f, 0.0f, 0.0f));
    scene.instances[0].previousTransform = glm::mat4(1.0f);
    const GBufferImage img = render(gpu, scene, {testCamera()});

    const float expected = -float(kSize) / (2.0f * kDistance);  // -8 pixels
    uint32_t covered = 0;
    for (size_t i = 0; i < img.depth.size(); ++i) {
        if (img.normal[i].w == 0.0f) {
            // Sky, static camera: zero up to the rounding of reprojecting a
            // point at infinity (NVIDIA gives ~1e-6 px where lavapipe gives 0).
            CHECK(glm::length(img.motion[i]) < 1e-3f);
            continue;
        }
        ++covered;
        INFO("pixel " << i % kSize << ", " << i / kSize);
        REQUIRE(std::abs(img.motion[i].x - expected) < 0.02f);
        REQUIRE(std::abs(img.motion[i].y) < 0.02f);
    }
    // The square spans x in [0, 2], y in [-1, 1] at distance 4: 16 x 16 pixels.
    CHECK(covered == 16 * 16);
}

TEST_CASE("a morph that moved the vertices since last frame gives their motion in pixels") {
    // The sideways case above, with the move made by a morph target (+1 in
    // x at weight 1) instead of the instance transform.
    test::GpuTest gpu;
    constexpr float kDistance = 4.0f;
    scene::Geometry square1 = square({0, 0, -kDistance}, {1, 0, 0}, {0, 1, 0}, 1.0f);
    scene::MorphTarget target;
    target.positions.assign(square1.positions.size(), {1, 0, 0});
    square1.morphTargets.push_back(target);
    scene::Scene scene;
    scene.name = "gbuffer-morph-motion-test";
    scene.materials.emplace_back();
    scene::Mesh mesh;
    mesh.lods.push_back({{square1}});
    mesh.morphWeights = {0.0f};
    scene.meshes.push_back(std::move(mesh));
    scene.instances.push_back({});
    scene::prepareScene(scene);
    REQUIRE(scene.instances[0].previousMorphWeights == std::vector<float>{0.0f});
    scene.instances[0].morphWeights = {1.0f};
    const GBufferImage img = render(gpu, scene, {testCamera()});

    const float expected = -float(kSize) / (2.0f * kDistance);  // -8 pixels
    uint32_t covered = 0;
    for (size_t i = 0; i < img.depth.size(); ++i) {
        if (img.normal[i].w == 0.0f) continue;
        ++covered;
        INFO("pixel " << i % kSize << ", " << i / kSize);
        REQUIRE(std::abs(img.motion[i].x - expected) < 0.02f);
        REQUIRE(std::abs(img.motion[i].y) < 0.02f);
    }
    CHECK(covered == 16 * 16);  // drawn where weight 1 puts it: x in [0, 2]
}

TEST_CASE("a camera moving sideways makes static geometry move the other way on screen") {
    test::GpuTest gpu;
    constexpr float kDistance = 5.0f;
    const scene::Scene scene = singleObjectScene(square({0, 0, -kDistance}, {1, 0, 0}, {0, 1, 0}, 50.0f), {});
    scene::Camera camera = testCamera();
    const scene::Camera first = camera;
    camera.advance({{0.5f, 0, 0}, {0.5f, 0, -1}, {0, 1, 0}}, 1);
    const GBufferImage img = render(gpu, scene, {first, camera});

    // The camera moved +0.5: the wall was 0.5 units further right last frame.
    const float expected = 0.5f * float(kSize) / (2.0f * kDistance);  // 3.2 pixels
    for (size_t i = 0; i < img.depth.size(); ++i) {
        INFO("pixel " << i % kSize << ", " << i / kSize);
        REQUIRE(std::abs(img.motion[i].x - expected) < 0.01f);
        REQUIRE(std::abs(img.motion[i].y) < 0.01f);
    }
}

TEST_CASE("the plaza renders finite, mostly covered, over animated frames") {
    test::GpuTest gpu;
    scene::Scene scene = scene::makePlaza();
    std::vector<scene::Camera> cameras;
    scene::Camera camera;
    camera.resolution = {kSize, kSize};
    camera.lens = scene.lens;
    camera.reset(scene.cameraPath.evaluate(0.0f), 0);
    cameras.push_back(camera);

    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    Readback readback(ctx, kSize, kSize);
    constexpr uint32_t kFrames = 3;
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        if (frame > 0) {
            const float t = float(frame) / 30.0f;
            scene::advanceScene(scene, t);
            camera.advance(scene.cameraPath.evaluate(t), frame);
        }
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
        readback.add(graph, gbuf, resources);
        executor.run(graph.compile(executor.compileOptions()), resources);
    }
    executor.waitIdle();
    const GBufferImage img = readback.decode();

    CHECK(renderer.stats().frame == kFrames);
    // Every instance in view is drawn (at least one draw each); the rest is culled.
    CHECK(renderer.stats().draws >= scene.instances.size() - renderer.stats().instancesCulled);
    CHECK(renderer.stats().instancesCulled > 0u);  // the plaza's camera never sees all of it
    CHECK(renderer.stats().instancesCulled < scene.instances.size());
    uint32_t covered = 0;
    for (size_t i = 0; i < img.depth.size(); ++i) {
        INFO("pixel " << i % kSize << ", " << i / kSize);
        REQUIRE(std::isfinite(img.depth[i]));
        REQUIRE(img.depth[i] >= 0.0f);
        REQUIRE(img.depth[i] <= 1.0f);
        REQUIRE(finite(img.normal[i]));
        REQUIRE(finite(img.lit[i]));
        REQUIRE(std::isfinite(img.motion[i].x));
        REQUIRE(std::isfinite(img.motion[i].y));
        // A walking camera over 1/30 s moves the image by a few pixels at most.
        REQUIRE(glm::length(img.motion[i]) < float(kSize) / 4.0f);
        REQUIRE(img.lit[i].r >= 0.0f);
        if (img.depth[i] > 0.0f) {
            ++covered;
            REQUIRE(std::abs(glm::length(glm::vec3(img.normal[i])) - 1.0f) < 1e-2f);
        }
    }
    CHECK(covered > img.depth.size() / 2);
}

TEST_CASE("a camera without pixels is an error naming the G-buffer") {
    test::GpuTest gpu;
    const scene::Scene scene = singleObjectScene(square({0, 0, -1}, {1, 0, 0}, {0, 1, 0}, 1.0f), {});
    passes::GBufferRenderer renderer(gpu.ctx(), scene);
    rg::Graph graph;
    scene::Camera camera = testCamera();
    camera.resolution = {0, kSize};
    CHECK_THROWS_WITH_AS(passes::addGBufferPass(graph, renderer, {camera}), doctest::Contains("G-buffer"),
                         gpu::GpuError);
}

namespace {

// A 64x64 texture of 2x2 checker cells, 32 texels each, `cells` in the
// order top-left, top-right, bottom-left, bottom-right of the image.
scene::Texture checkerTexture(const std::array<glm::u8vec4, 4>& cells) {
    scene::Texture texture;
    texture.name = "checker";
    texture.width = texture.height = 64;
    for (uint32_t y = 0; y < 64; ++y) {
        for (uint32_t x = 0; x < 64; ++x) {
            const glm::u8vec4 c = cells[(y / 32) * 2 + x / 32];
            texture.rgba8.insert(texture.rgba8.end(), {c.r, c.g, c.b, c.a});
        }
    }
    return texture;
}

// A plane at distance 5 that fills the test image exactly (90-degree lens),
// so texture coordinates (x + 0.5, y + 0.5) / 64 land on texel centres of a
// 64x64 texture at pixel (x, y): set 0 as is, set 1 mirrored in u. Sampled
// at its four corners (the vertex path) the checker would give the average
// of its cells everywhere.
scene::Scene checkerPlaneScene(const scene::Texture& texture, const scene::Material& material,
                               const std::vector<glm::vec4>& colors = {}) {
    scene::Geometry plane = square({0, 0, -5}, {1, 0, 0}, {0, 1, 0}, 5.0f);
    for (const glm::vec3& p : plane.positions) {
        const glm::vec2 uv(p.x / 10.0f + 0.5f, 0.5f - p.y / 10.0f);
        plane.texcoords0.push_back(uv);
        plane.texcoords1.push_back({1.0f - uv.x, uv.y});
    }
    plane.colors = colors;
    scene::Scene s;
    s.name = "gbuffer-checker-test";
    s.textures.push_back(texture);
    s.materials.push_back(material);
    scene::Mesh mesh;
    mesh.lods.push_back({{plane}});
    s.meshes.push_back(std::move(mesh));
    s.instances.push_back({});
    scene::prepareScene(s);
    return s;
}

// The checker cell the texture reference reads at pixel (x, y) of
// checkerPlaneScene, or -1 within `margin` (in texture coordinates) of a
// cell's edge, where filtering mixes cells.
int checkerCellAt(const scene::TextureRef& ref, uint32_t x, uint32_t y, float margin) {
    glm::vec2 uv((float(x) + 0.5f) / float(kSize), (float(y) + 0.5f) / float(kSize));
    if (ref.texCoord == 1) uv.x = 1.0f - uv.x;
    const glm::vec2 t = shader::applyUvTransform(ref.uvTransform(), uv) * 2.0f;
    const glm::vec2 inCell = t - glm::floor(t);
    if (std::min(std::min(inCell.x, 1.0f - inCell.x), std::min(inCell.y, 1.0f - inCell.y)) < 2.0f * margin) return -1;
    const glm::ivec2 cell = glm::ivec2(glm::floor(t)) & 1;
    return cell.y * 2 + cell.x;
}

float unorm8(uint8_t v) {
    return float(v) / 255.0f;
}

} // namespace

TEST_CASE("the base colour texture is sampled per pixel: each checker cell gives its texel times factor and COLOR_0") {
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(200, 40, 90, 255), glm::u8vec4(30, 180, 250, 255),
                                              glm::u8vec4(120, 120, 20, 255), glm::u8vec4(250, 250, 250, 255)};
    scene::Material material;
    material.baseColorTexture.texture = 0;
    material.baseColorFactor = {0.8f, 1.0f, 0.6f, 1.0f};
    const glm::vec4 color(1.0f, 0.5f, 1.0f, 1.0f);
    test::GpuTest gpu;
    const scene::Scene scene = checkerPlaneScene(checkerTexture(cells), material, std::vector<glm::vec4>(4, color));
    passes::GBufferStats stats;
    const GBufferImage img = render(gpu, scene, {testCamera()}, &stats);
    CHECK(stats.textureImages == 1);
    CHECK(stats.normalMaps == 0);
    CHECK(stats.texturedDraws == 1);

    std::array<int, 4> seen{};
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const int cell = checkerCellAt(material.baseColorTexture, x, y, 2.0f / 64.0f);
            if (cell < 0) continue;
            ++seen[size_t(cell)];
            INFO("pixel " << x << ", " << y << ", cell " << cell);
            const glm::u8vec4 albedo = img.albedo[img.at(x, y)];
            for (int c = 0; c < 3; ++c) {
                // sRGB texel decoded, times factor and vertex colour, stored sRGB.
                const float texel = shader::srgbToLinear(unorm8(cells[size_t(cell)][c]));
                const float linear = texel * material.baseColorFactor[c] * color[c];
                REQUIRE(std::abs(int(albedo[c]) - srgbByte(linear)) <= 1);
            }
        }
    }
    for (const int n : seen) CHECK(n > 100);
}

TEST_CASE("the metallic-roughness texture is sampled per pixel: G times the roughness factor, B times the metallic") {
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(0, 30, 250, 255), glm::u8vec4(0, 240, 10, 255),
                                              glm::u8vec4(0, 128, 128, 255), glm::u8vec4(0, 200, 60, 255)};
    scene::Material material;
    material.metallicRoughnessTexture.texture = 0;
    material.metallicRoughnessTexture.texCoord = 1;  // mirrored in u
    material.roughnessFactor = 0.5f;
    material.metallicFactor = 0.9f;
    test::GpuTest gpu;
    const scene::Scene scene = checkerPlaneScene(checkerTexture(cells), material);
    passes::GBufferStats stats;
    const GBufferImage img = render(gpu, scene, {testCamera()}, &stats);
    CHECK(stats.textureImages == 1);

    std::array<int, 4> seen{};
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const int cell = checkerCellAt(material.metallicRoughnessTexture, x, y, 2.0f / 64.0f);
            if (cell < 0) continue;
            ++seen[size_t(cell)];
            INFO("pixel " << x << ", " << y << ", cell " << cell);
            const glm::u8vec4 rm = img.roughnessMetal[img.at(x, y)];
            const float roughness = unorm8(cells[size_t(cell)].g) * material.roughnessFactor;
            const float metallic = unorm8(cells[size_t(cell)].b) * material.metallicFactor;
            REQUIRE(std::abs(int(rm.r) - int(shader::encodeUnorm8(roughness))) <= 1);
            REQUIRE(std::abs(int(rm.g) - int(shader::encodeUnorm8(metallic))) <= 1);
        }
    }
    for (const int n : seen) CHECK(n > 100);
}

TEST_CASE("the base colour texture is read through its reference's coordinate set and KHR_texture_transform") {
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(255, 0, 0, 255), glm::u8vec4(0, 255, 0, 255),
                                              glm::u8vec4(0, 0, 255, 255), glm::u8vec4(255, 255, 0, 255)};
    struct Case {
        const char* what;
        uint32_t texCoord;
        glm::vec2 offset;
        float rotation;
        glm::vec2 scale;
    };
    for (const Case& c : {Case{"set 0, identity", 0, {0.0f, 0.0f}, 0.0f, {1.0f, 1.0f}},
                          Case{"set 1, identity", 1, {0.0f, 0.0f}, 0.0f, {1.0f, 1.0f}},
                          Case{"set 0, offset a quarter", 0, {0.25f, 0.0f}, 0.0f, {1.0f, 1.0f}},
                          Case{"set 1, rotated a quarter turn, scaled twice", 1, {0.0f, 0.0f},
                               glm::half_pi<float>(), {2.0f, 2.0f}}}) {
        INFO(c.what);
        scene::Material material;
        material.baseColorTexture.texture = 0;
        material.baseColorTexture.texCoord = c.texCoord;
        material.baseColorTexture.offset = c.offset;
        material.baseColorTexture.rotation = c.rotation;
        material.baseColorTexture.scale = c.scale;
        test::GpuTest gpu;
        const scene::Scene scene = checkerPlaneScene(checkerTexture(cells), material);
        const GBufferImage img = render(gpu, scene, {testCamera()});
        std::array<int, 4> seen{};
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                // Scaled twice, a pixel spans two texels: a wider margin.
                const int cell = checkerCellAt(material.baseColorTexture, x, y, 3.0f / 64.0f * c.scale.x);
                if (cell < 0) continue;
                ++seen[size_t(cell)];
                INFO("pixel " << x << ", " << y << ", cell " << cell);
                const glm::u8vec4 albedo = img.albedo[img.at(x, y)];
                for (int k = 0; k < 3; ++k) REQUIRE(std::abs(int(albedo[k]) - int(cells[size_t(cell)][k])) <= 1);
            }
        }
        for (const int n : seen) CHECK(n > 20);
    }
}

TEST_CASE("only the textures drawn materials sample are uploaded, once per texture and colour space") {
    // Texture 0 serves as base colour (sRGB) and metallic-roughness (linear)
    // of the drawn material: two images. Texture 1 belongs to a material no
    // geometry uses, texture 2 to none: neither is uploaded.
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(255), glm::u8vec4(128), glm::u8vec4(64), glm::u8vec4(32)};
    scene::Material drawn;
    drawn.baseColorTexture.texture = 0;
    drawn.metallicRoughnessTexture.texture = 0;
    scene::Scene s = checkerPlaneScene(checkerTexture(cells), drawn);
    s.textures.push_back(checkerTexture(cells));
    s.textures.push_back(checkerTexture(cells));
    scene::Material unused;
    unused.baseColorTexture.texture = 1;
    unused.normalTexture.texture = 1;
    s.materials.push_back(unused);
    test::GpuTest gpu;
    passes::GBufferStats stats;
    render(gpu, s, {testCamera()}, &stats);
    CHECK(stats.textureImages == 2);
    CHECK(stats.normalMaps == 0);
    // 64x64 RGBA8 and its mips down to 1x1, twice.
    uint64_t bytes = 0;
    for (uint32_t side = 64; side >= 1; side /= 2) bytes += uint64_t(side) * side * 4;
    CHECK(stats.textureBytes == 2 * bytes);
    CHECK(stats.texturedDraws == 1);
}

TEST_CASE("an emissive plane's lit colour is factor x strength x its sRGB texel x the emissive scale, unlit") {
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(255, 40, 90, 255), glm::u8vec4(30, 180, 250, 255),
                                              glm::u8vec4(120, 120, 20, 255), glm::u8vec4(250, 250, 250, 255)};
    scene::Material material;
    material.baseColorFactor = {0.0f, 0.0f, 0.0f, 1.0f};  // black: no diffuse term
    material.emissiveFactor = {1.0f, 0.5f, 0.25f};
    material.emissiveStrength = 8.0f;
    material.emissiveTexture.texture = 0;
    material.emissiveTexture.texCoord = 1;  // mirrored in u
    scene::Scene scene = checkerPlaneScene(checkerTexture(cells), material);
    // No sun and no sky: the lit colour is the emission alone.
    scene.sun.illuminance = 0.0f;
    scene.environment.intensity = 0.0f;
    passes::GBufferSettings settings;
    settings.lighting.emissiveScale = 0.5f;
    test::GpuTest gpu;
    passes::GBufferStats stats;
    const GBufferImage img = render(gpu, scene, {testCamera()}, &stats, settings);
    CHECK(stats.textureImages == 1);
    CHECK(stats.texturedDraws == 1);

    std::array<int, 4> seen{};
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const int cell = checkerCellAt(material.emissiveTexture, x, y, 2.0f / 64.0f);
            if (cell < 0) continue;
            ++seen[size_t(cell)];
            INFO("pixel " << x << ", " << y << ", cell " << cell);
            const glm::vec4 lit = img.lit[img.at(x, y)];
            for (int c = 0; c < 3; ++c) {
                const float scale =
                    material.emissiveFactor[c] * material.emissiveStrength * settings.lighting.emissiveScale;
                const float expected = scale * shader::srgbToLinear(unorm8(cells[size_t(cell)][c]));
                // Half-float storage (2^-11 relative) and the sampler's sRGB
                // decode: lavapipe's polynomial is off the formula by up to
                // ~7e-4 of full scale (a dark texel's 2%, under half an
                // 8-bit step).
                REQUIRE(std::abs(lit[c] - expected) <= 2e-3f * expected + 1.5e-3f * scale);
            }
        }
    }
    for (const int n : seen) CHECK(n > 100);
}

TEST_CASE("emission adds to the lit colour of a sunlit plane; a material that does not emit uploads no emissive texture") {
    // The same plane twice, emitting (factor only, no texture) and not: the
    // difference is the emission wherever the plane is.
    scene::Material plain;
    plain.baseColorFactor = {0.5f, 0.5f, 0.5f, 1.0f};
    plain.emissiveTexture.texture = 0;  // emissiveFactor stays zero: never uploaded
    scene::Material glowing = plain;
    glowing.emissiveTexture = {};
    glowing.emissiveFactor = {0.2f, 0.4f, 0.6f};
    glowing.emissiveStrength = 2.5f;
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(255), glm::u8vec4(128), glm::u8vec4(64), glm::u8vec4(32)};
    test::GpuTest gpu;
    passes::GBufferStats stats;
    const GBufferImage base = render(gpu, checkerPlaneScene(checkerTexture(cells), plain), {testCamera()}, &stats);
    CHECK(stats.textureImages == 0);
    CHECK(stats.texturedDraws == 0);
    const GBufferImage lit = render(gpu, checkerPlaneScene(checkerTexture(cells), glowing), {testCamera()});
    const glm::vec3 emission = glowing.emissiveFactor * glowing.emissiveStrength;  // default emissiveScale 1
    uint32_t covered = 0;
    for (size_t i = 0; i < base.lit.size(); ++i) {
        if (base.normal[i].w < 0.5f) continue;
        ++covered;
        for (int c = 0; c < 3; ++c) {
            const float difference = lit.lit[i][c] - base.lit[i][c];
            // Both values are halves: their rounding at the larger one.
            REQUIRE(std::abs(difference - emission[c]) <= 2e-3f * (lit.lit[i][c] + emission[c]) + 1e-4f);
        }
    }
    CHECK(covered > kSize * kSize / 2);
}

// ---------------------------------------------------------------------------
// Alpha-tested materials (glTF alphaMode MASK)
// ---------------------------------------------------------------------------

TEST_CASE("an alpha-tested plane leaves no surface where its base colour alpha is below the cutoff; an opaque one "
          "covers everything") {
    // Cells 1 and 3 transparent (alpha 0), 0 and 2 opaque.
    const std::array<glm::u8vec4, 4> cells = {glm::u8vec4(200, 40, 90, 255), glm::u8vec4(30, 180, 250, 0),
                                              glm::u8vec4(120, 120, 20, 255), glm::u8vec4(250, 250, 250, 0)};
    test::GpuTest gpu;
    for (const scene::AlphaMode mode : {scene::AlphaMode::Mask, scene::AlphaMode::Opaque}) {
        CAPTURE(int(mode));
        scene::Material material;
        material.baseColorTexture.texture = 0;
        material.alphaMode = mode;
        material.alphaCutoff = 0.5f;
        const scene::Scene scene = checkerPlaneScene(checkerTexture(cells), material);
        passes::GBufferStats stats;
        const GBufferImage img = render(gpu, scene, {testCamera()}, &stats);
        CHECK(stats.maskedDraws == (mode == scene::AlphaMode::Mask ? 1u : 0u));
        std::array<int, 4> covered{}, empty{};
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const int cell = checkerCellAt(material.baseColorTexture, x, y, 2.0f / 64.0f);
                if (cell < 0) continue;
                const bool surface = img.normal[img.at(x, y)].w > 0.5f && img.depth[img.at(x, y)] > 0.0f;
                (surface ? covered : empty)[size_t(cell)]++;
            }
        }
        CAPTURE(covered[0]);
        CAPTURE(covered[1]);
        for (size_t c = 0; c < 4; ++c) {
            const bool transparent = mode == scene::AlphaMode::Mask && cells[c].a == 0;
            CHECK((transparent ? covered : empty)[c] == 0);
            CHECK((transparent ? empty : covered)[c] > 100);
        }
    }
}

TEST_CASE("the alpha test reads the factor and COLOR_0 alpha too: a plane at 0.4 against a 0.5 cutoff vanishes, at "
          "0.6 it stays") {
    test::GpuTest gpu;
    for (const float alpha : {0.4f, 0.6f}) {
        CAPTURE(alpha);
        scene::Material material;
        material.alphaMode = scene::AlphaMode::Mask;
        material.alphaCutoff = 0.5f;
        material.baseColorFactor = {0.5f, 0.5f, 0.5f, alpha};
        scene::Geometry plane = square({0, 0, -5}, {1, 0, 0}, {0, 1, 0}, 5.0f);
        const GBufferImage img = render(gpu, singleObjectScene(plane, material), {testCamera()});
        uint32_t covered = 0;
        for (const glm::vec4& n : img.normal) covered += n.w > 0.5f ? 1u : 0u;
        CHECK(covered == (alpha > 0.5f ? kSize * kSize : 0u));
    }
}
