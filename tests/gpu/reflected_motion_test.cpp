// Reflected objects carry their own motion: the lamp of the built-in
// "mirror-motion" scene slides along +x over a glossy floor while the camera
// stands still. Where the floor reflects the lamp, integrate's hit motion
// must be the lamp's own displacement since last frame (a ray-traced hit
// from its instance's transforms, an SSLR hit from the G-buffer's motion at
// the hit), zero where it reflects still things; and temporal accumulation
// must move the reflection with the lamp, not hold it still. The same when
// the lamp slides inside a standing instance, by a joint or a morph target:
// a ray-traced hit's motion then comes from how its BLAS's triangles moved
// since the last build.
#include "support/gpu_test.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/error.h"

#include <glm/gtc/packing.hpp>

#include <cmath>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kWidth = 96, kHeight = 64;
constexpr float kFrameSeconds = 1.0f / 30.0f;

struct MotionFrame {
    std::vector<glm::vec3> hitMotion;       // integrate's, per pixel
    std::vector<glm::vec2> reflectionMotion;  // temporal's, per pixel
};

std::vector<glm::vec4> halves(const rg::HostReadback& readback, size_t channels) {
    const auto h = readback.as<uint16_t>();
    std::vector<glm::vec4> out(size_t(kWidth) * kHeight, glm::vec4(0.0f));
    for (size_t p = 0; p < out.size(); ++p) {
        for (size_t c = 0; c < channels; ++c) out[p][int(c)] = glm::unpackHalf1x16(h[p * channels + c]);
    }
    return out;
}

// Three frames of the mirror-motion scene from just before the lamp starts
// to move (it moves between the second and the third); the third frame's
// motions.
MotionFrame renderMoving(passes::ReflectionMode mode, bool reflectedMotion,
                         scene::MirrorMotionLamp lamp = scene::MirrorMotionLamp::Rigid) {
    test::GpuTest gpu;
    gpu::Context& ctx = gpu.ctx();
    scene::Scene s = scene::makeMirrorMotion(true, lamp);
    rg::Executor executor(ctx);
    passes::ReflectionRenderer renderer(ctx, s, {});
    const rg::HostReadback hitMotion(ctx, VkDeviceSize(kWidth) * kHeight * 8, "test.hit_motion");
    const rg::HostReadback reflectionMotion(ctx, VkDeviceSize(kWidth) * kHeight * 4, "test.reflection_motion");
    scene::Camera camera;
    camera.resolution = {kWidth, kHeight};
    camera.lens = s.lens;
    camera.jitter = false;
    const scene::CameraPose pose = s.cameraPath.evaluate(0.0f);
    constexpr uint32_t kFrames = 3;
    for (uint32_t i = 0; i < kFrames; ++i) {
        if (i == 0) {
            camera.reset(pose, i);
        } else {
            camera.advance(pose, i);
        }
        scene::advanceScene(s, scene::kMirrorMotion.objectStartSeconds + float(int(i) - 1) * kFrameSeconds, &camera);
        rg::Graph graph(executor.queueCaps());
        passes::ReflectionFrameSettings settings;
        settings.mode = mode;
        settings.reflectedMotion = reflectedMotion;
        settings.temporalDebugOutputs = true;  // the reflection motion is read back
        settings.resetHistory = i == 0;
        const passes::ReflectionFrame f = renderer.addFrame(graph, camera, settings);
        rg::FrameResources resources;
        renderer.bind(resources, f);
        if (i + 1 == kFrames) {
            hitMotion.copy(graph, resources, f.integrate.hitMotion);
            reflectionMotion.copy(graph, resources, f.temporal.reflectionMotion);
        }
        executor.run(graph.compile(executor.compileOptions()), resources);
    }
    executor.waitIdle();
    MotionFrame out;
    for (const glm::vec4& v : halves(hitMotion, 4)) out.hitMotion.emplace_back(v);
    for (const glm::vec4& v : halves(reflectionMotion, 2)) out.reflectionMotion.emplace_back(v);
    return out;
}

