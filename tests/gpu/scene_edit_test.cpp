// A scene that changes under the renderer, as an embedding engine changes
// it between frames: instances added, removed and given another mesh;
// meshes, materials and textures edited (Scene::assetRevision), new ones
// added. After the edit the renderer's image must be the image of a
// renderer made fresh on the edited scene, in every mode (no stale BLAS,
// primitive offsets, hit materials or G-buffer vertices), with validation
// on.
#include "support/gpu_test.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/procedural_meshes.h"

#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr glm::uvec2 kSize{64, 48};

// Renders frames [first, first + count) of `s` from the start of its camera
// path (history reset on the first, no jitter, time frozen) and returns the
// last composited image.
std::vector<uint8_t> render(gpu::Context& ctx, rg::Executor& executor, passes::ReflectionRenderer& renderer,
                            const scene::Scene& s, passes::ReflectionMode mode, uint32_t first, uint32_t count) {
    const rg::HostReadback readback(ctx, VkDeviceSize(kSize.x) * kSize.y * 4, "scene_edit.readback");
    scene::Camera camera;
    camera.resolution = kSize;
    camera.lens = s.lens;
    camera.jitter = false;
    const scene::CameraPose pose = s.cameraPath.evaluate(0.0f);
    for (uint32_t i = first; i < first + count; ++i) {
        if (i == first) {
            camera.reset(pose, i);
        } else {
            camera.advance(pose, i);
        }
        rg::Graph graph(executor.queueCaps());
        passes::ReflectionFrameSettings settings;
        settings.mode = mode;
        settings.resetHistory = i == first;
        const passes::ReflectionFrame f = renderer.addFrame(graph, camera, settings);
        rg::FrameResources resources;
        renderer.bind(resources, f);
        if (i + 1 == first + count) {
            readback.copy(graph, resources, f.output.color);
        }
        executor.run(graph.compile(executor.compileOptions()), resources);
    }
    // The device's wait, not only the executor's timelines: the validation
    // layer here does not count a host wait on a timeline semaphore, and
    // would take the next renderer's uploads into memory freed after it
    // (the readback's, for one) for hazards.
    ctx.waitIdle();
    std::vector<uint8_t> rgba(size_t(kSize.x) * kSize.y * 4);
    std::memcpy(rgba.data(), readback.bytes().data(), rgba.size());
    return rgba;
}

// The image of a renderer made fresh on `s`, at the same frame numbers.
std::vector<uint8_t> renderFresh(gpu::Context& ctx, const scene::Scene& s, passes::ReflectionMode mode,
                                 uint32_t first, uint32_t count) {
    rg::Executor executor(ctx);
    passes::ReflectionRenderer renderer(ctx, s);
    return render(ctx, executor, renderer, s, mode, first, count);
}

size_t differingPixels(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.size(); i += 4) {
        n += std::memcmp(&a[i], &b[i], 4) != 0 ? 1 : 0;
    }
    return n;
}

size_t findInstance(const scene::Scene& s, const auto& predicate) {
    for (size_t i = 0; i < s.instances.size(); ++i) {
        if (predicate(s.instances[i])) return i;
    }
    FAIL("no instance of the kind the test edits");
    return 0;
}

// Instance edits an engine makes without touching assets: a skinned and a
// rigidly moving instance removed from the middle (every later instance
// shifts down), a static one given another mesh, a copy of a static one
// added in front of the camera.
void editInstances(scene::Scene& s) {
    const size_t skinned = findInstance(s, [](const scene::Instance& i) {
        return i.motion == scene::Motion::Skinned && !i.firstPerson;
    });
    s.instances.erase(s.instances.begin() + std::ptrdiff_t(skinned));
    const size_t dynamic = findInstance(s, [](const scene::Instance& i) { return i.motion == scene::Motion::Dynamic; });
    s.instances.erase(s.instances.begin() + std::ptrdiff_t(dynamic));

    const size_t a = findInstance(s, [](const scene::Instance& i) { return i.motion == scene::Motion::Static; });
    const size_t b = findInstance(s, [&](const scene::Instance& i) {
        return i.motion == scene::Motion::Static && i.mesh != s.instances[a].mesh;
    });
    s.instances[a].mesh = s.instances[b].mesh;

    const scene::CameraPose pose = s.cameraPath.evaluate(0.0f);
    const glm::vec3 ahead = pose.position + 4.0f * glm::normalize(pose.target - pose.position);
    scene::Instance copy = s.instances[b];
    copy.name = "added copy";
    copy.node = scene::kNone;
    copy.transform = glm::translate(glm::mat4(1.0f), ahead) * glm::scale(glm::mat4(1.0f), glm::vec3(0.3f));
    copy.previousTransform = copy.transform;
    s.instances.push_back(copy);
}

