#include "bench/report.h"

#include <nlohmann/json.hpp>
#include <stb_easy_font.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
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
               number(r.image.psnr) + ',' + number(r.image.ssim) + '\n';
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
        row["total_ms"] = jsonNumber(r.totalMs);
        row["frame_wall_ms"] = jsonNumber(r.frameWallMs);
        row["rt_rays"] = r.rtRays;
        row["sslr_rays"] = r.sslrRays;
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
    const char* header = "%-7s %-17s %8s %9s %9s %9s %8s | %7s %8s %6s %6s | %7s %8s %6s %6s\n";
    std::snprintf(line, sizeof line, header, "mode", "param", "value", "refl_ms", "total_ms", "wall_ms", "rt_rays",
                  "flip", "relmse", "psnr", "ssim", "r.flip", "r.relmse", "r.psnr", "r.ssim");
    out += line;
    out += std::string(std::strlen(line) - 1, '-') + '\n';
    for (const Row& r : rows) {
        const auto cell = [](const std::optional<double>& v) { return v ? number(v, "%.3f") : std::string("-"); };
        std::snprintf(line, sizeof line,
                      "%-7s %-17s %8s %9s %9s %9s %8llu | %7.4f %8.4f %6.2f %6.4f | %7.4f %8.4f %6.2f %6.4f\n",
                      r.mode.c_str(), r.param.c_str(), r.value ? formatValue(r.value).c_str() : "-",
                      cell(r.reflectionMs).c_str(), cell(r.totalMs).c_str(), cell(r.frameWallMs).c_str(),
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
               std::to_string(r.sslrRays) + ',' + number(r.flipMean) + '\n';
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
                        {"total_ms", optional(r.totalMs)},
                        {"rt_rays", r.rtRays},
                        {"sslr_rays", r.sslrRays},
                        {"flip_mean", std::isfinite(r.flipMean) ? Json(r.flipMean) : Json(nullptr)},
                        {"passes", passes},
                        {"draws", r.draws},
                        {"triangles_drawn", r.trianglesDrawn},
                        {"tlas_instances", r.tlasInstances},
                        {"reference_frames", r.referenceFrames}});
    }
    j["rows"] = list;
    return j.dump(2) + "\n";
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

std::vector<double> niceTicks(double lo, double hi, int target) {
    if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1) return {lo};
    const double raw = (hi - lo) / target;
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / magnitude;
    const double step = magnitude * (f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0);
    std::vector<double> ticks;
    for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k += 1.0) {
        ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);  // no "-0"
    }
    return ticks;
}

namespace {

using Rgb = std::array<uint8_t, 3>;

constexpr Rgb kBlack{0, 0, 0};
constexpr Rgb kGrid{225, 225, 225};
constexpr Rgb kFront{60, 60, 60};

// The modes in the colours of the "ray_classes" debug view (hybrid purple,
// SSLR blue, RT red), so the plot reads like the renderer's own pictures.
Rgb seriesColor(const std::string& series, size_t index) {
    if (series == "hybrid") return {150, 50, 200};
    if (series == "ssr") return {40, 100, 230};
    if (series == "rt") return {220, 50, 40};
    constexpr std::array<Rgb, 4> others{{{30, 160, 80}, {230, 150, 20}, {20, 170, 180}, {120, 120, 120}}};
    return others[index % others.size()];
}

class Canvas {
public:
    Canvas(uint32_t width, uint32_t height) : w_(int(width)), h_(int(height)), rgba_(size_t(width) * height * 4, 255) {}

