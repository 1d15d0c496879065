#pragma once
// glint-bench's report: the rows it measures, the table, CSV and
// JSON it writes, the Pareto front of time against error, and the plot
// (drawn by matplotlib). Pure CPU code with no Vulkan, so the tests check
// the schema and the plot without a device.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace glint::bench {

// The CSV header, column for column (docs/results/ keeps such files). The metric columns
// are the final image's; the reflection term's go to the JSON only.
inline constexpr std::string_view kCsvHeader =
    "scene,mode,param,value,width,height,reflection_ms,total_ms,rt_rays,flip_mean,relmse,psnr,ssim,reflection_mean_ms,"
    "reflection_span_ms,screen_space_idle_frames";

// The baseline row of each mode has this as its param (and no value).
inline constexpr std::string_view kDefaultParam = "default";

// One image against the reference (glint/metrics).
struct ErrorMetrics {
    double flipMean = 0.0;  // LDR-FLIP mean at the run's pixels per degree
    double relMse = 0.0;    // epsilon metrics::kRelMseEpsilon
    double psnr = 0.0;      // dB; +inf for identical images
    double ssim = 0.0;
};

// One configuration: a mode with defaults, or one parameter changed.
struct Row {
    std::string scene;
    std::string mode;                  // hybrid, ssr, rt
    std::string param{kDefaultParam};  // a parameter name (app::parameters()) or "default"
    std::optional<double> value;       // the parameter's value; none on default rows
    uint32_t width = 0;
    uint32_t height = 0;
    std::optional<double> reflectionMs;  // median GPU time of the reflection passes
    // Their mean: work done on some frames only (the hybrid's SSLR probe
    // frames, passes/feedback.h) counts here and not in the median.
    std::optional<double> reflectionMeanMs;
    // The same chain timed as one span (no per-pass timestamps), median and
    // mean over the other half of the frames.
    std::optional<double> reflectionSpanMs;
    std::optional<double> reflectionSpanMeanMs;
    std::optional<double> totalMs;       // median GPU time of all passes
    std::optional<double> frameWallMs;   // median host time of a frame (a CPU device's real cost)
    uint64_t sslrRays = 0;               // last frame
    uint64_t rtRays = 0;                 // last frame
    // Hybrid frames rendered as rt because SSLR did not pay
    // (passes::FeedbackSettings::hostGate), of the run's frames.
    uint32_t screenSpaceIdleFrames = 0;
    ErrorMetrics image;       // the final image against the reference's
    ErrorMetrics reflection;  // the resolved reflection term against the reference's
};

// What the JSON says about the run as a whole.
struct RunInfo {
    std::string device;
    std::string deviceType;  // "cpu", "discrete-gpu", ...
    std::string driver;
    std::string date;    // ISO 8601, UTC
    std::string commit;  // "unknown" when neither git nor the build knew it
    std::string scene;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t frames = 0;
    double startSeconds = 0.0;
    bool jitter = false;  // sub-pixel jitter in the measured runs (the reference has none)
    uint32_t warmupFrames = 0;  // untimed frames before each measured run
    double ppd = 0.0;
    double relMseEpsilon = 0.0;
    std::string timeAxis;       // "reflection_ms" or "frame_wall_ms": what the plot's x is
    // How pass times were taken: "gpu_timestamps", or "host_serial" (each
    // pass submitted alone and timed on the host: CPU devices).
    std::string passTimer = "gpu_timestamps";
    // --set: the parameters every run (the references' own settings aside)
    // started from, "NAME=VALUE,..."; empty: Glint's defaults.
    std::string set;
    // --motion: how the mirror-motion lamp moved (rigid, skinned, morphed).
    std::string mirrorLamp;
    // The configurations (for --scale, sizes times modes) the run set out
    // to measure, and whether --time-limit stopped it before the last: the
    // rows then hold those measured in time.
    uint32_t configurationsPlanned = 0;
    bool cutShort = false;
    uint32_t referenceFrames = 0;
    bool referenceConverged = false;
    double referenceLastChange = 0.0;
    double referenceTolerance = 0.0;
};

// ---- Text outputs ----------------------------------------------------------

// The value column: shortest text that reads back as the same float
// setParameter stores ("0.9", "64"); empty on default rows.
std::string formatValue(const std::optional<double>& value);

// kCsvHeader, then one line per row. Missing times are empty cells; PSNR of
// identical images is "inf" (std::stod reads both back).
std::string toCsv(std::span<const Row> rows);

// {info..., "rows": [every CSV column + frame_wall_ms, sslr_rays and
// "reflection": {flip_mean, relmse, psnr, ssim}]}; missing or infinite
// numbers are null (JSON has no infinity).
std::string toJson(const RunInfo& info, std::span<const Row> rows);

// A fixed-width table for stdout: every row, times and both error sets.
std::string toTable(std::span<const Row> rows);

// ---- Pareto front ----------------------------------------------------------

struct Point {
    double x = 0.0;  // cost (time)
    double y = 0.0;  // error
};

// Indices of the non-dominated points when both coordinates are minimised
// (no other point is at most as large in both and smaller in one), in
// increasing x. Points with a non-finite coordinate take no part; of equal
// points only the first is kept.
std::vector<size_t> paretoFront(std::span<const Point> points);

// ---- Plot ------------------------------------------------------------------

struct PlotPoint {
    Point at;
    std::string series;  // the legend entry (a mode)
    std::string label;   // shown beside points on the front ("sslr_steps=32")
    bool baseline = false;  // drawn larger: a mode's default settings
};

