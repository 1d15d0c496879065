// The BVH policy (bvh_planner.h) over synthetic scenes and the plaza.

#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/error.h"
#include "glint/scene/packed_primitives.h"
#include "glint/scene/procedural_meshes.h"

#include "scene_test_support.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <map>
#include <set>

using namespace glint::scene;

namespace {

// A scene of unit boxes: one static mesh (with a coarser reflection LOD)
// and instances added by the tests.
struct TestScene {
    Scene scene;

    TestScene() {
        scene.name = "bvh test";
        scene.materials.resize(4);
        Mesh box;
        box.name = "box";
        box.lods.push_back({{makeBox(glm::vec3(1.0f), 0)}});
        Geometry coarse = makeBox(glm::vec3(1.0f), 0);
        coarse.indices.resize(18);  // 6 triangles: a cheaper reflection LOD
        box.lods.push_back({{coarse}});
        scene.meshes.push_back(box);
    }

    uint32_t add(const glm::vec3& at, Motion motion = Motion::Static) {
        Instance inst;
        inst.mesh = 0;
        inst.motion = motion;
        inst.transform = inst.previousTransform = glm::translate(glm::mat4(1.0f), at);
        inst.name = "box " + std::to_string(scene.instances.size());
        scene.instances.push_back(inst);
        return uint32_t(scene.instances.size() - 1);
    }

    // A skinned instance needs a skinned mesh and a skin; one joint is enough
    // for the planner (it only reads deformVersion).
    uint32_t addSkinned(const glm::vec3& at) {
        if (skinnedMesh_ == kNone) {
            Mesh m;
            m.name = "skinned";
            Geometry g = makeBox(glm::vec3(1.0f), 0);
            bindToJoint(g, 0);
            m.lods.push_back({{g}});
            scene.meshes.push_back(m);
            skinnedMesh_ = int32_t(scene.meshes.size() - 1);
            scene.nodes.emplace_back();
            scene.skins.push_back({"skin", {0}, {glm::mat4(1.0f)}});
        }
        const uint32_t i = add(at, Motion::Skinned);
        scene.instances[i].mesh = uint32_t(skinnedMesh_);
        scene.instances[i].skin = 0;
        return i;
    }

    void prepare() { prepareScene(scene); }

private:
    int32_t skinnedMesh_ = kNone;
};

size_t countReason(const BvhPlan& plan, BlasBuildReason reason) {
    return size_t(
        std::count_if(plan.builds.begin(), plan.builds.end(), [&](const BlasBuild& b) { return b.reason == reason; }));
}

bool inTlas(const BvhPlan& plan, uint32_t instance) {
    return std::any_of(plan.tlas.begin(), plan.tlas.end(),
                       [&](const TlasInstance& t) { return t.sceneInstance == instance; });
}

} // namespace

TEST_CASE("a static BLAS is built once and shared by every instance of its mesh") {
    TestScene t;
    for (int i = 0; i < 10; ++i) {
        t.add({float(i) * 3.0f, 0, 0});
    }
    t.prepare();
    BvhPlanner planner;
    std::set<BlasId> referenced;
    size_t builds = 0;
    for (uint64_t frame = 0; frame < 100; ++frame) {
        const glm::vec3 camera{std::sin(float(frame) * 0.1f) * 20.0f, 2.0f, 5.0f};
        const BvhPlan plan = planner.plan(t.scene, camera, frame);
        builds += plan.builds.size();
        CHECK(plan.tlas.size() == 10);
        for (const TlasInstance& inst : plan.tlas) {
            referenced.insert(inst.blas);
        }
        if (frame > 0) {
            CHECK(plan.stats.staticReused == 1);
            CHECK(plan.builds.empty());
        }
    }
    CHECK(builds == 1);
    CHECK(referenced.size() == 1);
}

TEST_CASE("the reflection BLAS uses the mesh's lower LOD unless the mesh names another") {
    TestScene t;
    t.add({0, 0, 0});
    t.prepare();
    {
        BvhPlanner planner;
        const BvhPlan plan = planner.plan(t.scene, {0, 0, 5}, 0);
        REQUIRE(plan.blases.size() == 1);
        CHECK(plan.blases[0].lod == 1);
        CHECK(plan.blases[0].triangleCount == 6);
    }
    t.scene.meshes[0].reflectionLod = 0;
    BvhPlanner planner;
    const BvhPlan plan = planner.plan(t.scene, {0, 0, 5}, 0);
    CHECK(plan.blases[0].lod == 0);
    CHECK(plan.blases[0].triangleCount == 12);
}