    void set(int x, int y, Rgb c) {
        if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
        uint8_t* p = &rgba_[(size_t(y) * size_t(w_) + size_t(x)) * 4];
        p[0] = c[0];
        p[1] = c[1];
        p[2] = c[2];
        p[3] = 255;
    }
    void fillRect(int x0, int y0, int x1, int y1, Rgb c) {  // [x0, x1) x [y0, y1)
        for (int y = std::max(y0, 0); y < std::min(y1, h_); ++y) {
            for (int x = std::max(x0, 0); x < std::min(x1, w_); ++x) set(x, y, c);
        }
    }
    void disc(double cx, double cy, double r, Rgb c) {
        for (int y = int(std::floor(cy - r)); y <= int(std::ceil(cy + r)); ++y) {
            for (int x = int(std::floor(cx - r)); x <= int(std::ceil(cx + r)); ++x) {
                if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r) set(x, y, c);
            }
        }
    }
    // A line of the given width: discs stepped at most half a pixel apart.
    void line(double x0, double y0, double x1, double y1, double width, Rgb c) {
        const double length = std::hypot(x1 - x0, y1 - y0);
        const int steps = std::max(1, int(std::ceil(length * 2.0)));
        for (int i = 0; i <= steps; ++i) {
            const double t = double(i) / steps;
            disc(x0 + (x1 - x0) * t, y0 + (y1 - y0) * t, width * 0.5, c);
        }
    }
    // stb_easy_font's quads, scaled by an integer; (x, y) is the top left.
    void text(int x, int y, const std::string& s, int scale, Rgb c) {
        std::vector<char> textCopy(s.begin(), s.end());  // stb_easy_font takes char*
        textCopy.push_back('\0');
        // Its docs say about 270 bytes per character on average, but a glyph
        // of many segments ('8': 7 quads of 64 bytes) needs more, and one
        // that does not fit is silently cut: room for 16 quads each.
        std::vector<char> vertices(s.size() * 16 * 64 + 64);
        unsigned char color[4] = {c[0], c[1], c[2], 255};
        const int quads = stb_easy_font_print(0.0f, 0.0f, textCopy.data(), color, vertices.data(),
                                              int(vertices.size()));
        // Each vertex: x, y, z floats and 4 colour bytes; corners 0 and 2 of a
        // quad are opposite, and every quad is axis-aligned.
        const auto* v = reinterpret_cast<const float*>(vertices.data());
        for (int q = 0; q < quads; ++q) {
            const float* a = v + q * 16;
            const float* b = a + 8;
            const int qx0 = int(std::lround(std::min(a[0], b[0]))), qx1 = int(std::lround(std::max(a[0], b[0])));
            const int qy0 = int(std::lround(std::min(a[1], b[1]))), qy1 = int(std::lround(std::max(a[1], b[1])));
            fillRect(x + qx0 * scale, y + qy0 * scale, x + qx1 * scale, y + qy1 * scale, c);
        }
    }
    static int textWidth(const std::string& s, int scale) {
        std::vector<char> textCopy(s.begin(), s.end());
        textCopy.push_back('\0');
        return stb_easy_font_width(textCopy.data()) * scale;
    }
    std::vector<uint8_t> take() { return std::move(rgba_); }

private:
    int w_, h_;
    std::vector<uint8_t> rgba_;
};

// [lo, hi] around the data with a margin, starting at 0 where the margin
// would cross it (times and errors are never negative).
std::pair<double, double> axisRange(double lo, double hi) {
    if (!std::isfinite(lo) || !std::isfinite(hi)) return {0.0, 1.0};
    double pad = (hi - lo) * 0.08;
    if (!(pad > 0.0)) pad = std::max(std::abs(hi) * 0.1, 1e-3);
    double a = lo - pad, b = hi + pad;
    if (lo >= 0.0 && a < 0.0) a = 0.0;
    return {a, b};
}

// A power of ten as the axis shows it: 1k, 10k, 1M, ...
std::string decadeText(double v) {
    const char* suffixes[] = {"", "k", "M", "G", "T"};
    int k = 0;
    while (v >= 1000.0 && k < 4) {
        v /= 1000.0;
        ++k;
    }
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g%s", v, suffixes[k]);
    return buffer;
}

std::string tickText(double v, double step) {
    const int decimals = step > 0.0 ? std::clamp(int(-std::floor(std::log10(step) + 1e-9)), 0, 6) : 3;
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
    return buffer;
}

} // namespace

