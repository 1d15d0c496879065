// glint-bench: what each reflection setting costs and what it
// loses. Renders the converged reference once, then every mode with its
// defaults and sweeps of the main parameters over the same camera path,
// and reports per-pass GPU time (median over frames; on a CPU device the
// frame's host time too), ray counts and the error of the last frame
// against the reference (FLIP, relMSE, PSNR, SSIM) on the final image and on
// the resolved reflection term. Writes a table on stdout, CSV, JSON and a
// time-against-error plot with the Pareto front.
//
// The reference is rendered where the measured runs end: at the pose and
// scene time of their last frame (a still camera path holding that pose),
// because a test configuration's last frame is what is compared and the
// reference's camera stands still.

#include "bench/measure.h"
#include "bench/motion.h"
#include "bench/report.h"
#include "bench/scale.h"
#include "common/app.h"
#include "common/reflection_run.h"
#include "glint/metrics/error_map.h"
#include "glint/metrics/flip.h"
#include "glint/metrics/image.h"
#include "glint/metrics/pixel_metrics.h"
#include "glint/scene/builtin_scenes.h"

#include "glint_commit.h"  // generated: GLINT_BUILD_COMMIT

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>

using namespace glint;

namespace {

constexpr const char* kUsage =
    "glint-bench: speed against error. Renders the converged reference at the pose of the runs' last frame,\n"
    "then each of --modes with defaults and the parameter sweeps (in the --sweep-modes where the parameter\n"
    "means something), N frames each, and compares each run's last frame with the reference. DIR (default\n"
    "build/bench) gets the CSV, JSON and plot, the reference, each mode's default image, its FLIP map and\n"
    "both reflection terms (*_reflections.png, tonemapped as the \"resolved\" debug view).";

const std::vector<app::Flag> kFlags = {
    {"scene", "plaza (default), hard-cases, city[:OPTIONS], mirror-motion[:lamp=rigid|skinned|morphed], FILE.gltf or FILE.glb"},
    {"frames", "frames per run (default 16)"},
    {"size", "WxH or N; default 256x256 on a CPU device, 1920x1080 on a GPU"},
    {"modes", "the modes run with defaults (default hybrid,ssr,rt)"},
    {"sweep-modes", "the modes the parameter sweeps run in (default hybrid; \"\": no sweeps)"},
    {"sweep", "NAME,...: sweep only these parameters (default: every parameter with a sweep)"},
    {"set", "NAME=VALUE[,NAME=VALUE...]: parameters of every run, the defaults the sweeps start from"},
    {"out-dir", "DIR for everything written (default build/bench)"},
    {"csv", "the CSV (default DIR/<scene>_bench.csv)"},
    {"json", "the JSON (default DIR/<scene>_bench.json)"},
    {"plot", "the time-against-error plot (default DIR/<scene>_bench.png)"},
    {"time", "SECONDS along the camera path of the measured pose"},
    {"ppd", "FLIP's pixels per degree"},
    {"backend", "auto (default), query or pipeline"},
    {"reference-max-frames", "at most this many reference frames"},
    {"warmup-frames", "untimed frames of each configuration before its run (default 60 on a GPU, 0 on a CPU)"},
    {"scale", "N1,N2,...: cost against scene size instead: the city (--scene city:triangles=T,seed=S sets its "
              "other options) at each number of buildings, each with its own reference, every mode with its "
              "defaults; writes DIR/city_scale.{csv,json,png}"},
    {"motion-lamp", "with --motion: how the mirror-motion lamp moves, rigid (default), skinned or morphed"},
    {"time-limit", "SECONDS: start no configuration (with --scale, no city size) after this long; what was measured "
                   "is written, and the JSON's cut_short says the run stopped early (default: no limit). The CSV and "
                   "JSON are rewritten after every configuration, so a run that is killed keeps its rows too"},
};

double parsePositive(const std::string& flag, const std::string& text, bool allowZero) {
    try {
        size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size() && std::isfinite(v) && (v > 0.0 || (allowZero && v == 0.0))) return v;
    } catch (const std::exception&) {
    }
    throw std::runtime_error("--" + flag + " " + text + ": not a " + (allowZero ? "non-negative" : "positive") +
                             " number");
}