TEST_CASE("deforming dynamic BLASes are rebuilt round-robin, at most 16 a frame, each within ceil(n/16) frames") {
    for (const uint32_t n : {5u, 16u, 17u, 40u, 100u}) {
        INFO("n = " << n);
        TestScene t;
        for (uint32_t i = 0; i < n; ++i) {
            t.add({float(i % 10) * 3.0f, 0, float(i / 10) * 3.0f}, Motion::Dynamic);
        }
        t.prepare();
        // Every BLAS first built on frame 0 (the first-build budget is
        // another test's), so that frame 1 on is the rebuild loop alone.
        BvhSettings settings;
        settings.maxFirstBuildsPerFrame = n;
        BvhPlanner planner(settings);
        std::map<BlasId, uint64_t> lastRebuilt;
        const uint64_t bound = (n + 15) / 16;
        for (uint64_t frame = 0; frame < 60; ++frame) {
            for (Instance& inst : t.scene.instances) {
                ++inst.deformVersion;  // everything deforms every frame
            }
            const BvhPlan plan = planner.plan(t.scene, {10, 0, 10}, frame);
            REQUIRE(plan.stats.rebuilt <= 16);
            CHECK(plan.stats.rebuilt == (frame == 0 ? 0 : std::min(n, 16u)));
            CHECK(plan.stats.deferredBudget == (frame == 0 ? 0 : n - std::min(n, 16u)));
            for (const BlasBuild& b : plan.builds) {
                lastRebuilt[b.blas] = frame;
            }
            for (const BlasDesc& d : plan.blases) {
                REQUIRE(frame - lastRebuilt.at(d.id) < bound + (frame < bound ? 1 : 0));
            }
        }
    }
}

TEST_CASE("skinned rebuilds stop at 12 a frame inside the 16, and every skinned BLAS gets its turn") {
    TestScene t;
    const uint32_t skinned = 30, dynamic = 30;
    for (uint32_t i = 0; i < skinned; ++i) {
        t.addSkinned({float(i % 10) * 3.0f, 0, float(i / 10) * 3.0f});
    }
    for (uint32_t i = 0; i < dynamic; ++i) {
        t.add({float(i % 10) * 3.0f, 3.0f, float(i / 10) * 3.0f}, Motion::Dynamic);
    }
    t.prepare();
    BvhPlanner planner;
    std::map<uint32_t, uint64_t> lastRebuilt;  // by instance
    uint64_t worstGap = 0;
    for (uint64_t frame = 0; frame < 200; ++frame) {
        for (Instance& inst : t.scene.instances) {
            ++inst.deformVersion;
        }
        const BvhPlan plan = planner.plan(t.scene, {15, 0, 5}, frame);
        REQUIRE(plan.stats.rebuilt <= 16);
        REQUIRE(plan.stats.rebuiltSkinned <= 12);
        if (frame > 0) {
            CHECK(plan.stats.rebuilt == 16);  // the budget is used, not wasted
        }
        for (const BlasBuild& b : plan.builds) {
            lastRebuilt[uint32_t(plan.find(b.blas)->instance)] = frame;
        }
        if (frame >= 10) {
            for (uint32_t i = 0; i < skinned + dynamic; ++i) {
                worstGap = std::max(worstGap, frame - lastRebuilt.at(i));
            }
        }
    }
    // 60 deforming objects, 16 rebuilds a frame: a fair loop reaches each
    // within ceil(60 / 16) = 4 frames, the skinned cap costs at most a few more.
    MESSAGE("longest wait for a rebuild: " << worstGap << " frames");
    CHECK(worstGap <= 6);
}

TEST_CASE("an object that moves without deforming never has its BLAS rebuilt") {
    TestScene t;
    const uint32_t mover = t.add({0, 0, 0}, Motion::Dynamic);
    const uint32_t skinnedStill = t.addSkinned({5, 0, 0});
    t.prepare();
    BvhPlanner planner;
    for (uint64_t frame = 0; frame < 50; ++frame) {
        Instance& inst = t.scene.instances[mover];
        inst.previousTransform = inst.transform;
        inst.transform = glm::translate(glm::mat4(1.0f), {float(frame) * 0.1f, 0, 0});
        const BvhPlan plan = planner.plan(t.scene, {0, 0, 10}, frame);
        CHECK(plan.stats.rebuilt == 0);
        CHECK(plan.stats.skippedUnchanged == (frame == 0 ? 0u : 2u));
        if (frame > 0) {
            CHECK(plan.stats.instancesMoved == 1);
        }
        const auto it = std::find_if(plan.tlas.begin(), plan.tlas.end(),
                                     [&](const TlasInstance& ti) { return ti.sceneInstance == mover; });
        REQUIRE(it != plan.tlas.end());
        CHECK(it->transform == inst.transform);  // the TLAS carries the motion
    }
    (void)skinnedStill;
}