// The lamp moved +x by speed x frame time: last frame's point minus this one's.
const glm::vec3 kLampMotion(-scene::kMirrorMotion.objectSpeed * kFrameSeconds, 0.0f, 0.0f);

struct Census {
    uint32_t lamp = 0;    // hit motion within 1 cm of the lamp's
    uint32_t still = 0;   // zero within 1 cm
    uint32_t other = 0;   // neither
    glm::vec2 lampReflectionMotion{0.0f};  // temporal's mean over the lamp's pixels
};

Census census(const MotionFrame& f) {
    Census c;
    for (size_t p = 0; p < f.hitMotion.size(); ++p) {
        const glm::vec3 m = f.hitMotion[p];
        if (glm::length(m - kLampMotion) < 0.01f) {
            ++c.lamp;
            c.lampReflectionMotion += f.reflectionMotion[p];
        } else if (glm::length(m) < 0.01f) {
            ++c.still;
        } else {
            ++c.other;
        }
    }
    if (c.lamp > 0) c.lampReflectionMotion /= float(c.lamp);
    MESSAGE("lamp ", c.lamp, ", still ", c.still, ", other ", c.other, ", reflection motion of the lamp's pixels (",
            c.lampReflectionMotion.x, ", ", c.lampReflectionMotion.y, ") px");
    return c;
}

} // namespace

TEST_CASE("a moving object's reflection carries its motion, moved rigidly, by a joint or by a morph target: "
          "ray-traced hits from the instance and how the BLAS's triangles moved since its last build, SSLR hits "
          "from the G-buffer") {
    for (const scene::MirrorMotionLamp lamp :
         {scene::MirrorMotionLamp::Rigid, scene::MirrorMotionLamp::Skinned, scene::MirrorMotionLamp::Morphed}) {
        const char* how = lamp == scene::MirrorMotionLamp::Rigid     ? "rigid"
                          : lamp == scene::MirrorMotionLamp::Skinned ? "skinned"
                                                                     : "morphed";
        CAPTURE(how);
        for (const passes::ReflectionMode mode : {passes::ReflectionMode::Rt, passes::ReflectionMode::Ssr}) {
            CAPTURE(passes::modeName(mode));
            const Census c = census(renderMoving(mode, true, lamp));
            // The lamp's reflection covers a patch of the floor (about 5x5
            // pixels at this size); every other reflecting pixel holds still.
            CHECK(c.lamp >= 12);
            CHECK(c.still > 1000);
            CHECK(c.other <= c.lamp / 4);
            // The lamp moves about a pixel a frame to the right: its
            // reflection came from about a pixel to the left.
            CHECK(c.lampReflectionMotion.x < -0.5f);
            CHECK(c.lampReflectionMotion.x > -2.0f);
            CHECK(std::abs(c.lampReflectionMotion.y) < 0.5f);
        }
    }
}

TEST_CASE("without reflected motion the lamp's reflection is reprojected as if it stood still") {
    const Census c = census(renderMoving(passes::ReflectionMode::Rt, false));
    CHECK(c.lamp >= 12);
    CHECK(std::abs(c.lampReflectionMotion.x) < 0.2f);
}

TEST_CASE("mirror-motion's lamp option names what it refuses") {
    CHECK(scene::parseMirrorMotionLamp("mirror-motion") == scene::MirrorMotionLamp::Rigid);
    CHECK(scene::parseMirrorMotionLamp("mirror-motion:lamp=skinned") == scene::MirrorMotionLamp::Skinned);
    CHECK(scene::parseMirrorMotionLamp("mirror-motion:lamp=morphed") == scene::MirrorMotionLamp::Morphed);
    CHECK_THROWS_WITH_AS(scene::parseMirrorMotionLamp("mirror-motion:lamp=wobbly"),
                         doctest::Contains("'wobbly' is not rigid, skinned or morphed"), scene::SceneError);
    CHECK_THROWS_WITH_AS(scene::parseMirrorMotionLamp("mirror-motion:speed=3"), doctest::Contains("lamp=rigid"),
                         scene::SceneError);
}