// "a,b,,c" -> {"a", "b", "", "c"}: empty items are kept, for the caller to
// refuse by name.
std::vector<std::string> splitList(const std::string& text) {
    std::vector<std::string> items;
    for (size_t start = 0; start <= text.size();) {
        const size_t end = std::min(text.find(',', start), text.size());
        items.push_back(text.substr(start, end - start));
        start = end + 1;
    }
    return items;
}

std::vector<passes::ReflectionMode> parseModes(const std::string& flag, const std::string& text) {
    std::vector<passes::ReflectionMode> modes;
    if (text.empty()) return modes;  // --sweep-modes "": no sweeps
    for (const std::string& item : splitList(text)) {
        try {
            const passes::ReflectionMode m = passes::parseMode(item);
            if (std::find(modes.begin(), modes.end(), m) == modes.end()) modes.push_back(m);
        } catch (const std::invalid_argument& e) {
            throw std::runtime_error("--" + flag + ": " + e.what());
        }
    }
    return modes;
}

// The plot, or a warning where it cannot be drawn (no python3 with
// matplotlib on this machine): the CSV and JSON are the results and are
// already written; scripts/setup installs matplotlib.
void drawPlot(const std::filesystem::path& path, const std::vector<bench::PlotPoint>& points,
              const bench::PlotOptions& options) {
    if (points.empty()) {
        spdlog::warn("no plot: nothing was measured");
        return;
    }
    try {
        bench::writePlot(path, points, options);
        spdlog::info("wrote {}", path.string());
    } catch (const std::runtime_error& e) {
        spdlog::warn("no plot: {}", e.what());
    }
}