TEST_CASE("first-person objects are rebuilt every frame they deform, ahead of the loop and inside the budget") {
    TestScene t;
    for (uint32_t i = 0; i < 30; ++i) {
        t.addSkinned({float(i % 10) * 3.0f, 0, float(i / 10) * 3.0f});
    }
    const uint32_t player = t.addSkinned({0, 0, 0});
    t.scene.instances[player].firstPerson = true;
    t.prepare();
    BvhPlanner planner;
    for (uint64_t frame = 0; frame < 40; ++frame) {
        for (Instance& inst : t.scene.instances) {
            ++inst.deformVersion;
        }
        const BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, frame);
        REQUIRE(plan.stats.rebuilt <= 16);
        REQUIRE(plan.stats.rebuiltSkinned <= 12);
        if (frame == 0) {
            continue;
        }
        CHECK(plan.stats.rebuiltFirstPerson == 1);
        REQUIRE(countReason(plan, BlasBuildReason::FirstPerson) == 1);
        const auto fp = std::find_if(plan.builds.begin(), plan.builds.end(),
                                     [](const BlasBuild& b) { return b.reason == BlasBuildReason::FirstPerson; });
        CHECK(plan.find(fp->blas)->instance == int32_t(player));
        CHECK(fp == std::find_if(plan.builds.begin(), plan.builds.end(),
                                 [](const BlasBuild& b) { return b.reason != BlasBuildReason::FirstInRange; }));
        const auto tlas = std::find_if(plan.tlas.begin(), plan.tlas.end(),
                                       [&](const TlasInstance& ti) { return ti.sceneInstance == player; });
        REQUIRE(tlas != plan.tlas.end());
        CHECK(tlas->mask == glint::shader::kInstanceMaskFirstPerson);
    }
}

TEST_CASE("the TLAS holds only instances within the radius; the long-range group reaches further") {
    TestScene t;
    // Unit boxes: the distance to the bounds is the centre distance - 0.5.
    const uint32_t at50 = t.add({50, 0, 0});
    const uint32_t at99 = t.add({0, 0, 99});
    const uint32_t at101 = t.add({-101, 0, 0});
    const uint32_t at300 = t.add({0, 0, -300});
    const uint32_t terrain300 = t.add({300, 0, 0});
    const uint32_t terrain600 = t.add({0, 0, 600});
    t.scene.instances[terrain300].longRange = true;
    t.scene.instances[terrain600].longRange = true;
    t.prepare();
    BvhPlanner planner;
    const BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    CHECK(inTlas(plan, at50));
    CHECK(inTlas(plan, at99));
    CHECK_FALSE(inTlas(plan, at101));
    CHECK_FALSE(inTlas(plan, at300));
    CHECK(inTlas(plan, terrain300));
    CHECK_FALSE(inTlas(plan, terrain600));
    CHECK(plan.stats.instancesInRange == 3);
    CHECK(plan.stats.instancesCulled == 3);
    for (const TlasInstance& ti : plan.tlas) {
        CHECK(ti.mask == (ti.sceneInstance == terrain300 ? glint::shader::kInstanceMaskLongRange
                                                         : glint::shader::kInstanceMaskWorld));
        CHECK(ti.sbtOffset == glint::shader::kSbtOffsetPackedPrimitives);
    }
    BvhPlanner widePlanner;
    CHECK(widePlanner.plan(t.scene, {0, 0, 0}, 0, 400.0f).tlas.size() == 5);
    // The long-range group reaches at least as far as the frame's radius.
    CHECK(widePlanner.plan(t.scene, {0, 0, 0}, 1, 1000.0f).tlas.size() == 6);
    BvhSettings shortLongRange;
    shortLongRange.longRangeRadius = 10.0f;
    BvhPlanner shortPlanner(shortLongRange);
    CHECK(shortPlanner.plan(t.scene, {0, 0, 0}, 0, 400.0f).tlas.size() == 5);
    CHECK_THROWS_WITH_AS(BvhPlanner().plan(t.scene, {0, 0, 0}, 0, 0.0f), doctest::Contains("radius"), SceneError);
}

