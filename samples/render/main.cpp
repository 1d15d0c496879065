// glint-render: the headless renderer. Renders a scene with the hybrid
// reflections (passes/reflection_frame.h) in one of three modes over a
// deterministic camera path and writes the last frame as a PNG, optionally
// a debug view instead, and stats JSON. `--scene smoke` instead traces the
// smoke scene with every ray backend the device has (the first-light check
// of the ray tracing stack).

#include "common/app.h"
#include "common/reflection_run.h"
#include "glint/passes/smoke_trace.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/image_io.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

using namespace glint;

namespace {

constexpr const char* kUsage =
    "glint-render: renders a scene with the hybrid reflections (or hybrid, ssr, rt, or the converged\n"
    "reference) over its camera path and writes the last frame as a PNG.";

const std::vector<app::Flag> kFlags = {
    {"scene", "plaza (default), hard-cases, city[:instances=N,triangles=T,seed=S] (16..4096 buildings of about T "
              "triangles; default 64, 40000, 1), mirror-motion[:lamp=rigid|skinned|morphed], smoke (first light of each ray backend), FILE.gltf or FILE.glb"},
    {"mode", "hybrid (default), ssr, rt, or reference (every ray traced, accumulated from a still camera)"},
    {"size", "WxH or N (square); default 256"},
    {"frames", "frames along the camera path; the last is written (default 1)"},
    {"out", "the PNG (default build/out/<scene>_<mode>.png)"},
    {"debug-view", "write a debug view instead of the final image (--list-debug-views)"},
    {"stats", "FILE.json: per-pass times, rays, pixel classes, BVH and raster work"},
    {"backend", "auto (default), query or pipeline: the ray backend"},
    {"bvh-queue", "async (default) or graphics: where the BVH builds run"},
    {"time", "SECONDS along the camera path to start at (plaza: 3)"},
    {"set", "NAME=VALUE[,NAME=VALUE...]: tunable parameters (--list-parameters)"},
    {"tolerance", "reference mode: stop when the mean changes by less than this (default 2e-4)"},
    {"seed", "reference mode: the noise seed (default 0)"},
    {"max-frames", "reference mode: at most this many frames"},
    {"camera", "NAME or INDEX: a glTF camera or a built-in preset, held still"},
    {"environment", "FILE.hdr: an equirectangular Radiance HDR (2:1; -Z at its centre, +Y at its top) lights and is "
                    "reflected in place of the scene's sky, prefiltered by roughness on the GPU once"},
    {"pass-timer", "auto (default), gpu or host: GPU timestamps, or each pass submitted alone and timed on the host "
                   "(auto: host on a CPU device such as lavapipe, whose timestamps miss compute dispatches)"},
};

float parseSeconds(const std::string& text) {
    try {
        size_t used = 0;
        const float seconds = std::stof(text, &used);
        if (used == text.size() && std::isfinite(seconds) && seconds >= 0.0f) return seconds;
    } catch (const std::exception&) {
    }
    throw std::runtime_error("--time " + text + ": not a non-negative number of seconds");
}

int renderSmoke(gpu::Context& ctx, const std::filesystem::path& outDir, uint32_t width, uint32_t height) {
    passes::SmokeTracer tracer(ctx, scene::makeSmokeScene());
    for (auto backend : passes::availableBackends(ctx)) {
        const auto result = tracer.trace(backend, width, height);
        const std::string path = (outDir / ("smoke_" + std::string(passes::backendName(backend)) + ".png")).string();
        app::writePng(path, width, height, passes::smokeImage(result.hits, width, height));
        if (result.gpuMilliseconds) {
            spdlog::info("{}: {:.3f} ms GPU, {:.2f} Mrays/s", passes::backendName(backend), *result.gpuMilliseconds,
                         double(width) * height / (*result.gpuMilliseconds * 1e3));
        }
    }
    ctx.waitIdle();
    return app::validationClean(ctx) ? 0 : 2;
}

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-render", [&] {
        app::Args args(argc, argv, kUsage, kFlags,
                       {{"list-debug-views", "print the debug views (name, modes, what each shows) and exit"},
                        {"list-parameters", "print the tunable parameters (--set) and exit"}});
        if (args.has("list-parameters")) {
            std::fputs(app::parameterListing().c_str(), stdout);
            return 0;
        }
        if (args.has("list-debug-views")) {
            for (const passes::DebugViewInfo& v : passes::debugViews()) {
                const std::string modes = std::string(v.modes.hybrid ? "hybrid " : "") + (v.modes.ssr ? "ssr " : "") +
                                          (v.modes.rt ? "rt" : "");
                std::printf("%-18.*s %-15s %.*s\n", int(v.name.size()), v.name.data(), modes.c_str(),
                            int(v.shows.size()), v.shows.data());
            }
            return 0;
        }
        const std::string sceneName = args.get("scene", "plaza");
        const auto [width, height] = app::parseSize(args.get("size", "256"));
        const uint32_t frames = args.getUint("frames", 1);
        if (frames == 0) throw std::runtime_error("--frames 0: must be at least 1");