// The commit the binary was built from (cmake/write_commit.cmake).
std::string gitCommit() { return GLINT_BUILD_COMMIT; }

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buffer[32];
    std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buffer;
}

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-bench", [&] {
        const auto programStart = std::chrono::steady_clock::now();
        const app::Args args(argc, argv, kUsage, kFlags,
                             {{"quick", "a short run: fewer frames and sweep values (what CI runs)"},
                              {"jitter", "jitter the camera as the measured runs would (default off)"},
                              {"motion", "reflections in motion instead: each configuration along the camera path "
                                         "(--frames, default 64) against references of 4 frames along it, a still "
                                         "camera (flip_still, flicker), and the mirror-motion scene "
                                         "(ghost_energy_1/4/16, lag_px); writes DIR/<scene>_motion.{csv,json,png}"}});
        const std::string sceneName = args.get("scene", "plaza");
        const uint32_t frames = args.getUint("frames", args.has("motion") ? 64 : 16);
        if (frames == 0) throw std::runtime_error("--frames 0: must be at least 1");
        const bool quick = args.has("quick");
        const std::vector<passes::ReflectionMode> modes = parseModes("modes", args.get("modes", "hybrid,ssr,rt"));
        if (modes.empty()) throw std::runtime_error("--modes: name at least one of hybrid, ssr, rt");
        const std::vector<passes::ReflectionMode> sweepModes = parseModes("sweep-modes", args.get("sweep-modes", "hybrid"));
        std::vector<std::string> sweepOnly;
        if (args.has("sweep")) {
            sweepOnly = splitList(args.get("sweep", ""));
            for (const std::string& name : sweepOnly) {
                app::getParameter(app::ReflectionRunOptions{}, name);  // throws naming an unknown parameter
            }
        }
        const double ppd = args.has("ppd") ? parsePositive("ppd", args.get("ppd", ""), false) : metrics::kDefaultPpd;
        const std::filesystem::path outDir = args.get("out-dir", "build/bench");
        const bool scaleRun = args.has("scale");
        const bool motionRun = args.has("motion");
        if (scaleRun && motionRun) throw std::runtime_error("--scale and --motion: choose one");
        if (args.has("motion-lamp") && !motionRun) throw std::runtime_error("--motion-lamp needs --motion");
        const std::string stem =
            scaleRun ? std::string("city") : std::filesystem::path(sceneName).stem().string();
        const std::string suffix = scaleRun ? "_scale" : motionRun ? "_motion" : "_bench";
        const std::filesystem::path csvPath = args.get("csv", (outDir / (stem + suffix + ".csv")).string());
        const std::filesystem::path jsonPath = args.get("json", (outDir / (stem + suffix + ".json")).string());
        const std::filesystem::path plotPath = args.get("plot", (outDir / (stem + suffix + ".png")).string());
        // --time-limit: a wall-clock budget from the start (a lent GPU's
        // time is limited); no configuration starts after it.
        std::optional<std::chrono::steady_clock::time_point> deadline;
        if (args.has("time-limit")) {
            deadline = programStart + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                          std::chrono::duration<double>(
                                              parsePositive("time-limit", args.get("time-limit", ""), false)));
        }
        const auto pastDeadline = [&] { return deadline && std::chrono::steady_clock::now() >= *deadline; };

        // Error is measured against a ray-traced reference, and the modes
        // compared trace rays: a device without ray tracing is refused.
        gpu::ContextOptions contextOptions = args.contextOptions();
        contextOptions.requireRayTracing = true;
        gpu::Context ctx(contextOptions);
        const bool cpuDevice = ctx.caps().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        const auto [width, height] =
            app::parseSize(args.get("size", cpuDevice ? "256x256" : "1920x1080"));
        app::ReflectionRunOptions base;
        base.width = width;
        base.height = height;
        base.frames = frames;
        base.readResolved = true;
        // The reference's still camera has no sub-pixel jitter, and nothing
        // in the frame resolves the jitter of the opaque image (no TAA): a
        // jittered last frame would add up to half a pixel of edge error to
        // every configuration alike and hide the reflections' differences.
        // --jitter measures with it.
        base.jitter = args.has("jitter");
        // As glint-render: 3 s along the plaza's path looks down the plaza past the puddles.
        base.startSeconds =
            float(parsePositive("time", args.get("time", sceneName == "plaza" && !scaleRun ? "3" : "0"), true));
        try {
            base.renderer.backend = passes::parseBackend(args.get("backend", "auto"));
        } catch (const std::invalid_argument& e) {
            throw std::runtime_error(std::string("--backend: ") + e.what());
        }
        app::setParameters(base, args.get("set", ""));
        const float exposure = base.frame.composite.exposure;
        // A CPU device has no GPU clocks to raise (and a warm-up would double
        // its long runs); a GPU gets about a second of load at 1080p.
        const uint32_t warmupFrames = args.getUint("warmup-frames", cpuDevice ? 0 : 60);
        bench::RunInfo info;
        info.device = ctx.caps().deviceName;
        info.deviceType = gpu::deviceTypeName(ctx.caps().deviceType);
        info.driver = ctx.caps().driverName + " " + ctx.caps().driverInfo;
        info.date = utcNow();
        info.commit = gitCommit();
        info.scene = stem;
        info.width = width;
        info.height = height;
        info.frames = frames;
        info.startSeconds = base.startSeconds;
        info.jitter = base.jitter;
        info.warmupFrames = warmupFrames;
        info.ppd = ppd;
        info.relMseEpsilon = metrics::kRelMseEpsilon;
        // GPU timestamps on lavapipe miss compute dispatches: there each pass
        // is submitted alone and timed on the host (rg::PassTimer::HostSerial).
        info.timeAxis = "reflection_ms";
        info.passTimer = cpuDevice ? "host_serial" : "gpu_timestamps";
        info.set = args.get("set", "");
        info.referenceTolerance = app::ReferenceOptions{}.tolerance;
        std::optional<uint32_t> referenceMaxFrames;
        if (args.has("reference-max-frames")) referenceMaxFrames = args.getUint("reference-max-frames", 0);

        if (scaleRun) {
            // The city at each size, every mode with its defaults (--scene
            // city:triangles=T,seed=S sets the rest of the city).
            bench::ScaleSettings scale;
            scale.instances = bench::parseScale(args.get("scale", ""));
            if (sceneName.substr(0, 4) == "city") scale.city = scene::parseCityOptions(sceneName);
            scale.base = base;
            scale.modes = modes;
            scale.warmupFrames = warmupFrames;
            scale.ppd = ppd;
            scale.referenceMaxFrames = referenceMaxFrames;
            scale.deadline = deadline;
            info.configurationsPlanned = uint32_t(scale.instances.size() * modes.size());
            // The CSV and JSON after every row: a run stopped early keeps them.
            const auto writeScale = [&](std::span<const bench::ScaleRow> rows) {
                info.cutShort = rows.size() < info.configurationsPlanned;
                bench::writeText(csvPath, bench::toScaleCsv(rows));
                bench::writeText(jsonPath, bench::toScaleJson(info, rows));
            };
            scale.onRow = writeScale;
            spdlog::info("scale: the city at {} sizes, {}x{}, {} frames from {} s, on {} ({})", scale.instances.size(),
                         width, height, frames, base.startSeconds, info.device, info.deviceType);
            const std::vector<bench::ScaleRow> rows = bench::runScale(ctx, scale);
            writeScale(rows);
            std::fputs(bench::toScaleCsv(rows).c_str(), stdout);
            std::fflush(stdout);
            spdlog::info("wrote {}", csvPath.string());
            spdlog::info("wrote {}", jsonPath.string());
            bench::PlotOptions plot;
            plot.title = "city " + std::to_string(width) + "x" + std::to_string(height) + ", " + info.device + ", " +
                         info.date.substr(0, 10);
            plot.xLabel = "instanced triangles";
            plot.yLabel = cpuDevice ? "reflection_ms (host time of the reflection passes, each submitted alone)"
                                    : "reflection_ms (GPU time of the reflection passes, median)";
            plot.logX = true;
            plot.seriesLines = true;
            plot.paretoFront = false;
            drawPlot(plotPath, bench::scalePlotPoints(rows), plot);
            ctx.waitIdle();
            return app::validationClean(ctx) ? 0 : 2;
        }
        scene::Scene scene = scene::loadScene(sceneName, args.gltfOptions());

        // Every configuration, so progress can say "k of n".
        std::vector<bench::Configuration> configurations;
        for (const passes::ReflectionMode mode : modes) configurations.push_back({mode, std::string(bench::kDefaultParam)});
        // The sweeps come with the parameters (app::Parameter): values equal
        // to the default are skipped, the mode's default row has them.
        for (const app::Parameter& sweep : app::parameters()) {
            for (const passes::ReflectionMode mode : modes) {
                if (!sweep.sweepModes[size_t(mode)]) continue;
                if (!sweepOnly.empty() &&
                    std::find(sweepOnly.begin(), sweepOnly.end(), std::string(sweep.name)) == sweepOnly.end()) {
                    continue;
                }
                if (std::find(sweepModes.begin(), sweepModes.end(), mode) == sweepModes.end()) continue;
                const double defaultValue = app::getParameter(base, sweep.name);
                for (const double v : quick ? sweep.quickSweep : sweep.sweep) {
                    if (float(v) == float(defaultValue)) continue;
                    configurations.push_back({mode, std::string(sweep.name), v});
                }
            }
        }
        info.configurationsPlanned = uint32_t(configurations.size());
        spdlog::info("{}: {}x{}, {} frames from {} s, {} configurations on {} ({})", scene.name, width, height,
                     frames, base.startSeconds, configurations.size(), ctx.caps().deviceName,
                     gpu::deviceTypeName(ctx.caps().deviceType));
        const auto benchStart = std::chrono::steady_clock::now();
        const auto elapsed = [&] {
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - benchStart).count();
        };
        // --time-limit: true (and says so) once no further configuration may start.
        const auto timeIsUp = [&](size_t measured) {
            if (!pastDeadline()) return false;
            spdlog::warn("the time limit passed after {} of {} configurations ({:.0f} s); the rest are not measured",
                         measured, configurations.size(), elapsed());
            return true;
        };

        if (motionRun) {
            bench::MotionSettings motion;
            motion.base = base;
            motion.pathFrames = frames;
            motion.ppd = ppd;
            motion.referenceMaxFrames = referenceMaxFrames;
            motion.warmupFrames = warmupFrames;
            const std::string lamp = args.get("motion-lamp", "rigid");
            motion.mirrorLamp = scene::parseMirrorMotionLamp("mirror-motion:lamp=" + lamp);
            info.mirrorLamp = lamp;
            if (quick) {
                motion.stillFrames = 12;
                motion.flickerFrames = 4;
            }
            const bench::MotionReferences references = bench::renderMotionReferences(ctx, scene, motion);
            spdlog::info("motion: references of {} path frames and the mirror-motion scene in {:.1f} s",
                         references.pathFrames.size(), elapsed());
            std::vector<bench::MotionRow> rows;
            const auto writeMotion = [&] {
                info.cutShort = rows.size() < configurations.size();
                bench::writeText(csvPath, bench::toMotionCsv(rows));
                bench::writeText(jsonPath, bench::toMotionJson(info, rows));
            };
            for (size_t k = 0; k < configurations.size(); ++k) {
                if (timeIsUp(k)) break;
                const bench::Configuration& c = configurations[k];
                const app::ReflectionRunOptions options = bench::configure(base, c);
                bench::MotionRow row = bench::measureMotion(ctx, scene, motion, options, references);
                row.scene = stem;
                row.mode = passes::modeName(c.mode);
                row.param = c.param;
                if (c.param != bench::kDefaultParam) row.value = app::getParameter(options, c.param);
                spdlog::info("[{}/{}] {}: reflections {:.3f} ms, FLIP still {:.4f}, in motion {:.4f}, ghost "
                             "{:.3f}/{:.3f}/{:.3f}, lag {:.2f} px, flicker {:.5f} ({:.0f} s)",
                             k + 1, configurations.size(), bench::describe(c), row.reflectionMs.value_or(0.0),
                             row.flipStill, row.flipMotion, row.ghostEnergy[0], row.ghostEnergy[1],
                             row.ghostEnergy[2], row.lagPixels, row.flicker, elapsed());
                rows.push_back(std::move(row));
                writeMotion();
            }
            writeMotion();
            std::fputs(bench::toMotionCsv(rows).c_str(), stdout);
            std::fflush(stdout);
            spdlog::info("wrote {}", csvPath.string());
            spdlog::info("wrote {}", jsonPath.string());
            bench::PlotOptions plot;
            plot.title = stem + " in motion " + std::to_string(width) + "x" + std::to_string(height) + ", " +
                         std::to_string(frames) + " frames, " + info.device + ", " + info.date.substr(0, 10);
            plot.xLabel = cpuDevice ? "reflection_ms (host time of the reflection passes, each submitted alone)"
                                    : "reflection_ms (GPU time of the reflection passes, median)";
            plot.yLabel = "flip_motion (reflection term against per-frame references, mean)";
            drawPlot(plotPath, bench::motionPlotPoints(rows), plot);
            spdlog::info("{:.0f} s in all", elapsed());
            ctx.waitIdle();
            return app::validationClean(ctx) ? 0 : 2;
        }

        // 1. The reference at the last measured frame's pose and scene time.
        const bench::Reference reference = bench::renderReference(ctx, scene, base, referenceMaxFrames);
        const metrics::Image& referenceImage = reference.image;
        const bench::ReflectionTerm& referenceTerm = reference.term;
        app::writePng((outDir / (stem + "_reference.png")).string(), width, height, reference.result.rgba);
        app::writePng((outDir / (stem + "_reference_reflections.png")).string(), width, height,
                      bench::toSrgb8(referenceTerm.display));
        spdlog::info("reference: {} frames ({}) in {:.1f} s", reference.result.framesRun,
                     reference.result.converged ? "converged" : "frame limit", elapsed());
        info.referenceFrames = reference.result.framesRun;
        info.referenceConverged = reference.result.converged;
        info.referenceLastChange = reference.result.lastChange;

        // 2. Every configuration over the same path.
        std::vector<bench::Row> rows;
        const auto writeStill = [&] {
            info.cutShort = rows.size() < configurations.size();
            bench::writeText(csvPath, bench::toCsv(rows));
            bench::writeText(jsonPath, bench::toJson(info, rows));
        };
        for (size_t k = 0; k < configurations.size(); ++k) {
            if (timeIsUp(k)) break;
            const bench::Configuration& c = configurations[k];
            const app::ReflectionRunOptions options = bench::configure(base, c);
            const bool baseline = c.param == bench::kDefaultParam;
            const std::string modeName(passes::modeName(c.mode));
            const std::string what = bench::describe(c);

            const app::ReflectionRunResult result = bench::runMeasured(ctx, scene, options, warmupFrames);
            const metrics::Image image = metrics::imageFromSrgb8(width, height, result.rgba, 4, what);
            const bench::ReflectionTerm term = bench::reflectionTerm(result.resolved, width, height, exposure, what);

            bench::Row row;
            row.scene = stem;
            row.mode = modeName;
            row.param = c.param;
            if (!baseline) row.value = app::getParameter(options, c.param);
            row.width = width;
            row.height = height;
            row.reflectionMs = result.reflectionMs;
            row.reflectionMeanMs = result.reflectionMeanMs;
            row.reflectionSpanMs = result.reflectionSpanMs;
            row.reflectionSpanMeanMs = result.reflectionSpanMeanMs;
            row.totalMs = result.totalMs;
            row.frameWallMs = result.frameWallMs;
            row.sslrRays = result.sslrRays;
            row.rtRays = result.rtRays;
            row.screenSpaceIdleFrames = result.screenSpaceIdleFrames;
            row.image = bench::measure(referenceImage, image, ppd);
            row.reflection =
                bench::measure(referenceTerm.display, term.display, ppd, &referenceTerm.radiance, &term.radiance);
            rows.push_back(row);
            writeStill();
            if (baseline) {
                app::writePng((outDir / (stem + "_" + modeName + ".png")).string(), width, height, result.rgba);
                app::writePng((outDir / (stem + "_" + modeName + "_reflections.png")).string(), width, height,
                              bench::toSrgb8(term.display));
                const metrics::FlipResult f = metrics::flip(referenceImage, image, ppd);
                metrics::writeErrorMap(outDir / (stem + "_" + modeName + "_flip.png"), f.errorMap, width, height);
            }
            spdlog::info("[{}/{}] {}: reflections {:.3f} ms GPU, frame {:.2f} ms wall, {} RT rays, FLIP {:.4f} "
                         "(reflections {:.4f}) ({:.0f} s)",
                         k + 1, configurations.size(), what, result.reflectionMs.value_or(0.0),
                         result.frameWallMs.value_or(0.0), result.rtRays, row.image.flipMean,
                         row.reflection.flipMean, elapsed());
        }

        // 3. The report.
        std::fputs(bench::toTable(rows).c_str(), stdout);
        std::fflush(stdout);

        writeStill();
        spdlog::info("wrote {}", csvPath.string());
        spdlog::info("wrote {}", jsonPath.string());
        bench::PlotOptions plot;
        plot.title = stem + " " + std::to_string(width) + "x" + std::to_string(height) + ", " + std::to_string(frames) +
                     " frames, " + info.device + ", " + info.date.substr(0, 10);
        plot.xLabel = cpuDevice ? "reflection_ms (host time of the reflection passes, each submitted alone, median)"
                                : "reflection_ms (GPU time of the reflection passes, median)";
        plot.yLabel = "FLIP mean against the reference (final image)";
        drawPlot(plotPath, bench::plotPoints(rows, false), plot);
        spdlog::info("{:.0f} s in all", elapsed());

        ctx.waitIdle();
        return app::validationClean(ctx) ? 0 : 2;
    });
}