TEST_CASE("an object never within the radius gets no BLAS; one that arrives is built when it does") {
    TestScene t;
    t.scene.meshes.push_back(t.scene.meshes[0]);  // a second mesh, so the far objects do not share the near one's BLAS
    t.add({0, 0, 0});
    const uint32_t approaching = t.add({0, 0, -150});
    const uint32_t never = t.add({400, 0, 0});
    t.scene.instances[approaching].mesh = 1;
    t.scene.instances[never].mesh = 1;
    t.scene.instances[approaching].motion = Motion::Dynamic;
    t.prepare();
    BvhPlanner planner;
    uint64_t arrivalBuild = 0;
    for (uint64_t frame = 0; frame < 100; ++frame) {
        const glm::vec3 camera{0, 0, -float(frame)};  // walking towards -Z
        const BvhPlan plan = planner.plan(t.scene, camera, frame);
        for (const BlasBuild& b : plan.builds) {
            const BlasDesc* d = plan.find(b.blas);
            REQUIRE(d != nullptr);
            CHECK_FALSE((d->mesh == 1 && d->instance == kNone));  // only "never" would use a static mesh-1 BLAS
            if (d->instance == int32_t(approaching)) {
                CHECK(b.reason == BlasBuildReason::FirstInRange);
                arrivalBuild = frame;
            }
        }
        CHECK(plan.stats.instancesWithoutBlas == (inTlas(plan, approaching) || arrivalBuild ? 1u : 2u));
    }
    // Bounds reach z = -149.5; within 100 m once the camera is at z <= -49.5.
    CHECK(arrivalBuild == 50);
}

TEST_CASE("200 objects entering range at once are built over frames within the first-build budget, first person "
          "first, then the largest on screen; each joins the TLAS whole once built") {
    TestScene t;
    // 199 boxes on a spiral out to 90 m, one first-person object at the far end.
    for (uint32_t i = 0; i < 199; ++i) {
        const float angle = 0.7f * float(i), distance = 3.0f + 0.45f * float(i);
        t.add({distance * std::cos(angle), 0.0f, distance * std::sin(angle)}, Motion::Dynamic);
    }
    const uint32_t player = t.add({0.0f, 0.0f, 95.0f}, Motion::Dynamic);
    t.scene.instances[player].firstPerson = true;
    t.prepare();
    BvhSettings settings;
    settings.maxFirstBuildsPerFrame = 16;
    BvhPlanner planner(settings);
    std::set<uint32_t> built;  // scene instances whose BLAS exists
    float previousFarthest = 0.0f;
    uint64_t frame = 0;
    for (; frame < 20; ++frame) {
        const BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, frame);
        CHECK(plan.stats.built <= 16u);
        CHECK(plan.stats.built == std::min<size_t>(16u, 200u - built.size()));
        float nearest = 1e30f, farthest = 0.0f;
        for (const BlasBuild& b : plan.builds) {
            REQUIRE(b.reason == BlasBuildReason::FirstInRange);
            const uint32_t instance = uint32_t(plan.find(b.blas)->instance);
            built.insert(instance);
            if (instance == player) {
                CHECK(frame == 0);
                continue;
            }
            const float d = glm::length(glm::vec3(t.scene.instances[instance].transform[3]));
            nearest = std::min(nearest, d);
            farthest = std::max(farthest, d);
        }
        // Equal boxes: the largest on screen are the nearest, so no box
        // waits for one farther away.
        if (!plan.builds.empty()) CHECK(nearest >= previousFarthest);
        previousFarthest = std::max(previousFarthest, farthest);
        // The TLAS holds exactly the built objects; the rest wait.
        CHECK(plan.tlas.size() == built.size());
        for (const TlasInstance& ti : plan.tlas) CHECK(built.count(ti.sceneInstance) == 1u);
        CHECK(plan.stats.instancesAwaitingBlas == 200u - built.size());
        CHECK(plan.stats.deferredFirstBuilds == 200u - built.size());
        CHECK(plan.complete() == (built.size() == 200u));
        if (plan.complete()) break;
    }
    CHECK(frame == 12);  // ceil(200 / 16) frames: 0..12
}