        app::ReflectionRunOptions options;
        options.width = width;
        options.height = height;
        options.frames = frames;
        const std::string modeText = args.get("mode", "hybrid");
        if (modeText == "reference") {
            options.reference.enabled = true;
            const std::string tolerance = args.get("tolerance", std::to_string(options.reference.tolerance));
            try {
                options.reference.tolerance = std::stod(tolerance);
            } catch (const std::exception&) {
                options.reference.tolerance = 0.0;
            }
            if (!(options.reference.tolerance > 0.0) || !std::isfinite(options.reference.tolerance)) {
                throw std::runtime_error("--tolerance " + tolerance + ": not a positive number");
            }
            options.reference.seed = args.getUint("seed", 0);
            options.reference.maxFrames = args.getUint("max-frames", options.reference.maxFrames);
        }
        try {
            options.frame.mode = passes::parseMode(modeText == "reference" ? "rt" : modeText);
            options.renderer.backend = passes::parseBackend(args.get("backend", "auto"));
        } catch (const std::invalid_argument& e) {
            throw std::runtime_error(std::string("--mode/--backend: ") + e.what());
        }
        // --set a=1,b=2: the tunable parameters (--list-parameters).
        app::setParameters(options, args.get("set", ""));
        // Where the BVH builds run: async compute (default; the graphics
        // queue on one-queue devices) or the graphics queue, to measure what
        // the overlap buys.
        const std::string bvhQueue = args.get("bvh-queue", "async");
        if (bvhQueue != "async" && bvhQueue != "graphics") {
            throw std::runtime_error("--bvh-queue " + bvhQueue + ": expected async or graphics");
        }
        options.renderer.bvhUpdate.queue = bvhQueue == "graphics" ? rg::Queue::Graphics : rg::Queue::AsyncCompute;
        // Pass times: GPU timestamps, or each pass submitted alone and timed
        // on the host (auto: host on a CPU device such as lavapipe, whose
        // timestamps do not cover compute dispatches).
        const std::string passTimer = args.get("pass-timer", "auto");
        if (passTimer == "gpu") {
            options.passTimer = rg::PassTimer::GpuTimestamps;
        } else if (passTimer == "host") {
            options.passTimer = rg::PassTimer::HostSerial;
        } else if (passTimer != "auto") {
            throw std::runtime_error("--pass-timer " + passTimer + ": expected auto, gpu or host");
        }
        options.frame.debugView = args.get("debug-view", "");
        if (!options.frame.debugView.empty()) {
            if (passes::findDebugView(options.frame.debugView) == nullptr) {
                throw std::runtime_error("--debug-view " + options.frame.debugView +
                                         ": unknown (--list-debug-views prints the names)");
            }
        }
        // Built-in scenes: 3 s along the plaza's path looks down the plaza
        // past the puddles (the path starts behind a palm trunk).
        options.startSeconds = parseSeconds(args.get("time", sceneName == "plaza" ? "3" : "0"));

        const std::string defaultOut =
            "build/out/" + std::filesystem::path(sceneName).stem().string() + "_" + modeText + ".png";
        const std::filesystem::path out = args.get("out", defaultOut);

        gpu::Context ctx(args.contextOptions());
        if (sceneName == "smoke") {
            return renderSmoke(ctx, out.extension() == ".png" ? out.parent_path() : out, width, height);
        }
        scene::Scene scene = scene::loadScene(sceneName, args.gltfOptions());
        if (args.has("environment")) {
            // Errors name the file (scene::SceneError): missing, unreadable, not 2:1.
            const scene::Environment image = scene::loadEquirectangularEnvironment(args.get("environment", ""));
            scene.environment.kind = image.kind;
            scene.environment.image = image.image;
        }
        // --camera: a glTF camera or a built-in preset, held still (frames
        // beyond the first orbit it slowly); without it, a file's first
        // camera or framing view, or a built-in scene's path.
        if (args.has("camera")) {
            scene::useView(scene, scene::findView(scene, args.get("camera", "")));
            if (!args.has("time")) options.startSeconds = 0.0f;
        }
        if (options.reference.enabled) {
            spdlog::info("{}: reference, {}x{}, until the mean changes by less than {} (at most {} frames)", scene.name,
                         width, height, options.reference.tolerance, options.reference.maxFrames);
        } else {
            spdlog::info("{}: {} mode, {}x{}, {} frame{}", scene.name, passes::modeName(options.frame.mode), width,
                         height, frames, frames == 1 ? "" : "s");
        }
        const app::ReflectionRunResult result = app::runReflections(ctx, scene, options);
        app::writePng(out.string(), width, height, result.rgba);

        for (const app::PassTime& p : result.passes) {
            spdlog::info("  {:<28} {:>8.3f} ms{}", p.name, p.milliseconds,
                         p.queue == rg::Queue::AsyncCompute ? " (async compute)" : "");
        }
        if (result.reflectionMs) {
            const std::string span =
                result.reflectionSpanMs ? fmt::format(" ({:.3f} ms as one span)", *result.reflectionSpanMs) : "";
            spdlog::info("reflections {:.3f} ms{} (mean {:.3f}), frame {:.3f} ms {}, {:.3f} ms wall (median of {} "
                         "frames); rays: {} SSLR, {} RT",
                         *result.reflectionMs, span, result.reflectionMeanMs.value_or(0.0), *result.totalMs,
                         result.passTimer == rg::PassTimer::HostSerial ? "host (passes submitted alone)" : "GPU",
                         result.frameWallMs.value_or(0.0), result.framesTimed,
                         result.sslrRays, result.rtRays);
        }
        if (args.has("stats")) {
            const std::filesystem::path statsPath = args.get("stats", "");
            if (statsPath.has_parent_path()) std::filesystem::create_directories(statsPath.parent_path());
            std::ofstream file(statsPath);
            file << app::statsJson(ctx, options, result);
            if (!file) throw std::runtime_error("cannot write stats '" + statsPath.string() + "'");
            spdlog::info("wrote {}", statsPath.string());
        }
        ctx.waitIdle();
        return app::validationClean(ctx) ? 0 : 2;
    });
}
