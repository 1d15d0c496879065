// glint-bench's report (samples/bench/report.h): the CSV schema it states,
// the Pareto front, and the plot, all without a GPU.

#include "bench/report.h"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

using namespace glint::bench;

namespace {

std::vector<std::string> split(const std::string& line, char separator) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, separator)) cells.push_back(cell);
    if (!line.empty() && line.back() == separator) cells.push_back("");
    return cells;
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::string line;
    std::istringstream in(text);
    while (std::getline(in, line)) out.push_back(line);
    return out;
}

Row makeRow(const std::string& mode, const std::string& param, std::optional<double> value, double ms, double flip) {
    Row r;
    r.scene = "plaza";
    r.mode = mode;
    r.param = param;
    r.value = value;
    r.width = 64;
    r.height = 48;
    r.reflectionMs = ms;
    r.reflectionMeanMs = ms * 1.1;
    r.reflectionSpanMs = ms * 1.05;
    r.screenSpaceIdleFrames = 3;
    r.totalMs = ms * 3.0;
    r.frameWallMs = ms * 10.0;
    r.rtRays = 1234;
    r.image = {flip, 0.5, 30.0, 0.9};
    r.reflection = {flip * 2.0, 1.5, 20.0, 0.8};
    return r;
}

} // namespace

TEST_CASE("the CSV has the stated header and one parseable row per configuration") {
    const std::vector<Row> rows = {makeRow("hybrid", "default", std::nullopt, 1.0, 0.05),
                                   makeRow("ssr", "default", std::nullopt, 0.5, 0.09),
                                   makeRow("hybrid", "sslr_threshold", 0.7f, 0.8, 0.06),
                                   makeRow("hybrid", "sslr_steps", 32.0, 0.9, 0.055)};
    const std::vector<std::string> out = lines(toCsv(rows));
    REQUIRE(out.size() == rows.size() + 1);
    CHECK(out[0] == "scene,mode,param,value,width,height,reflection_ms,total_ms,rt_rays,flip_mean,relmse,psnr,ssim,"
                    "reflection_mean_ms,reflection_span_ms,screen_space_idle_frames");
    for (size_t i = 0; i < rows.size(); ++i) {
        const std::vector<std::string> cells = split(out[i + 1], ',');
        REQUIRE(cells.size() == 16);
        CHECK(cells[0] == "plaza");
        CHECK(cells[1] == rows[i].mode);
        CHECK(cells[2] == rows[i].param);
        // Every numeric column reads back whole; the value is empty only on default rows.
        for (size_t c = 4; c < cells.size(); ++c) {
            size_t used = 0;
            const double v = std::stod(cells[c], &used);
            CHECK_MESSAGE(used == cells[c].size(), "column ", c, ": ", cells[c]);
            CHECK(std::isfinite(v));
        }
        if (rows[i].param == "default") {
            CHECK(cells[3].empty());
        } else {
            CHECK(std::stod(cells[3]) == doctest::Approx(*rows[i].value));
        }
    }
    // A parameter stored as a float prints as typed, not as its double expansion.
    CHECK(split(out[3], ',')[3] == "0.7");
    CHECK(split(out[4], ',')[3] == "32");
    CHECK(std::stod(split(out[1], ',')[9]) == doctest::Approx(0.05));
    CHECK(std::stod(split(out[1], ',')[14]) == doctest::Approx(1.05));
    CHECK(split(out[1], ',')[15] == "3");
}

TEST_CASE("parameter values print as typed: whole numbers without exponents, floats without float noise") {
    CHECK(formatValue(std::nullopt).empty());
    CHECK(formatValue(10.0) == "10");
    CHECK(formatValue(200.0) == "200");
    CHECK(formatValue(0.0) == "0");
    CHECK(formatValue(double(0.95f)) == "0.95");
    CHECK(formatValue(double(0.22f)) == "0.22");
}

TEST_CASE("the CSV writes a missing time as an empty cell and identical images' PSNR as inf") {
    Row r = makeRow("rt", "default", std::nullopt, 1.0, 0.0);
    r.reflectionMs.reset();
    r.image.psnr = std::numeric_limits<double>::infinity();
    const std::vector<std::string> cells = split(lines(toCsv(std::vector<Row>{r}))[1], ',');
    REQUIRE(cells.size() == 16);
    CHECK(cells[6].empty());
    CHECK(cells[11] == "inf");
    CHECK(std::isinf(std::stod(cells[11])));
}

TEST_CASE("the JSON holds the CSV's rows plus the reflection term and the run's provenance") {
    RunInfo info;
    info.device = "llvmpipe";
    info.commit = "abc";
    info.date = "2026-11-22T00:00:00Z";
    Row r = makeRow("hybrid", "default", std::nullopt, 1.0, 0.05);
    r.image.psnr = std::numeric_limits<double>::infinity();
    const std::string json = toJson(info, std::vector<Row>{r});
    for (const char* key : {"\"device\"", "\"driver\"", "\"date\"", "\"commit\"", "\"rows\"", "\"frame_wall_ms\"",
                            "\"reflection\"", "\"flip_mean\"", "\"rt_rays\"", "\"reflection_ms\""}) {
        CHECK_MESSAGE(json.find(key) != std::string::npos, key);
    }
    CHECK(json.find("\"psnr\": null") != std::string::npos);  // JSON has no infinity
}

