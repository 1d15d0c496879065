#include "common/app.h"

#include "glint/gpu/error.h"

#include "glint/scene/image_io.h"

#include <CLI/CLI.hpp>
#include <spdlog/cfg/helpers.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

namespace glint::app {

namespace {
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// "off", "RATIO" or "RATIO:ERROR" (scene::ReflectionLodSettings).
std::optional<scene::ReflectionLodSettings> parseReflectionLods(const std::string& text) {
    if (text == "off") return std::nullopt;
    scene::ReflectionLodSettings settings;
    const auto number = [&](const std::string& part, float low, float high, bool openLow) {
        size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(part, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != part.size() || !(openLow ? v > low : v >= low) || !(v <= high)) {
            throw UsageError("--reflection-lods " + text + ": expected off, RATIO or RATIO:ERROR with RATIO in (0, 1] "
                             "and ERROR in [0, 1]");
        }
        return float(v);
    };
    const size_t colon = text.find(':');
    settings.targetRatio = number(text.substr(0, colon), 0.0f, 1.0f, true);
    if (colon != std::string::npos) settings.maxError = number(text.substr(colon + 1), 0.0f, 1.0f, false);
    return settings;
}
} // namespace

Args::Args(int argc, char** argv, const std::string& usage, const std::vector<Flag>& knownFlags,
           const std::vector<Flag>& knownSwitches) {
    CLI::App cli(usage);
    cli.set_help_flag("-h,--help", "print this help and exit");
    cli.add_flag("--validate", common_.validate,
                 "Khronos validation with synchronization validation; exit 2 on any message");
    cli.add_option("--device", common_.device, "a substring of the device name (GLINT_DEVICE does the same)");
    cli.add_option("--log", common_.logLevel, "trace, debug, info, warn, error or off")->capture_default_str();
    cli.add_flag("--no-ray-query", common_.pipelineOnly,
                 "use the ray tracing pipeline even where ray query exists (as on NVIDIA)");
    cli.add_flag("--no-ray-tracing", common_.noRayTracing,
                 "as on a device without ray tracing: hybrid and rt render as ssr (GLINT_NO_RAY_TRACING=1)");
    std::string lods;
    cli.add_option("--reflection-lods", lods,
                   "RATIO[:ERROR]|off: glTF meshes' reflection LODs, a share of the triangles and the largest "
                   "relative error (default 0.25:0.01); off: BVHs from full detail");
    std::map<std::string, std::string> given;
    std::vector<std::pair<std::string, CLI::Option*>> options;
    for (const Flag& f : knownFlags) {
        options.emplace_back(f.name, cli.add_option("--" + f.name, given[f.name], f.help)->type_name("VALUE"));
    }
    std::vector<std::pair<std::string, CLI::Option*>> switches;
    for (const Flag& f : knownSwitches) switches.emplace_back(f.name, cli.add_flag("--" + f.name, f.help));
    try {
        cli.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::cout << cli.help();
        std::exit(0);
    } catch (const CLI::ParseError& e) {
        throw UsageError(std::string(e.what()) + " (--help lists the flags)");
    }
    for (const auto& [name, option] : options) {
        if (option->count() > 0) values_[name] = given[name];
    }
    for (const auto& [name, option] : switches) {
        if (option->count() > 0) values_[name] = "1";
    }
    if (!lods.empty()) common_.reflectionLods = parseReflectionLods(lods);
    const auto level = spdlog::level::from_str(common_.logLevel);
    if (level == spdlog::level::off && common_.logLevel != "off") {
        throw UsageError("--log " + common_.logLevel + ": not a log level (trace, debug, info, warn, error, off)");
    }
    spdlog::set_level(level);
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : it->second;
}

uint32_t Args::getUint(const std::string& name, uint32_t fallback) const {
    const auto it = values_.find(name);
    if (it == values_.end()) {
        return fallback;
    }
    try {
        size_t used = 0;
        const unsigned long v = std::stoul(it->second, &used);
        if (used != it->second.size() || v > 0xffffffffu) {
            throw std::invalid_argument("");
        }
        return static_cast<uint32_t>(v);
    } catch (const std::exception&) {
        throw UsageError("--" + name + " " + it->second + ": not a non-negative integer");
    }
}

scene::GltfLoadOptions Args::gltfOptions() const {
    scene::GltfLoadOptions o;
    o.reflectionLods = common_.reflectionLods;
    return o;
}

gpu::ContextOptions Args::contextOptions() const {
    gpu::ContextOptions o;
    o.validation = common_.validate;
    o.deviceFilter = common_.device;
    o.disableRayQuery = common_.pipelineOnly;
    o.disableRayTracing = common_.noRayTracing;
    // Every sample runs without ray tracing: the renderer falls back to ssr.
    o.requireRayTracing = false;
    return o;
}

int runMain(const char* program, const std::function<int()>& body) {
    spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
    try {
        return body();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: error: %s\n", program, e.what());
        return 1;
    }
}

bool validationClean(gpu::Context& ctx) {
    if (!ctx.validationEnabled()) {
        return true;
    }
    const size_t n = ctx.validation().count();
    if (n == 0) {
        spdlog::info("validation: 0 messages");
        return true;
    }
    spdlog::error("{}", ctx.validation().summary());
    return false;
}

std::pair<uint32_t, uint32_t> parseSize(const std::string& text) {
    const auto number = [&](const std::string& part) {
        size_t used = 0;
        unsigned long v = 0;
        try {
            v = std::stoul(part, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != part.size() || v == 0 || v > 8192) {
            throw UsageError("--size " + text + ": expected N or WxH with 1..8192 pixels each");
        }
        return uint32_t(v);
    };
    const size_t x = text.find('x');
    if (x == std::string::npos) {
        const uint32_t n = number(text);
        return {n, n};
    }
    return {number(text.substr(0, x)), number(text.substr(x + 1))};
}

void writePng(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
    scene::writePng(path, width, height, rgba);
    spdlog::info("wrote {} ({}x{})", path, width, height);
}

} // namespace glint::app
