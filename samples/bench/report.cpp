#include "bench/report.h"

#include "plot_script.h"

#include <nlohmann/json.hpp>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>

namespace glint::bench {

namespace {

std::string printf1(const char* format, double v) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, v);
    return buffer;
}

std::string number(const std::optional<double>& v, const char* format = "%.6g") {
    if (!v) return "";
    if (std::isinf(*v)) return *v > 0 ? "inf" : "-inf";
    if (std::isnan(*v)) return "nan";
    return printf1(format, *v);
}

// Keys in the CSV's order, provenance first: easier to read than sorted.
using Json = nlohmann::ordered_json;

Json jsonNumber(const std::optional<double>& v) {
    return v && std::isfinite(*v) ? Json(*v) : Json(nullptr);
}

Json jsonMetrics(const ErrorMetrics& m) {
    return {{"flip_mean", jsonNumber(m.flipMean)},
            {"relmse", jsonNumber(m.relMse)},
            {"psnr", jsonNumber(m.psnr)},
            {"ssim", jsonNumber(m.ssim)}};
}

} // namespace

// ---- Text outputs ----------------------------------------------------------

std::string formatValue(const std::optional<double>& value) {
    if (!value) return "";
    // Whole numbers as such ("10", not "1e+01"): step counts, radii.
    if (std::abs(*value) < 1e15 && *value == std::floor(*value)) return printf1("%.0f", *value);
    // Parameters are stored as floats (or small integers): the shortest
    // text that reads back as the same float keeps "0.9" from becoming
    // "0.899999976".
    for (int precision = 1; precision <= 17; ++precision) {
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, "%.*g", precision, *value);
        if (float(std::strtod(buffer, nullptr)) == float(*value)) return buffer;
    }
    return printf1("%.17g", *value);
}

std::string toCsv(std::span<const Row> rows) {
    std::string out(kCsvHeader);
    out += '\n';
    for (const Row& r : rows) {
        // Scene names come from file stems; a comma would shift every column.
        std::string scene = r.scene;
        std::replace(scene.begin(), scene.end(), ',', '_');
        out += scene + ',' + r.mode + ',' + r.param + ',' + formatValue(r.value) + ',' + std::to_string(r.width) +
               ',' + std::to_string(r.height) + ',' + number(r.reflectionMs) + ',' + number(r.totalMs) + ',' +
               std::to_string(r.rtRays) + ',' + number(r.image.flipMean) + ',' + number(r.image.relMse) + ',' +
               number(r.image.psnr) + ',' + number(r.image.ssim) + ',' + number(r.reflectionMeanMs) + ',' +
               number(r.reflectionSpanMs) + ',' + std::to_string(r.screenSpaceIdleFrames) + '\n';
    }
    return out;
}

std::string toJson(const RunInfo& info, std::span<const Row> rows) {
    Json j;
    j["device"] = info.device;
    j["device_type"] = info.deviceType;
    j["driver"] = info.driver;
    j["date"] = info.date;
    j["commit"] = info.commit;
    j["scene"] = info.scene;
    j["size"] = {info.width, info.height};
    j["frames"] = info.frames;
    j["start_seconds"] = info.startSeconds;
    j["jitter"] = info.jitter;
    j["warmup_frames"] = info.warmupFrames;
    j["flip_ppd"] = info.ppd;
    j["relmse_epsilon"] = info.relMseEpsilon;
    j["time_axis"] = info.timeAxis;
    j["pass_timer"] = info.passTimer;
    j["set"] = info.set;
    j["configurations_planned"] = info.configurationsPlanned;
    j["cut_short"] = info.cutShort;
    j["reference"] = {{"frames", info.referenceFrames},
                      {"converged", info.referenceConverged},
                      {"last_change", info.referenceLastChange},
                      {"tolerance", info.referenceTolerance}};
    Json list = Json::array();
    for (const Row& r : rows) {
        Json row;
        row["scene"] = r.scene;
        row["mode"] = r.mode;
        row["param"] = r.param;
        row["value"] = jsonNumber(r.value);
        row["width"] = r.width;
        row["height"] = r.height;
        row["reflection_ms"] = jsonNumber(r.reflectionMs);
        row["reflection_mean_ms"] = jsonNumber(r.reflectionMeanMs);
        row["reflection_span_ms"] = jsonNumber(r.reflectionSpanMs);
        row["reflection_span_mean_ms"] = jsonNumber(r.reflectionSpanMeanMs);
        row["total_ms"] = jsonNumber(r.totalMs);
        row["frame_wall_ms"] = jsonNumber(r.frameWallMs);
        row["rt_rays"] = r.rtRays;
        row["sslr_rays"] = r.sslrRays;
        row["screen_space_idle_frames"] = r.screenSpaceIdleFrames;
        row["flip_mean"] = jsonNumber(r.image.flipMean);
        row["relmse"] = jsonNumber(r.image.relMse);
        row["psnr"] = jsonNumber(r.image.psnr);
        row["ssim"] = jsonNumber(r.image.ssim);
        row["reflection"] = jsonMetrics(r.reflection);
        list.push_back(row);
    }
    j["rows"] = list;
    return j.dump(2) + "\n";
}