TEST_CASE("the Pareto front keeps exactly the non-dominated points, cheapest first") {
    // (time, error): 0 and 2 and 4 trade off; 1 is beaten by 0 (slower and
    // worse), 3 by 2; 5 ties 2 in time but is worse; 6 has no time.
    const std::vector<Point> points = {{1.0, 0.30}, {1.5, 0.35}, {2.0, 0.10}, {3.0, 0.20},
                                       {4.0, 0.05}, {2.0, 0.15}, {std::nan(""), 0.01}};
    CHECK(paretoFront(points) == std::vector<size_t>{0, 2, 4});
}

TEST_CASE("the Pareto front of a single point, of equal points and of none") {
    CHECK(paretoFront(std::vector<Point>{{1.0, 1.0}}) == std::vector<size_t>{0});
    CHECK(paretoFront(std::vector<Point>{{1.0, 1.0}, {1.0, 1.0}}) == std::vector<size_t>{0});
    CHECK(paretoFront(std::vector<Point>{}).empty());
    // Cheaper and better dominates everything: a front of one.
    CHECK(paretoFront(std::vector<Point>{{2.0, 0.5}, {0.5, 0.1}, {1.0, 0.2}}) == std::vector<size_t>{1});
}

namespace {

// The PNG's size from its IHDR chunk.
std::pair<uint32_t, uint32_t> pngSize(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    unsigned char header[24] = {};
    file.read(reinterpret_cast<char*>(header), sizeof header);
    REQUIRE(file);
    const auto word = [&](int at) {
        return uint32_t(header[at]) << 24 | uint32_t(header[at + 1]) << 16 | uint32_t(header[at + 2]) << 8 |
               uint32_t(header[at + 3]);
    };
    return {word(16), word(20)};
}

std::string readAll(const std::string& path) {
    std::ifstream file(path);
    return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

} // namespace

TEST_CASE("the plot's points carry the Pareto front; matplotlib draws them as PNG and SVG at the requested size") {
    const std::vector<Row> rows = {makeRow("hybrid", "default", std::nullopt, 1.0, 0.05),
                                   makeRow("ssr", "default", std::nullopt, 0.5, 0.09),
                                   makeRow("rt", "default", std::nullopt, 1.2, 0.04),
                                   makeRow("hybrid", "sslr_steps", 32.0, 0.9, 0.055),
                                   makeRow("hybrid", "sslr_steps", 16.0, 1.1, 0.06)};
    const std::vector<PlotPoint> points = plotPoints(rows, false);
    REQUIRE(points.size() == 5);
    CHECK(points[0].at.x == 1.0);
    CHECK(points[3].label == "sslr_steps=32");
    CHECK(plotPoints(rows, true)[0].at.x == 10.0);

    PlotOptions options;
    options.title = "plaza 64x48";
    options.xLabel = "reflection_ms";
    options.yLabel = "FLIP mean";
    const auto json = nlohmann::json::parse(plotJson(points, options));
    REQUIRE(json["points"].size() == 5);
    // ssr (fastest), sslr_steps=32, hybrid, rt (least error) are on the
    // front; sslr_steps=16 is dominated by the hybrid default.
    const std::vector<bool> front = {true, true, true, true, false};
    for (size_t i = 0; i < front.size(); ++i) CHECK(json["points"][i]["front"] == front[i]);
    CHECK(json["title"] == "plaza 64x48");

    for (const auto& [w, h] : {std::pair<uint32_t, uint32_t>{800, 500}, {300, 200}}) {
        options.width = w;
        options.height = h;
        // Relative: ctest runs the suite in its build folder.
        const std::string stem = "test-out/bench/plot_" + std::to_string(w);
        writePlot(stem + ".png", points, options);
        CHECK(pngSize(stem + ".png") == std::pair<uint32_t, uint32_t>{w, h});
        const std::string svg = readAll(stem + ".svg");
        CHECK(svg.find("<svg") != std::string::npos);
        // The script and its input stay beside the plot.
        CHECK(std::filesystem::exists(stem + ".plot.py"));
        CHECK(std::filesystem::exists(stem + ".plot.json"));
    }
}

TEST_CASE("an empty plot is still drawn; a tiny one is refused") {
    PlotOptions options;
    options.width = 200;
    options.height = 120;
    writePlot("test-out/bench/plot_empty.png", {}, options);
    CHECK(pngSize("test-out/bench/plot_empty.png") == std::pair<uint32_t, uint32_t>{200, 120});
    options.width = 32;
    CHECK_THROWS_WITH_AS(writePlot("test-out/bench/plot_tiny.png", {}, options), doctest::Contains("plot_tiny.png"),
                         std::runtime_error);
}

TEST_CASE("the scale CSV has its header and a row per size and mode; the plot puts sizes on a log axis") {
    std::vector<ScaleRow> rows;
    for (const uint32_t n : {16u, 256u, 4096u}) {
        for (const char* mode : {"hybrid", "rt"}) {
            ScaleRow r;
            r.scene = "city";
            r.mode = mode;
            r.instances = n;
            r.triangles = uint64_t(n) * 40000;
            r.width = 1920;
            r.height = 1080;
            r.reflectionMs = std::string(mode) == "rt" ? 0.3 + 0.1 * std::log2(double(n)) : 0.4;
            r.reflectionSpanMs = *r.reflectionMs * 0.9;
            r.reflectionMeanMs = *r.reflectionMs * 1.1;
            r.reflectionSpanMeanMs = *r.reflectionMs;
            r.totalMs = 5.0;
            r.rtRays = 1000;
            r.sslrRays = 2000;
            r.flipMean = 0.05;
            r.passes = {{"gbuffer", 3.0}};
            rows.push_back(r);
        }
    }
    const std::vector<std::string> csv = lines(toScaleCsv(rows));
    REQUIRE(csv.size() == rows.size() + 1);
    CHECK(csv[0] == kScaleCsvHeader);
    const std::vector<std::string> cells = split(csv[3], ',');
    REQUIRE(cells.size() == split(std::string(kScaleCsvHeader), ',').size());
    CHECK(cells[2] == "256");
    CHECK(cells[3] == "10240000");
    CHECK(std::stod(cells[7]) == doctest::Approx(0.36));

    const std::vector<PlotPoint> points = scalePlotPoints(rows);
    REQUIRE(points.size() == rows.size());
    CHECK(points[0].at.x == 640000.0);
    PlotOptions options;
    options.logX = true;
    options.seriesLines = true;
    options.paretoFront = false;
    const auto json = nlohmann::json::parse(plotJson(points, options));
    CHECK(json["logX"] == true);
    CHECK(json["points"].size() == rows.size());
    for (const auto& p : json["points"]) CHECK(p["front"] == false);
    writePlot("test-out/bench/scale.png", points, options);
    CHECK(pngSize("test-out/bench/scale.png") == std::pair<uint32_t, uint32_t>{options.width, options.height});
}

TEST_CASE("the motion CSV has its header and the motion metrics per configuration; empty bands are nan and null") {
    std::vector<MotionRow> rows(2);
    for (size_t k = 0; k < rows.size(); ++k) {
        MotionRow& r = rows[k];
        r.scene = "plaza";
        r.mode = k == 0 ? "hybrid" : "rt";
        r.width = 1920;
        r.height = 1080;
        r.reflectionMs = 0.5 + double(k);
        r.flipStill = 0.05;
        r.flipMotion = 0.06;
        r.flipPerFrame = {0.05, 0.07};
        r.ghostEnergy = {0.1, 0.04, 0.02};
        r.lagPixels = 1.5;
        r.flicker = 0.002;
        r.flipBand = {0.03, 0.05, 0.08, std::numeric_limits<double>::quiet_NaN()};
    }
    rows[1].param = "history_frames";
    rows[1].value = 64.0;
    const std::vector<std::string> csv = lines(toMotionCsv(rows));
    REQUIRE(csv.size() == 3);
    CHECK(csv[0] == kMotionCsvHeader);
    const std::vector<std::string> header = split(std::string(kMotionCsvHeader), ',');
    const std::vector<std::string> cells = split(csv[2], ',');
    REQUIRE(cells.size() == header.size());
    const auto column = [&](const char* name) {
        return cells[size_t(std::find(header.begin(), header.end(), name) - header.begin())];
    };
    CHECK(column("param") == "history_frames");
    CHECK(column("value") == "64");
    CHECK(std::stod(column("ghost_energy_4")) == doctest::Approx(0.04));
    CHECK(std::stod(column("lag_px")) == doctest::Approx(1.5));
    CHECK(std::stod(column("flicker")) == doctest::Approx(0.002));
    CHECK(column("flip_very_rough") == "nan");

    const auto json = nlohmann::json::parse(toMotionJson(RunInfo{}, rows));
    REQUIRE(json["rows"].size() == 2);
    CHECK(json["rows"][0]["flip_per_frame"].size() == 2);
    CHECK(json["rows"][0]["flip_very_rough"].is_null());
    CHECK(json["rows"][1]["ghost_energy_16"] == doctest::Approx(0.02));

    const std::vector<PlotPoint> points = motionPlotPoints(rows);
    REQUIRE(points.size() == 2);
    CHECK(points[1].at.x == 1.5);
    CHECK(points[1].at.y == 0.06);
    CHECK(points[0].baseline);
    CHECK(points[1].label == "history_frames=64");
}