struct PlotOptions {
    uint32_t width = 960;
    uint32_t height = 640;
    std::string title;
    std::string xLabel;
    std::string yLabel;
    // A logarithmic x axis (ticks at powers of ten; x must be positive).
    bool logX = false;
    // Each series' points joined in increasing x (a quantity against size).
    bool seriesLines = false;
    // The Pareto front of time against error, marked and labelled.
    bool paretoFront = true;
};

// Rows as plot points: x is frame_wall_ms when `wallTime`, else
// reflection_ms; y is the final image's FLIP mean. Rows without that time
// are left out.
std::vector<PlotPoint> plotPoints(std::span<const Row> rows, bool wallTime);

// What the plot script reads: the options and the points with finite
// coordinates (positive x on a log axis), each marked whether it is on the
// Pareto front (paretoFront) when options.paretoFront.
std::string plotJson(std::span<const PlotPoint> points, const PlotOptions& options);

// The plot drawn by matplotlib: points coloured by series (defaults as
// diamonds), the Pareto front as a dashed line with its points labelled,
// axes, grid and legend; a PNG of options.width x options.height pixels at
// `path` and an SVG beside it. The points (<stem>.plot.json) and the script
// (<stem>.plot.py, samples/bench/plot.py) are left beside them, so the plot
// can be redrawn with python3 alone. Throws std::runtime_error naming the
// file when python3 or matplotlib is missing or fails.
void writePlot(const std::filesystem::path& path, std::span<const PlotPoint> points, const PlotOptions& options);

// ---- Cost against scene size (glint-bench --scale) --------------------------

// The CSV header of the scale run, column for column.
inline constexpr std::string_view kScaleCsvHeader =
    "scene,mode,instances,triangles,width,height,reflection_ms,reflection_span_ms,total_ms,rt_rays,sslr_rays,"
    "flip_mean,reflection_mean_ms,reflection_span_mean_ms";

// One mode at one size of the city.
struct ScaleRow {
    std::string scene;
    std::string mode;
    uint32_t instances = 0;   // buildings (scene::CityOptions::instances)
    uint64_t triangles = 0;   // instanced triangles drawn at LOD 0 (scene::instancedTriangleCount)
    uint32_t width = 0;
    uint32_t height = 0;
    std::optional<double> reflectionMs;      // median sum of the reflection passes' times
    std::optional<double> reflectionSpanMs;  // median of the chain timed as one span
    std::optional<double> reflectionMeanMs;      // means of both (Row::reflectionMeanMs)
    std::optional<double> reflectionSpanMeanMs;
    std::optional<double> totalMs;
    uint64_t rtRays = 0;
    uint64_t sslrRays = 0;
    double flipMean = 0.0;  // the final image against this size's own reference
    // JSON only: per-pass times (median, ms) and the raster work culling left.
    std::vector<std::pair<std::string, double>> passes;
    uint32_t draws = 0;
    // Triangles the G-buffer drew (with occlusion culling: what the GPU's
    // cull left), and the instances in the frustum it found hidden.
    uint64_t trianglesDrawn = 0;
    uint32_t instancesOccluded = 0;
    uint32_t tlasInstances = 0;
    uint32_t referenceFrames = 0;
};

std::string toScaleCsv(std::span<const ScaleRow> rows);
// {info..., "rows": [every CSV column, "passes": {name: ms}, draws, ...]}.
std::string toScaleJson(const RunInfo& info, std::span<const ScaleRow> rows);

// x = instanced triangles, y = reflection_ms, one series per mode.
std::vector<PlotPoint> scalePlotPoints(std::span<const ScaleRow> rows);

// ---- Reflections in motion (glint-bench --motion) ---------------------------

// The CSV header of the motion run, column for column. flip_* are the
// reflection term's LDR-FLIP against per-frame references: flip_still at a
// still camera, flip_motion the mean along the path, flip_<band> along the
// path over the pixels whose surface roughness lies in the band
// (metrics::kRoughnessBandEdges).
inline constexpr std::string_view kMotionCsvHeader =
    "scene,mode,param,value,width,height,reflection_ms,flip_still,flip_motion,ghost_energy_1,ghost_energy_4,"
    "ghost_energy_16,lag_px,flicker,flip_mirror,flip_glossy,flip_rough,flip_very_rough";

// One configuration measured in motion.
struct MotionRow {
    std::string scene;
    std::string mode;
    std::string param{kDefaultParam};
    std::optional<double> value;
    uint32_t width = 0;
    uint32_t height = 0;
    std::optional<double> reflectionMs;  // median over the path run's frames
    double flipStill = 0.0;
    double flipMotion = 0.0;
    std::vector<double> flipPerFrame;  // JSON only: at each captured path frame
    std::array<double, 3> ghostEnergy{};  // 1, 4 and 16 frames after the object starts to move
    double lagPixels = 0.0;
    // metrics::flicker of the tonemapped reflection term over a still
    // camera's last frames (time frozen): 0 for the reference.
    double flicker = 0.0;
    std::array<double, 4> flipBand{};  // NaN where no pixel lies in the band
};

std::string toMotionCsv(std::span<const MotionRow> rows);
// {info..., "rows": [every CSV column, "flip_per_frame": [...]]}.
std::string toMotionJson(const RunInfo& info, std::span<const MotionRow> rows);
// x = reflection_ms, y = flip_motion, one series per mode; defaults as
// baselines, the front labelled.
std::vector<PlotPoint> motionPlotPoints(std::span<const MotionRow> rows);

// Writes `text` to `path`, creating the folder; throws naming the file.
void writeText(const std::filesystem::path& path, std::string_view text);

} // namespace glint::bench