std::string toTable(std::span<const Row> rows) {
    char line[512];
    std::string out;
    const char* header = "%-7s %-17s %8s %9s %9s %9s %9s %8s | %7s %8s %6s %6s | %7s %8s %6s %6s\n";
    std::snprintf(line, sizeof line, header, "mode", "param", "value", "refl_ms", "span_ms", "total_ms", "wall_ms",
                  "rt_rays",
                  "flip", "relmse", "psnr", "ssim", "r.flip", "r.relmse", "r.psnr", "r.ssim");
    out += line;
    out += std::string(std::strlen(line) - 1, '-') + '\n';
    for (const Row& r : rows) {
        const auto cell = [](const std::optional<double>& v) { return v ? number(v, "%.3f") : std::string("-"); };
        std::snprintf(line, sizeof line,
                      "%-7s %-17s %8s %9s %9s %9s %9s %8llu | %7.4f %8.4f %6.2f %6.4f | %7.4f %8.4f %6.2f %6.4f\n",
                      r.mode.c_str(), r.param.c_str(), r.value ? formatValue(r.value).c_str() : "-",
                      cell(r.reflectionMs).c_str(), cell(r.reflectionSpanMs).c_str(), cell(r.totalMs).c_str(),
                      cell(r.frameWallMs).c_str(),
                      static_cast<unsigned long long>(r.rtRays), r.image.flipMean, r.image.relMse, r.image.psnr,
                      r.image.ssim, r.reflection.flipMean, r.reflection.relMse, r.reflection.psnr, r.reflection.ssim);
        out += line;
    }
    out += "flip/relmse/psnr/ssim: final image; r.*: the resolved reflection term; both against the reference\n";
    return out;
}

void writeText(const std::filesystem::path& path, std::string_view text) {
    if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
    std::ofstream file(path, std::ios::binary);
    file.write(text.data(), std::streamsize(text.size()));
    if (!file) throw std::runtime_error("cannot write '" + path.string() + "'");
}

// ---- Pareto front ----------------------------------------------------------

std::vector<size_t> paretoFront(std::span<const Point> points) {
    std::vector<size_t> order;
    for (size_t i = 0; i < points.size(); ++i) {
        if (std::isfinite(points[i].x) && std::isfinite(points[i].y)) order.push_back(i);
    }
    // Sweep in increasing cost (ties: lower error first, then input order);
    // a point is on the front when its error is below every cheaper one's.
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (points[a].x != points[b].x) return points[a].x < points[b].x;
        return points[a].y < points[b].y;
    });
    std::vector<size_t> front;
    double bestError = std::numeric_limits<double>::infinity();
    for (const size_t i : order) {
        if (points[i].y < bestError) {
            front.push_back(i);
            bestError = points[i].y;
        }
    }
    return front;
}

// ---- Plot ------------------------------------------------------------------

std::string toScaleCsv(std::span<const ScaleRow> rows) {
    std::string out(kScaleCsvHeader);
    out += '\n';
    for (const ScaleRow& r : rows) {
        std::string scene = r.scene;
        std::replace(scene.begin(), scene.end(), ',', '_');
        out += scene + ',' + r.mode + ',' + std::to_string(r.instances) + ',' + std::to_string(r.triangles) + ',' +
               std::to_string(r.width) + ',' + std::to_string(r.height) + ',' + number(r.reflectionMs) + ',' +
               number(r.reflectionSpanMs) + ',' + number(r.totalMs) + ',' + std::to_string(r.rtRays) + ',' +
               std::to_string(r.sslrRays) + ',' + number(r.flipMean) + ',' + number(r.reflectionMeanMs) + ',' +
               number(r.reflectionSpanMeanMs) + '\n';
    }
    return out;
}