// Asset edits: the material of the largest static instance's first
// geometry turned into a green mirror, a mesh scaled in place, and a new
// mesh with a new material instanced in front of the camera.
void editAssets(scene::Scene& s) {
    size_t largest = 0;
    float largestSize = -1.0f;
    for (size_t i = 0; i < s.instances.size(); ++i) {
        const scene::Instance& inst = s.instances[i];
        if (inst.motion != scene::Motion::Static) continue;
        const float size = glm::length(scene::instanceBounds(s, inst).size());
        if (size > largestSize) {
            largestSize = size;
            largest = i;
        }
    }
    scene::Material& floor = s.materials.at(s.meshes[s.instances[largest].mesh].lods[0].geometries[0].material);
    floor.baseColorFactor = glm::vec4(0.2f, 0.6f, 0.25f, 1.0f);
    floor.roughnessFactor = 0.05f;
    floor.metallicFactor = 1.0f;
    floor.metallicRoughnessTexture = {};

    // Every LOD of a static instance's mesh (the reflection LOD too), twice as tall.
    const size_t tall = findInstance(s, [&](const scene::Instance& i) {
        return i.motion == scene::Motion::Static && i.mesh != s.instances[largest].mesh;
    });
    scene::Mesh& mesh = s.meshes[s.instances[tall].mesh];
    mesh.bounds = {};
    for (scene::MeshLod& lod : mesh.lods) {
        for (scene::Geometry& g : lod.geometries) {
            for (glm::vec3& p : g.positions) p.y *= 2.0f;
            g.bounds = scene::computeBounds(g.positions);
            mesh.bounds.extend(g.bounds);
        }
    }

    scene::Material red;
    red.name = "added red";
    red.baseColorFactor = glm::vec4(0.9f, 0.1f, 0.05f, 1.0f);
    red.metallicFactor = 0.0f;
    red.roughnessFactor = 0.3f;
    s.materials.push_back(red);
    scene::Mesh box;
    box.name = "added box";
    box.lods.push_back({{scene::makeBox(glm::vec3(1.0f), uint32_t(s.materials.size() - 1))}});
    box.bounds = box.lods[0].geometries[0].bounds;
    s.meshes.push_back(box);
    const scene::CameraPose pose = s.cameraPath.evaluate(0.0f);
    const glm::vec3 forward = glm::normalize(pose.target - pose.position);
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    scene::Instance inst;
    inst.name = "added box";
    inst.mesh = uint32_t(s.meshes.size() - 1);
    inst.transform = glm::translate(glm::mat4(1.0f), pose.position + 5.0f * forward - 1.5f * right);
    inst.previousTransform = inst.transform;
    s.instances.push_back(inst);
    ++s.assetRevision;
}

} // namespace

TEST_CASE("instances and assets edited between frames: the image is a fresh renderer's, in every mode") {
    test::GpuTest gpu;
    for (const passes::ReflectionMode mode :
         {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Rt, passes::ReflectionMode::Ssr}) {
        CAPTURE(std::string(passes::modeName(mode)));
        scene::Scene s = scene::makeBuiltinScene("plaza");
        rg::Executor executor(gpu.ctx());
        passes::ReflectionRenderer renderer(gpu.ctx(), s);
        const std::vector<uint8_t> before = render(gpu.ctx(), executor, renderer, s, mode, 0, 2);

        // Instances only: the assets stay uploaded, and only the BLASes of
        // instances whose index now holds another mesh or motion build.
        const bool traced = renderer.tracesRays() && mode != passes::ReflectionMode::Ssr;
        const uint64_t buildsBefore = renderer.bvhGpuStats().totalBlasBuilds;
        editInstances(s);
        const std::vector<uint8_t> instancesEdited = render(gpu.ctx(), executor, renderer, s, mode, 2, 2);
        CHECK(differingPixels(instancesEdited, before) > 0);
        CHECK(differingPixels(instancesEdited, renderFresh(gpu.ctx(), s, mode, 2, 2)) == 0);
        if (traced) {
            CHECK(renderer.bvhGpuStats().totalBlasBuilds - buildsBefore < renderer.bvhGpuStats().residentBlases / 2);
        }

        // Assets: edited, added; every renderer part loads them again, and
        // every BLAS builds anew.
        editAssets(s);
        const uint64_t buildsBeforeAssets = renderer.bvhGpuStats().totalBlasBuilds;
        const std::vector<uint8_t> assetsEdited = render(gpu.ctx(), executor, renderer, s, mode, 4, 2);
        CHECK(differingPixels(assetsEdited, instancesEdited) > kSize.x * kSize.y / 20);
        CHECK(differingPixels(assetsEdited, renderFresh(gpu.ctx(), s, mode, 4, 2)) == 0);
        if (traced) {
            CHECK(renderer.bvhGpuStats().totalBlasBuilds - buildsBeforeAssets >= renderer.bvhGpuStats().residentBlases);
        }
    }
}