TEST_CASE("the first-build triangle budget spreads builds over frames, and one object larger than it still builds") {
    TestScene t;
    // A second mesh of 240 triangles (a 12 x 10 grid), over the budget alone.
    Mesh big;
    big.name = "big";
    const Geometry g = makeGrid({1.0f, 1.0f}, {12, 10}, 0);
    big.lods.push_back({{g}});
    t.scene.meshes.push_back(big);
    const uint32_t large = t.add({0, 0, 2}, Motion::Dynamic);  // nearest: first in line
    t.scene.instances[large].mesh = 1;
    for (uint32_t i = 0; i < 10; ++i) t.add({float(i) * 2.0f, 0.0f, 20.0f}, Motion::Dynamic);
    t.prepare();
    const uint32_t bigTriangles = g.triangleCount();
    REQUIRE(bigTriangles == 240u);
    BvhSettings settings;
    settings.maxFirstBuildTrianglesPerFrame = 30;  // five coarse boxes of 6 triangles
    BvhPlanner planner(settings);
    const BvhPlan first = planner.plan(t.scene, {0, 0, 0}, 0);
    // The large object alone: over the budget, but the first of the frame.
    REQUIRE(first.builds.size() == 1u);
    CHECK(first.find(first.builds[0].blas)->instance == int32_t(large));
    CHECK(first.stats.builtTriangles == bigTriangles);
    const BvhPlan second = planner.plan(t.scene, {0, 0, 0}, 1);
    CHECK(second.builds.size() == 5u);
    CHECK(second.stats.builtTriangles == 30u);
    const BvhPlan third = planner.plan(t.scene, {0, 0, 0}, 2);
    CHECK(third.builds.size() == 5u);
    CHECK(third.complete());
}

TEST_CASE("an object mixing single- and double-sided materials gets a BLAS for each, the double-sided one's TLAS "
          "instance marked so (back-face culling is per instance)") {
    TestScene t;
    t.scene.materials[1].doubleSided = true;
    Mesh mixed;
    mixed.name = "mixed";
    mixed.lods.push_back({{makeBox(glm::vec3(1.0f), 0), makeBox(glm::vec3(0.5f), 1), makeBox(glm::vec3(0.2f), 2)}});
    t.scene.meshes.push_back(mixed);
    const uint32_t i = t.add({0, 0, 0});
    t.scene.instances[i].mesh = 1;
    const uint32_t plain = t.add({3, 0, 0});
    t.prepare();
    BvhPlanner planner;
    const BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    std::vector<const TlasInstance*> ofMixed;
    for (const TlasInstance& ti : plan.tlas) {
        if (ti.sceneInstance == i) ofMixed.push_back(&ti);
        if (ti.sceneInstance == plain) CHECK_FALSE(ti.doubleSided);
    }
    REQUIRE(ofMixed.size() == 2u);
    for (const TlasInstance* ti : ofMixed) {
        const BlasDesc* d = plan.find(ti->blas);
        REQUIRE(d != nullptr);
        CHECK(ti->doubleSided == d->doubleSided);
        for (const BlasGeometry& g : d->geometries) CHECK(t.scene.materials[g.material].doubleSided == d->doubleSided);
        CHECK(d->geometries.size() == (d->doubleSided ? 1u : 2u));
    }
}

TEST_CASE("the particle TLAS exists only when there are particles") {
    TestScene t;
    t.add({0, 0, 0});
    t.prepare();
    BvhPlanner planner;
    BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    CHECK_FALSE(plan.particleTlas);
    t.scene.particles.push_back({{0, 1, 0}, 0.1f, glm::vec4(1.0f)});
    plan = planner.plan(t.scene, {0, 0, 0}, 1);
    CHECK(plan.particleTlas);
    CHECK(plan.particleCount == 1);
}