std::string toScaleJson(const RunInfo& info, std::span<const ScaleRow> rows) {
    Json j = Json::parse(toJson(info, {}));
    j.erase("rows");
    j.erase("scene");
    Json list = Json::array();
    for (const ScaleRow& r : rows) {
        Json passes = Json::object();
        for (const auto& [name, ms] : r.passes) passes[name] = ms;
        const auto optional = [](const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); };
        list.push_back({{"scene", r.scene},
                        {"mode", r.mode},
                        {"instances", r.instances},
                        {"triangles", r.triangles},
                        {"width", r.width},
                        {"height", r.height},
                        {"reflection_ms", optional(r.reflectionMs)},
                        {"reflection_span_ms", optional(r.reflectionSpanMs)},
                        {"reflection_mean_ms", optional(r.reflectionMeanMs)},
                        {"reflection_span_mean_ms", optional(r.reflectionSpanMeanMs)},
                        {"total_ms", optional(r.totalMs)},
                        {"rt_rays", r.rtRays},
                        {"sslr_rays", r.sslrRays},
                        {"flip_mean", std::isfinite(r.flipMean) ? Json(r.flipMean) : Json(nullptr)},
                        {"passes", passes},
                        {"draws", r.draws},
                        {"triangles_drawn", r.trianglesDrawn},
                        {"instances_occluded", r.instancesOccluded},
                        {"tlas_instances", r.tlasInstances},
                        {"reference_frames", r.referenceFrames}});
    }
    j["rows"] = list;
    return j.dump(2) + "\n";
}

std::string toMotionCsv(std::span<const MotionRow> rows) {
    std::string out(kMotionCsvHeader);
    out += '\n';
    for (const MotionRow& r : rows) {
        std::string scene = r.scene;
        std::replace(scene.begin(), scene.end(), ',', '_');
        out += scene + ',' + r.mode + ',' + r.param + ',' + formatValue(r.value) + ',' + std::to_string(r.width) + ',' +
               std::to_string(r.height) + ',' + number(r.reflectionMs) + ',' + number(r.flipStill) + ',' +
               number(r.flipMotion);
        for (const double g : r.ghostEnergy) out += ',' + number(g);
        out += ',' + number(r.lagPixels) + ',' + number(r.flicker);
        for (const double b : r.flipBand) out += ',' + number(b);
        out += '\n';
    }
    return out;
}

std::string toMotionJson(const RunInfo& info, std::span<const MotionRow> rows) {
    Json j = Json::parse(toJson(info, {}));
    j.erase("rows");
    j["mirror_lamp"] = info.mirrorLamp.empty() ? "rigid" : info.mirrorLamp;
    Json list = Json::array();
    for (const MotionRow& r : rows) {
        Json row = {{"scene", r.scene},
                    {"mode", r.mode},
                    {"param", r.param},
                    {"value", jsonNumber(r.value)},
                    {"width", r.width},
                    {"height", r.height},
                    {"reflection_ms", jsonNumber(r.reflectionMs)},
                    {"flip_still", jsonNumber(r.flipStill)},
                    {"flip_motion", jsonNumber(r.flipMotion)}};
        const std::array<const char*, 3> ghost = {"ghost_energy_1", "ghost_energy_4", "ghost_energy_16"};
        for (size_t k = 0; k < ghost.size(); ++k) row[ghost[k]] = jsonNumber(r.ghostEnergy[k]);
        row["lag_px"] = jsonNumber(r.lagPixels);
        row["flicker"] = jsonNumber(r.flicker);
        const std::array<const char*, 4> bands = {"flip_mirror", "flip_glossy", "flip_rough", "flip_very_rough"};
        for (size_t k = 0; k < bands.size(); ++k) row[bands[k]] = jsonNumber(r.flipBand[k]);
        Json perFrame = Json::array();
        for (const double f : r.flipPerFrame) perFrame.push_back(jsonNumber(f));
        row["flip_per_frame"] = perFrame;
        list.push_back(row);
    }
    j["rows"] = list;
    return j.dump(2) + "\n";
}

