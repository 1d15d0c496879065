// glint-bvh-bench: what the BVH update costs per scene, measured with GPU
// timestamps around its one graph pass (executor.timings()):
//   first   the first frame: every BLAS in range built, plus the TLAS;
//   steady  median over the animated frames that follow: the round-robin
//           rebuilds (skinned, first-person) plus the TLAS;
//   tlas    median over frames with no BLAS work at all (the TLAS, its
//           instance copy and the offset table), where a scene has them;
// the memory the manager holds after the run, and the first frame's scratch
// request. Scenes:
// the built-in plaza, then every glTF under ../shared/scenes (or --scenes
// a,b,c: built-in names or paths). The last line is machine-readable:
//   bvh_first_ms_plaza=<ms> bvh_steady_ms_plaza=<ms> bvh_mib_plaza=<MiB>

#include "common/app.h"
#include "graph/executor.h"
#include "graph/graph.h"
#include "passes/bvh_update.h"
#include "scene/animation.h"
#include "scene/builtin_scenes.h"
#include "scene/bvh_planner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

using namespace glint;

namespace {

struct SceneResult {
    std::string name;
    uint64_t triangles = 0;  // in the pool after the first frame
    uint32_t blases = 0;
    uint32_t tlasInstances = 0;
    double firstMs = 0;
    std::optional<double> steadyMs;
    double steadyRebuilds = 0;  // mean BLAS rebuilds of the steady frames
    std::optional<double> tlasOnlyMs;
    passes::BvhGpuStats memory;
};

std::optional<double> median(std::vector<double> v) {
    if (v.empty()) return std::nullopt;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

double passMilliseconds(const rg::Executor& executor) {
    for (const rg::PassTiming& t : executor.timings()) {
        if (t.name == "bvh_update") {
            if (!t.milliseconds) throw std::runtime_error("the device's queue has no timestamps");
            return *t.milliseconds;
        }
    }
    throw std::runtime_error("no timing for the bvh_update pass");
}

SceneResult measure(gpu::Context& ctx, const std::string& name, uint32_t frames) {
    scene::Scene s = scene::loadScene(name);
    scene::BvhPlanner planner;
    rg::Executor executor(ctx);
    passes::BvhManager bvh(ctx, s);
    SceneResult r;
    r.name = std::filesystem::path(name).filename().string();
    std::vector<double> steady, tlasOnly;
    uint64_t rebuilds = 0;
    for (uint32_t f = 0; f < frames; ++f) {
        scene::advanceScene(s, f / 30.0);  // 30 Hz animation
        const scene::CameraPose pose = s.cameraPath.atFrame(0, 1);  // a still camera: BLAS work only from animation
        const scene::BvhPlan plan = planner.plan(s, pose.position, f);
        rg::Graph graph(executor.queueCaps());
        const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, plan);
        rg::FrameResources resources;
        bvh.bind(resources, out);
        executor.run(graph.compile(executor.compileOptions()), resources);
        // One frame at a time: the timestamps then belong to this frame.
        executor.waitIdle();
        const double ms = passMilliseconds(executor);
        if (f == 0) {
            r.firstMs = ms;
            r.triangles = plan.poolTriangles;
            r.blases = plan.stats.residentBlases;
            r.tlasInstances = plan.stats.tlasInstances;
            r.memory.scratchBytes = bvh.stats().scratchBytes;  // the largest request: every BLAS at once
        } else if (plan.builds.empty()) {
            tlasOnly.push_back(ms);
        } else {
            steady.push_back(ms);
            rebuilds += plan.builds.size();
        }
    }
    // Held after the run: static BLASes' build positions are released by then.
    const uint64_t scratch = r.memory.scratchBytes;
    r.memory = bvh.stats();
    r.memory.scratchBytes = scratch;
    r.steadyMs = median(steady);
    r.steadyRebuilds = steady.empty() ? 0.0 : double(rebuilds) / double(steady.size());
    r.tlasOnlyMs = median(tlasOnly);
    return r;
}

std::vector<std::string> defaultScenes() {
    std::vector<std::string> scenes = {"plaza"};
    std::vector<std::string> files;
    std::error_code ec;
    for (const auto& dir : std::filesystem::directory_iterator(GLINT_SCENES_DIR, ec)) {
        for (const auto& entry : std::filesystem::directory_iterator(dir.path(), ec)) {
            const std::string ext = entry.path().extension().string();
            if (ext == ".gltf" || ext == ".glb") files.push_back(entry.path().string());
        }
    }
    std::sort(files.begin(), files.end());
    scenes.insert(scenes.end(), files.begin(), files.end());
    return scenes;
}

std::string ms(const std::optional<double>& v) {
    char buf[32];
    if (!v) return "-";
    std::snprintf(buf, sizeof buf, "%.3f", *v);
    return buf;
}

double mib(uint64_t bytes) { return double(bytes) / (1024.0 * 1024.0); }

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-bvh-bench", [&] {
        app::Args args(argc, argv, "usage: glint-bvh-bench [--scenes a,b,...] [--frames N]", {"scenes", "frames"}, {});
        const uint32_t frames = args.getUint("frames", 31);
        if (frames < 2 || frames > 10000) {
            throw std::runtime_error("--frames " + std::to_string(frames) + ": must be 2..10000");
        }
        std::vector<std::string> scenes;
        if (args.has("scenes")) {
            std::stringstream list(args.get("scenes", ""));
            for (std::string item; std::getline(list, item, ',');) scenes.push_back(item);
        } else {
            scenes = defaultScenes();
        }

        gpu::Context ctx(args.contextOptions());
        std::printf("glint-bvh-bench on %s (%s), %u frames per scene, builds on %s\n", ctx.caps().deviceName.c_str(),
                    ctx.caps().driverName.c_str(), frames,
                    ctx.caps().hasAsyncCompute() ? "the async compute queue" : "the graphics queue (no async compute)");
        std::printf("%-34s %8s %5s %5s %9s %9s %8s %9s %8s %8s %8s %8s %8s\n", "scene", "tris", "blas", "tlas",
                    "first_ms", "steady_ms", "rebuilds", "tlas_ms", "blas_MiB", "tlas_MiB", "pool_MiB", "geom_MiB",
                    "scr_MiB");
        std::optional<SceneResult> plaza;
        for (const std::string& name : scenes) {
            const SceneResult r = measure(ctx, name, frames);
            const passes::BvhGpuStats& m = r.memory;
            std::printf("%-34s %8llu %5u %5u %9.3f %9s %8.1f %9s %8.2f %8.2f %8.2f %8.2f %8.2f\n", r.name.c_str(),
                        static_cast<unsigned long long>(r.triangles), r.blases, r.tlasInstances, r.firstMs,
                        ms(r.steadyMs).c_str(), r.steadyRebuilds, ms(r.tlasOnlyMs).c_str(), mib(m.blasBytes),
                        mib(m.tlasBytes), mib(m.poolBytes), mib(m.geometryBytes + m.positionBytes), mib(m.scratchBytes));
            if (name == "plaza") plaza = r;
        }
        if (plaza) {
            const passes::BvhGpuStats& m = plaza->memory;
            std::printf("bvh_first_ms_plaza=%.3f bvh_steady_ms_plaza=%s bvh_mib_plaza=%.2f\n", plaza->firstMs,
                        ms(plaza->steadyMs).c_str(),
                        mib(m.blasBytes + m.tlasBytes + m.poolBytes + m.geometryBytes + m.positionBytes));
        }
        ctx.waitIdle();
        return app::validationClean(ctx) ? 0 : 2;
    });
}