TEST_CASE("objects with more than 32 geometries split per material, keeping each material in one BLAS") {
    MeshLod lod;
    const auto addGeometries = [&](uint32_t material, int count) {
        for (int i = 0; i < count; ++i) {
            lod.geometries.push_back(makeBox(glm::vec3(1.0f), material));
        }
    };
    addGeometries(0, 2);
    addGeometries(1, 3);
    addGeometries(0, 1);
    CHECK(partitionGeometries(lod, 32).size() == 1);  // few geometries: one BLAS whatever the materials

    lod.geometries.clear();
    addGeometries(0, 20);
    addGeometries(1, 15);
    addGeometries(2, 5);
    const auto parts = partitionGeometries(lod, 32);
    REQUIRE(parts.size() == 2);
    std::set<uint32_t> seen;
    for (const auto& part : parts) {
        CHECK(part.size() <= 32);
        std::set<uint32_t> materials;
        for (uint32_t g : part) {
            seen.insert(g);
            materials.insert(lod.geometries[g].material);
        }
        for (uint32_t m : materials) {  // every geometry of the material is in this part
            for (uint32_t g = 0; g < lod.geometries.size(); ++g) {
                if (lod.geometries[g].material == m) {
                    CHECK(std::find(part.begin(), part.end(), g) != part.end());
                }
            }
        }
    }
    CHECK(seen.size() == 40);

    lod.geometries.clear();
    addGeometries(3, 70);  // one material beyond a BLAS: chunks of 32
    const auto chunks = partitionGeometries(lod, 32);
    REQUIRE(chunks.size() == 3);
    CHECK(chunks[0].size() == 32);
    CHECK(chunks[2].size() == 6);
}

TEST_CASE("primitive offsets lead every (instance, geometry, primitive) to its own packed triangle") {
    TestScene t;
    // A split object: 34 geometries over 2 materials, so two BLASes.
    Mesh split;
    split.name = "split";
    split.lods.resize(1);
    for (int g = 0; g < 34; ++g) {
        split.lods[0].geometries.push_back(
            makeSphere(0.2f + 0.01f * float(g), 6 + uint32_t(g % 3), 4, uint32_t(g % 2)));
    }
    t.scene.meshes.push_back(split);
    t.scene.materials[1].baseColorFactor = {0.2f, 0.9f, 0.4f, 1.0f};
    t.scene.materials[1].roughnessFactor = 0.3f;
    t.add({0, 0, 0});
    t.add({3, 0, 0});
    t.scene.instances[t.add({0, 3, 0})].mesh = 1;
    t.scene.instances[t.add({3, 3, 0}, Motion::Dynamic)].mesh = 1;
    t.prepare();
    BvhPlanner planner;
    const BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    CHECK(plan.blases.size() == 1 + 2 + 2);  // shared box, shared split (2 parts), dynamic split (2 parts)
    CHECK(plan.tlas.size() == 2 + 2 + 2);

    // Ranges are disjoint and inside the pool.
    std::vector<std::pair<uint32_t, uint32_t>> ranges;
    for (const BlasDesc& d : plan.blases) {
        ranges.emplace_back(d.poolOffset, d.poolOffset + d.triangleCount);
        CHECK(d.poolOffset + d.triangleCount <= plan.poolTriangles);
        CHECK(d.geometries.size() <= 32);
    }
    std::sort(ranges.begin(), ranges.end());
    for (size_t i = 1; i < ranges.size(); ++i) {
        CHECK(ranges[i - 1].second <= ranges[i].first);
    }

    const std::vector<glint::shader::PackedPrimitive> pool = buildPrimitivePool(t.scene, plan);
    size_t checked = 0;
    for (const TlasInstance& ti : plan.tlas) {
        const BlasDesc* d = plan.find(ti.blas);
        REQUIRE(d != nullptr);
        const MeshLod& lod = t.scene.meshes[d->mesh].lods[d->lod];
        for (uint32_t g = 0; g < d->geometries.size(); ++g) {
            const Geometry& geometry = lod.geometries[d->geometries[g].meshGeometry];
            const UnwrappedGeometry expected = unwrapGeometry(t.scene, geometry);
            for (uint32_t p = 0; p < geometry.triangleCount(); ++p) {
                // What a hit shader does with customIndex, geometry and primitive index.
                const uint32_t slot = plan.primitiveOffsets[glint::shader::primitiveOffsetSlot(ti.customIndex, g)] + p;
                for (int k = 0; k < 3; ++k) {
                    REQUIRE(pool[slot].vertices[k].albedoSmoothness ==
                            expected.primitives[p].vertices[k].albedoSmoothness);
                    REQUIRE(pool[slot].vertices[k].normalMetallicReflectance ==
                            expected.primitives[p].vertices[k].normalMetallicReflectance);
                }
                ++checked;
            }
        }
    }
    CHECK(checked > 1000);
}