std::vector<uint8_t> renderPlot(std::span<const PlotPoint> points, const PlotOptions& options) {
    if (options.width == 0 || options.height == 0) throw std::invalid_argument("plot: empty size");
    Canvas canvas(options.width, options.height);
    const int w = int(options.width), h = int(options.height);
    // Text is drawn at 2x on a plot of usual size, 1x on a small one.
    const int scale = w >= 640 && h >= 400 ? 2 : 1;
    const int lineHeight = 9 * scale;

    // Series in first-seen order, for colours and the legend.
    std::vector<std::string> series;
    for (const PlotPoint& p : points) {
        if (std::find(series.begin(), series.end(), p.series) == series.end()) series.push_back(p.series);
    }
    std::map<std::string, Rgb> colors;
    for (size_t i = 0; i < series.size(); ++i) colors[series[i]] = seriesColor(series[i], i);

    // Legend entries, for the right margin's width.
    std::vector<std::string> legend = series;
    if (options.paretoFront) {
        legend.push_back("Pareto front");
        legend.push_back("mode defaults");
    }
    int legendWidth = 0;
    for (const std::string& s : legend) legendWidth = std::max(legendWidth, Canvas::textWidth(s, scale));
    legendWidth += 30 * scale;

    const int left = std::min(w / 4, 45 * scale + 20);
    const int right = w - std::min(w / 3, legendWidth + 10 * scale);
    const int top = std::min(h / 5, 4 * lineHeight);
    const int bottom = h - std::min(h / 4, 3 * lineHeight + 4);
    const int plotW = std::max(right - left, 1), plotH = std::max(bottom - top, 1);

    // x in plot space: its logarithm on a log axis, where x <= 0 has no place.
    const auto tx = [&](double x) {
        return options.logX ? (x > 0.0 ? std::log10(x) : std::numeric_limits<double>::quiet_NaN()) : x;
    };
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
    for (const PlotPoint& p : points) {
        if (!std::isfinite(tx(p.at.x)) || !std::isfinite(p.at.y)) continue;
        xmin = std::min(xmin, tx(p.at.x));
        xmax = std::max(xmax, tx(p.at.x));
        ymin = std::min(ymin, p.at.y);
        ymax = std::max(ymax, p.at.y);
    }
    auto [x0, x1] = axisRange(xmin, xmax);
    if (options.logX && std::isfinite(xmin)) {
        // The log axis may go below zero (x < 1): no clamp there.
        const double pad = std::max((xmax - xmin) * 0.08, 0.1);
        x0 = xmin - pad;
        x1 = xmax + pad;
    }
    const auto [y0, y1] = axisRange(ymin, ymax);
    const auto px = [&](double x) { return left + (tx(x) - x0) / (x1 - x0) * plotW; };
    const auto py = [&](double y) { return bottom - (y - y0) / (y1 - y0) * plotH; };

    // Grid and tick labels (a log axis: at the powers of ten inside it).
    std::vector<double> xt;
    if (options.logX) {
        for (double d = std::ceil(x0); d <= x1; d += 1.0) xt.push_back(std::pow(10.0, d));
    } else {
        xt = niceTicks(x0, x1, std::max(2, plotW / (60 * scale)));
    }
    const std::vector<double> yt = niceTicks(y0, y1, std::max(2, plotH / (40 * scale)));
    const double xStep = xt.size() > 1 ? xt[1] - xt[0] : 0.0;
    const double yStep = yt.size() > 1 ? yt[1] - yt[0] : 0.0;
    for (const double t : xt) {
        const int x = int(std::lround(px(t)));
        canvas.fillRect(x, top, x + 1, bottom, kGrid);
        canvas.fillRect(x, bottom, x + 1, bottom + 3 * scale, kBlack);
        const std::string s = options.logX ? decadeText(t) : tickText(t, xStep);
        canvas.text(x - Canvas::textWidth(s, scale) / 2, bottom + 5 * scale, s, scale, kBlack);
    }
    for (const double t : yt) {
        const int y = int(std::lround(py(t)));
        canvas.fillRect(left, y, right, y + 1, kGrid);
        canvas.fillRect(left - 3 * scale, y, left, y + 1, kBlack);
        const std::string s = tickText(t, yStep);
        canvas.text(left - 5 * scale - Canvas::textWidth(s, scale), y - 3 * scale, s, scale, kBlack);
    }
    canvas.fillRect(left, top, left + 1, bottom + 1, kBlack);
    canvas.fillRect(left, bottom, right + 1, bottom + 1, kBlack);

    // Titles: stb_easy_font draws only horizontally, so the y label sits
    // above its axis.
    canvas.text(left, std::max(2, top - 3 * lineHeight), options.title, scale, kBlack);
    canvas.text(left, std::max(2, top - lineHeight - 2), options.yLabel, scale, kBlack);
    canvas.text(left + (plotW - Canvas::textWidth(options.xLabel, scale)) / 2, bottom + 5 * scale + lineHeight + 4,
                options.xLabel, scale, kBlack);

    // Each series as a line, or the Pareto front, under the points.
    if (options.seriesLines) {
        for (const std::string& name : series) {
            std::vector<Point> line;
            for (const PlotPoint& p : points) {
                if (p.series == name && std::isfinite(tx(p.at.x)) && std::isfinite(p.at.y)) line.push_back(p.at);
            }
            std::sort(line.begin(), line.end(), [](const Point& a, const Point& b) { return a.x < b.x; });
            for (size_t i = 1; i < line.size(); ++i) {
                canvas.line(px(line[i - 1].x), py(line[i - 1].y), px(line[i].x), py(line[i].y), 1.5 * scale,
                            colors[name]);
            }
        }
    }
    std::vector<Point> at;
    for (const PlotPoint& p : points) at.push_back(p.at);
    const std::vector<size_t> front = options.paretoFront ? paretoFront(at) : std::vector<size_t>{};
    for (size_t i = 1; i < front.size(); ++i) {
        canvas.line(px(at[front[i - 1]].x), py(at[front[i - 1]].y), px(at[front[i]].x), py(at[front[i]].y),
                    1.5 * scale, kFront);
    }
    const double r = 3.0 * scale;
    for (const PlotPoint& p : points) {
        if (!std::isfinite(tx(p.at.x)) || !std::isfinite(p.at.y)) continue;
        const double radius = p.baseline ? r * 1.6 : r;
        if (p.baseline) canvas.disc(px(p.at.x), py(p.at.y), radius + 1.5, kBlack);
        canvas.disc(px(p.at.x), py(p.at.y), radius, colors[p.series]);
    }
    // Front points: a ring and their configuration beside them. Front
    // points close in time get their labels stacked rather than overprinted.
    struct Box {
        int x0, y0, x1, y1;
    };
    std::vector<Box> labels;
    const int labelHeight = 10;
    for (const size_t i : front) {
        const double cx = px(at[i].x), cy = py(at[i].y);
        for (int a = 0; a < 64; ++a) {
            const double t = a * 2.0 * 3.14159265358979 / 64.0;
            canvas.disc(cx + std::cos(t) * (r * 2.2), cy + std::sin(t) * (r * 2.2), 0.5 * scale, kFront);
        }
        Box box{int(cx + r * 2.5), int(cy - r * 2.5 - 4 * scale), 0, 0};
        box.x1 = box.x0 + Canvas::textWidth(points[i].label, 1);
        for (int tries = 0; tries < 8; ++tries) {
            box.y1 = box.y0 + labelHeight;
            const bool overlaps = std::any_of(labels.begin(), labels.end(), [&](const Box& b) {
                return box.x0 < b.x1 && b.x0 < box.x1 && box.y0 < b.y1 && b.y0 < box.y1;
            });
            if (!overlaps) break;
            box.y0 -= labelHeight;
        }
        labels.push_back(box);
        canvas.text(box.x0, box.y0, points[i].label, 1, kFront);
    }

    // Legend, right of the plot.
    int ly = top;
    const int lx = right + 10 * scale;
    for (const std::string& s : series) {
        canvas.disc(lx + 8 * scale, ly + 3.5 * scale, r, colors[s]);
        canvas.text(lx + 20 * scale, ly, s, scale, kBlack);
        ly += lineHeight + 4 * scale;
    }
    if (!options.paretoFront) return canvas.take();
    canvas.line(lx, ly + 3.5 * scale, lx + 16 * scale, ly + 3.5 * scale, 1.5 * scale, kFront);
    canvas.text(lx + 20 * scale, ly, "Pareto front", scale, kBlack);
    ly += lineHeight + 4 * scale;
    canvas.disc(lx + 8 * scale, ly + 3.5 * scale, r * 1.6 + 1.5, kBlack);
    canvas.disc(lx + 8 * scale, ly + 3.5 * scale, r * 1.6, kGrid);
    canvas.text(lx + 20 * scale, ly, "mode defaults", scale, kBlack);
    return canvas.take();
}

void writePlot(const std::filesystem::path& path, std::span<const PlotPoint> points, const PlotOptions& options) {
    const std::vector<uint8_t> rgba = renderPlot(points, options);
    if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
    if (!stbi_write_png(path.string().c_str(), int(options.width), int(options.height), 4, rgba.data(),
                        int(options.width * 4))) {
        throw std::runtime_error("cannot write plot '" + path.string() + "'");
    }
}

} // namespace glint::bench
