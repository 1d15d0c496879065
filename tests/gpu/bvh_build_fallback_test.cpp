// SSLR is the fallback while the BVH builds (the Far Cry 6 talk): 200
// objects enter the BVH's radius at once, their first builds spread over
// frames by the budget (scene::BvhSettings::maxFirstBuildsPerFrame), and
// meanwhile SSLR reflects them: holes where the objects are reflected stay
// few, and fewer than with the BVH traced as it is. The whole reflection
// frame (passes::ReflectionRenderer) in hybrid mode, on a real device with
// validation on.
//
// The scene: a mirror floor and 200 small boxes standing on it in a 20 x 10
// grid, each its own mesh (so its own BLAS), in front of a camera looking
// down at them. A hole is a pixel whose reflection meets one of the boxes
// when every BLAS is built (integrate's hit distance is finite), and meets
// nothing in the frame with the BVH still building (its ray passed where an
// unbuilt box stands).
#include "support/gpu_test.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/animation.h"
#include "glint/scene/procedural_meshes.h"
#include "glint/scene/scene.h"

#include "glint/ray_generation_shared.h"

#include <glm/gtc/matrix_transform.hpp>

#include <doctest/doctest.h>

#include <cstring>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kWidth = 96;
constexpr uint32_t kHeight = 64;
constexpr uint32_t kBoxes = 200;
constexpr uint32_t kBudget = 16;  // first builds per frame: 13 frames for 200

scene::Scene boxesOnAMirror() {
    scene::Scene s;
    s.name = "boxes on a mirror";
    scene::Material mirror;
    mirror.baseColorFactor = {0.9f, 0.9f, 0.9f, 1.0f};
    mirror.metallicFactor = 1.0f;
    mirror.roughnessFactor = 0.0f;
    s.materials.push_back(mirror);
    scene::Mesh floor;
    floor.name = "floor";
    floor.lods.push_back({{scene::makeGrid({40.0f, 40.0f}, {1, 1}, 0)}});
    s.meshes.push_back(floor);
    scene::Instance floorInstance;
    floorInstance.name = "floor";
    floorInstance.mesh = 0;
    s.instances.push_back(floorInstance);
    for (uint32_t i = 0; i < kBoxes; ++i) {
        scene::Material m;
        m.baseColorFactor = {0.2f + 0.6f * float(i % 5) / 4.0f, 0.3f + 0.5f * float(i % 7) / 6.0f, 0.8f, 1.0f};
        m.roughnessFactor = 0.8f;
        s.materials.push_back(m);
        scene::Mesh box;
        box.name = "box " + std::to_string(i);
        box.lods.push_back({{scene::makeBox(glm::vec3(0.3f, 0.5f, 0.3f), uint32_t(s.materials.size() - 1))}});
        s.meshes.push_back(box);
        scene::Instance inst;
        inst.name = box.name;
        inst.mesh = uint32_t(s.meshes.size() - 1);
        const glm::vec3 at(-4.75f + 0.5f * float(i % 20), 0.25f, -4.0f - 1.0f * float(i / 20));
        inst.transform = inst.previousTransform = glm::translate(glm::mat4(1.0f), at);
        s.instances.push_back(inst);
    }
    scene::prepareScene(s);
    return s;
}

struct FrameResult {
    std::vector<float> hitDistance;  // integrate's, per pixel
    bool bvhComplete = false;
    uint32_t built = 0;  // first builds this frame
};

// Renders frames of the scene in hybrid mode and reads back integrate's
// hit distance every frame.
class Sequence {
public:
    Sequence(gpu::Context& ctx, const scene::Scene& s, uint32_t firstBuildBudget)
        : ctx_(ctx), scene_(s), executor_(ctx), renderer_(ctx, scene_, options(firstBuildBudget)) {
        camera_.resolution = {kWidth, kHeight};
        camera_.lens = {glm::radians(60.0f), 0.1f, scene::kInfiniteFar};
        camera_.jitter = false;
    }