TEST_CASE("a dropped BLAS frees its pool range only after the frames in flight") {
    TestScene t;
    t.add({0, 0, 0}, Motion::Dynamic);
    t.add({3, 0, 0}, Motion::Dynamic);
    t.prepare();
    BvhSettings settings;
    settings.framesInFlight = 2;
    BvhPlanner planner(settings);
    BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    REQUIRE(plan.blases.size() == 2);
    const uint32_t freedOffset = plan.blases[1].poolOffset;
    const uint32_t poolSize = plan.poolTriangles;

    t.scene.instances.pop_back();  // the second object goes away
    plan = planner.plan(t.scene, {0, 0, 0}, 1);
    REQUIRE(plan.drops.size() == 1);
    CHECK(plan.drops[0].reason == BlasDropReason::ObjectRemoved);
    CHECK(plan.blases.size() == 1);

    t.add({3, 0, 0}, Motion::Dynamic);  // a new object of the same size, next frame
    plan = planner.plan(t.scene, {0, 0, 0}, 2);
    REQUIRE(plan.builds.size() == 1);
    CHECK(plan.find(plan.builds[0].blas)->poolOffset != freedOffset);  // still in flight
    CHECK(plan.poolTriangles > poolSize);

    t.add({6, 0, 0}, Motion::Dynamic);
    plan = planner.plan(t.scene, {0, 0, 0}, 3);  // frame 1 + 2 in flight: reusable now
    REQUIRE(plan.builds.size() == 1);
    CHECK(plan.find(plan.builds[0].blas)->poolOffset == freedOffset);
}

TEST_CASE("an instance removed from the middle: a deformable BLAS is rebuilt when the instance now at its index is "
          "shaped otherwise") {
    // Three deformable boxes posed differently (morph weights); each index
    // owns a BLAS. Removing the first moves the others down one index onto
    // BLASes built from another shape, with deformVersion left as it was.
    TestScene t;
    for (int i = 0; i < 3; ++i) {
        t.add({float(i) * 3.0f, 0, 0}, Motion::Dynamic);
    }
    t.prepare();
    for (size_t i = 0; i < 3; ++i) {
        t.scene.instances[i].morphWeights = {0.5f * float(i)};
    }
    BvhPlanner planner;
    BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    REQUIRE(plan.builds.size() == 3);
    plan = planner.plan(t.scene, {0, 0, 0}, 1);
    CHECK(plan.builds.empty());

    t.scene.instances.erase(t.scene.instances.begin());
    plan = planner.plan(t.scene, {0, 0, 0}, 2);
    REQUIRE(plan.drops.size() == 1);
    CHECK(plan.drops[0].reason == BlasDropReason::ObjectRemoved);
    CHECK(countReason(plan, BlasBuildReason::Deformed) == 2);
    CHECK(inTlas(plan, 0));
    CHECK(inTlas(plan, 1));

    // The last one removed: nobody moves, nothing builds.
    t.scene.instances.pop_back();
    plan = planner.plan(t.scene, {0, 0, 0}, 3);
    CHECK(plan.drops.size() == 1);
    CHECK(plan.builds.empty());
}

TEST_CASE("edited assets drop every BLAS, which builds again; instance edits alone keep them") {
    TestScene t;
    t.add({0, 0, 0});
    t.add({3, 0, 0});
    t.add({6, 0, 0}, Motion::Dynamic);
    t.prepare();
    BvhPlanner planner;
    BvhPlan plan = planner.plan(t.scene, {0, 0, 0}, 0);
    REQUIRE(plan.builds.size() == 2);  // the static mesh's shared BLAS, the dynamic one's own
    t.add({9, 0, 0});                  // an instance more: no asset changed
    t.scene.instances[0].transform = glm::translate(glm::mat4(1.0f), {0, 1, 0});
    plan = planner.plan(t.scene, {0, 0, 0}, 1);
    CHECK(plan.builds.empty());
    CHECK(plan.drops.empty());

    const auto rebuiltAll = [&](uint64_t frame) {
        plan = planner.plan(t.scene, {0, 0, 0}, frame);
        CHECK(plan.drops.size() == 2);
        for (const BlasDrop& d : plan.drops) CHECK(d.reason == BlasDropReason::AssetsEdited);
        CHECK(countReason(plan, BlasBuildReason::FirstInRange) == 2);
        CHECK(plan.tlas.size() == 4);
    };
    ++t.scene.assetRevision;  // a mesh or material edited in place
    rebuiltAll(2);
    plan = planner.plan(t.scene, {0, 0, 0}, 3);
    CHECK(plan.builds.empty());
    t.scene.materials.emplace_back();  // a material added, no revision: noticed by the count
    rebuiltAll(4);
}