std::vector<PlotPoint> motionPlotPoints(std::span<const MotionRow> rows) {
    std::vector<PlotPoint> points;
    for (const MotionRow& r : rows) {
        if (!r.reflectionMs) continue;
        PlotPoint p;
        p.at = {*r.reflectionMs, r.flipMotion};
        p.series = r.mode;
        p.baseline = r.param == kDefaultParam;
        p.label = p.baseline ? r.mode : r.param + "=" + formatValue(r.value);
        points.push_back(p);
    }
    return points;
}

std::vector<PlotPoint> scalePlotPoints(std::span<const ScaleRow> rows) {
    std::vector<PlotPoint> points;
    for (const ScaleRow& r : rows) {
        if (!r.reflectionMs || r.triangles == 0) continue;
        PlotPoint p;
        p.at = {double(r.triangles), *r.reflectionMs};
        p.series = r.mode;
        p.label = r.mode;
        points.push_back(p);
    }
    return points;
}

std::vector<PlotPoint> plotPoints(std::span<const Row> rows, bool wallTime) {
    std::vector<PlotPoint> points;
    for (const Row& r : rows) {
        const std::optional<double>& time = wallTime ? r.frameWallMs : r.reflectionMs;
        if (!time) continue;
        PlotPoint p;
        p.at = {*time, r.image.flipMean};
        p.series = r.mode;
        p.baseline = r.param == kDefaultParam;
        p.label = p.baseline ? r.mode : r.param + "=" + formatValue(r.value);
        points.push_back(p);
    }
    return points;
}

std::string plotJson(std::span<const PlotPoint> points, const PlotOptions& options) {
    // The front is glint-bench's (paretoFront), not the script's.
    std::vector<PlotPoint> finite;
    for (const PlotPoint& p : points) {
        if (std::isfinite(p.at.x) && std::isfinite(p.at.y) && (!options.logX || p.at.x > 0.0)) finite.push_back(p);
    }
    std::vector<Point> at;
    for (const PlotPoint& p : finite) at.push_back(p.at);
    std::vector<bool> onFront(finite.size(), false);
    if (options.paretoFront) {
        for (const size_t i : paretoFront(at)) onFront[i] = true;
    }
    Json list = Json::array();
    for (size_t i = 0; i < finite.size(); ++i) {
        const PlotPoint& p = finite[i];
        list.push_back({{"x", p.at.x}, {"y", p.at.y}, {"series", p.series}, {"label", p.label},
                        {"baseline", p.baseline}, {"front", bool(onFront[i])}});
    }
    const Json plot = {{"width", options.width},   {"height", options.height},
                       {"title", options.title},   {"xLabel", options.xLabel},
                       {"yLabel", options.yLabel}, {"logX", options.logX},
                       {"seriesLines", options.seriesLines}, {"paretoFront", options.paretoFront},
                       {"points", list}};
    return plot.dump(2) + "\n";
}

void writePlot(const std::filesystem::path& path, std::span<const PlotPoint> points, const PlotOptions& options) {
    if (options.width < 64 || options.height < 64) {
        throw std::runtime_error("plot '" + path.string() + "': " + std::to_string(options.width) + "x" +
                                 std::to_string(options.height) + " is smaller than 64x64");
    }
    std::filesystem::path stem = path;
    stem.replace_extension();
    const std::filesystem::path json = stem.string() + ".plot.json";
    const std::filesystem::path script = stem.string() + ".plot.py";
    std::filesystem::path svg = path;
    svg.replace_extension(".svg");
    writeText(json, plotJson(points, options));
    writeText(script, kPlotScript);

    const char* chosen = std::getenv("GLINT_PYTHON");
    const std::string python = chosen != nullptr && *chosen ? chosen : GLINT_PLOT_PYTHON;
    std::vector<std::string> words = {python, script.string(), json.string(), path.string(), svg.string()};
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawnp(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
        throw std::runtime_error("plot '" + path.string() + "': cannot run " + python +
                                 " (scripts/setup installs python3 and python3-matplotlib; GLINT_PYTHON picks another)");
    }
    int status = 0;
    if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        throw std::runtime_error("plot '" + path.string() + "': " + python + " " + script.string() +
                                 " failed (matplotlib missing? scripts/setup installs python3-matplotlib)");
    }
}

} // namespace glint::bench