    FrameResult frame(uint64_t index, bool sslrWhileBvhBuilds) {
        const scene::CameraPose pose{{0.0f, 2.0f, 1.0f}, {0.0f, 0.0f, -7.0f}, {0, 1, 0}};
        if (index == 0) {
            camera_.reset(pose, index);
        } else {
            camera_.advance(pose, index);
        }
        rg::Graph graph(executor_.queueCaps());
        passes::ReflectionFrameSettings settings;
        settings.mode = passes::ReflectionMode::Hybrid;
        settings.resetHistory = index == 0;
        settings.sslrWhileBvhBuilds = sslrWhileBvhBuilds;
        const passes::ReflectionFrame f = renderer_.addFrame(graph, camera_, settings);
        rg::FrameResources resources;
        renderer_.bind(resources, f);
        readback_.copy(graph, resources, f.integrate.hitDistance);
        executor_.run(graph.compile(executor_.compileOptions()), resources);
        executor_.waitIdle();
        FrameResult r;
        r.hitDistance.resize(size_t(kWidth) * kHeight);
        std::memcpy(r.hitDistance.data(), readback_.bytes().data(), r.hitDistance.size() * sizeof(float));
        r.bvhComplete = f.bvhComplete;
        r.built = renderer_.bvhPlanStats().built;
        return r;
    }

private:
    static passes::ReflectionRendererOptions options(uint32_t firstBuildBudget) {
        passes::ReflectionRendererOptions o;
        o.bvh.maxFirstBuildsPerFrame = firstBuildBudget;
        return o;
    }

    gpu::Context& ctx_;
    const scene::Scene& scene_;
    rg::Executor executor_;
    passes::ReflectionRenderer renderer_;
    scene::Camera camera_;
    rg::HostReadback readback_{ctx_, VkDeviceSize(kWidth) * kHeight * 4, "bvh_fallback_test.readback"};
};

bool reflectsSurface(float hitDistance) { return hitDistance < 0.5f * shader::kMissHitDistance; }

} // namespace

TEST_CASE("200 objects entering range at once build over frames within the budget, and SSLR fills their "
          "reflections meanwhile: holes only where SSLR cannot see either, fewer than without the fallback") {
    test::GpuTest gpu;
    const scene::Scene s = boxesOnAMirror();
    Sequence complete(gpu.ctx(), s, 1000);
    Sequence withFallback(gpu.ctx(), s, kBudget);
    Sequence withoutFallback(gpu.ctx(), s, kBudget);
    uint32_t builtTotal = 0, buildingFrames = 0, holesWith = 0, holesWithout = 0;
    for (uint64_t i = 0; i < 16; ++i) {
        CAPTURE(i);
        const FrameResult reference = complete.frame(i, true);
        const FrameResult building = withFallback.frame(i, true);
        const FrameResult tracedAsItIs = withoutFallback.frame(i, false);
        CHECK(reference.bvhComplete);
        // The budget: 16 first builds a frame (the floor's BLAS among them
        // on frame 0) until all 201 are built.
        CHECK(building.built <= kBudget);
        builtTotal += building.built;
        CHECK(building.bvhComplete == (builtTotal == kBoxes + 1));
        if (!building.bvhComplete) ++buildingFrames;

        uint32_t reflected = 0, holes = 0, holesAsItIs = 0;
        for (size_t p = 0; p < reference.hitDistance.size(); ++p) {
            if (!reflectsSurface(reference.hitDistance[p])) continue;
            ++reflected;
            if (!reflectsSurface(building.hitDistance[p])) ++holes;
            if (!reflectsSurface(tracedAsItIs.hitDistance[p])) ++holesAsItIs;
        }
        MESSAGE("frame " << i << ": BVH " << (building.bvhComplete ? "complete" : "building") << ", " << reflected
                         << " pixels reflect a box; holes " << holes << " with SSLR as the fallback, " << holesAsItIs
                         << " without");
        CHECK(reflected > 300u);
        // What remains are reflections SSLR cannot see either: boxes off
        // the screen's sides, not built yet (the nearest and largest go
        // first; measured: 7% and 5% of the reflected pixels in the first
        // two frames, at most 2% from the third on, none once complete).
        CHECK(holes <= reflected / (i < 2 ? 10u : 50u));
        CHECK(holes <= holesAsItIs + reflected / 100u);
        if (!building.bvhComplete) {
            holesWith += holes;
            holesWithout += holesAsItIs;
        } else {
            CHECK(holes <= reflected / 200u);
        }
    }
    CHECK(buildingFrames == 12u);
    CHECK(builtTotal == kBoxes + 1);
    // Without the fallback more rays pass through the unbuilt boxes and
    // meet the sky (measured: 164 holes over the twelve frames, 97 with it).
    CAPTURE(holesWith);
    CAPTURE(holesWithout);
    CHECK(4 * holesWith <= 3 * holesWithout);
}