TEST_CASE("eviction drops BLASes of objects long outside the radius, and they are rebuilt on return") {
    TestScene t;
    t.add({0, 0, 0});
    t.prepare();
    BvhSettings settings;
    settings.evictAfterFramesOutside = 10;
    BvhPlanner planner(settings);
    size_t builds = 0, drops = 0;
    for (uint64_t frame = 0; frame < 60; ++frame) {
        const glm::vec3 camera = frame < 20 || frame >= 40 ? glm::vec3(0.0f) : glm::vec3(500, 0, 0);
        const BvhPlan plan = planner.plan(t.scene, camera, frame);
        builds += plan.builds.size();
        drops += plan.drops.size();
        for (const BlasDrop& d : plan.drops) {
            CHECK(d.reason == BlasDropReason::Evicted);
        }
    }
    CHECK(drops == 1);
    CHECK(builds == 2);
}

TEST_CASE("plan frames must increase") {
    TestScene t;
    t.add({0, 0, 0});
    t.prepare();
    BvhPlanner planner;
    planner.plan(t.scene, {0, 0, 0}, 5);
    CHECK_THROWS_AS(planner.plan(t.scene, {0, 0, 0}, 5), SceneError);
    planner.reset();
    CHECK(planner.plan(t.scene, {0, 0, 0}, 0).builds.size() == 1);
}

TEST_CASE("along the plaza's camera path every BVH policy holds") {
    Scene s = makePlaza();
    BvhPlanner planner;
    Camera camera;
    camera.resolution = {960, 540};
    camera.lens = s.lens;
    const uint32_t frames = 600;  // 20 s at 30 Hz
    std::map<BlasId, size_t> staticBuilds;
    std::set<uint32_t> everInTlas;
    BvhStats total;
    size_t framesWithCulling = 0, framesWithDeferredSkinned = 0;
    for (uint32_t frame = 0; frame < frames; ++frame) {
        const CameraPose pose = s.cameraPath.atFrame(frame, frames);
        const double t = double(frame) / 30.0;
        if (frame == 0) {
            camera.reset(pose, frame);
        } else {
            camera.advance(pose, frame);
        }
        advanceScene(s, t, &camera);
        const BvhPlan plan = planner.plan(s, camera);
        REQUIRE(plan.stats.rebuilt <= 16);
        REQUIRE(plan.stats.rebuiltSkinned <= 12);
        if (frame > 0) {
            REQUIRE(plan.stats.rebuiltFirstPerson == 1);  // the arm deforms every frame
        }
        for (const BlasBuild& b : plan.builds) {
            const BlasDesc* d = plan.find(b.blas);
            if (d->motion == Motion::Static) {
                REQUIRE(++staticBuilds[b.blas] == 1);
            }
        }
        for (const TlasInstance& ti : plan.tlas) {
            everInTlas.insert(ti.sceneInstance);
        }
        framesWithCulling += plan.stats.instancesCulled > 0 ? 1 : 0;
        framesWithDeferredSkinned += plan.stats.deferredSkinnedBudget > 0 ? 1 : 0;
        total.built += plan.stats.built;
        total.rebuilt += plan.stats.rebuilt;
        total.rebuiltSkinned += plan.stats.rebuiltSkinned;
        total.skippedUnchanged += plan.stats.skippedUnchanged;
        total.instancesMoved += plan.stats.instancesMoved;
        if (frame == frames - 1) {
            MESSAGE("plaza, last frame: " << formatStats(plan.stats));
        }
    }
    MESSAGE("plaza over " << frames << " frames: " << total.built << " builds, " << total.rebuilt << " rebuilds ("
                          << total.rebuiltSkinned << " skinned), " << total.instancesMoved
                          << " moved-instance updates");
    CHECK(framesWithCulling == frames);             // something is always beyond 100 m
    CHECK(framesWithDeferredSkinned > frames / 2);  // 14 skinned objects against a cap of 12
    // The towers that never come within 100 m of the path never got a BLAS.
    for (size_t i = 0; i < s.instances.size(); ++i) {
        if (s.instances[i].name == "tower far east" || s.instances[i].name == "tower far south" ||
            s.instances[i].name == "glass tower") {
            CHECK(everInTlas.count(uint32_t(i)) == 0);
        }
        if (s.instances[i].name == "tower north" || s.instances[i].name == "tower west" ||
            s.instances[i].name == "tower east") {
            CHECK(everInTlas.count(uint32_t(i)) == 1);  // these do, at some point of the path
        }
    }
}
