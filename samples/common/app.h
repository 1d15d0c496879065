#pragma once
// What every Glint executable shares: common flags, logging set-up, and a
// main wrapper that turns any exception into one line on stderr and a
// non-zero exit.

#include "glint/gpu/context.h"
#include "glint/scene/gltf_loader.h"

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace glint::app {

struct CommonOptions {
    bool validate = false;       // --validate: Khronos validation + sync validation, fail on any message
    std::string device;          // --device NAME (overrides GLINT_DEVICE)
    std::string logLevel = "info";
    bool pipelineOnly = false;   // --no-ray-query: use the ray tracing pipeline even where ray query exists
    // --no-ray-tracing: run as on a device without ray tracing (hybrid and
    // rt render as ssr); GLINT_NO_RAY_TRACING=1 does the same.
    bool noRayTracing = false;
    // --reflection-lods RATIO[:ERROR]: the reflection LODs generated for
    // glTF meshes (scene::ReflectionLodSettings: triangle share, relative
    // error); "off": the BVH builds them from full detail.
    std::optional<scene::ReflectionLodSettings> reflectionLods = scene::ReflectionLodSettings{};
};

// One command-line option of an executable: "--name VALUE" (or a switch,
// "--name", value "1") and its line in --help.
struct Flag {
    Flag(const char* flagName, std::string flagHelp = {}) : name(flagName), help(std::move(flagHelp)) {}
    std::string name;
    std::string help;
};

// The command line, parsed by CLI11: the common flags (CommonOptions) and
// the executable's own; --help prints `usage` and every flag's help.
// Unknown flags, a missing value or a bad common value throw one line
// naming it.
class Args {
public:
    Args(int argc, char** argv, const std::string& usage, const std::vector<Flag>& knownFlags,
         const std::vector<Flag>& knownSwitches);
    const CommonOptions& common() const { return common_; }
    bool has(const std::string& name) const { return values_.count(name) != 0; }
    std::string get(const std::string& name, const std::string& fallback) const;
    uint32_t getUint(const std::string& name, uint32_t fallback) const;

    gpu::ContextOptions contextOptions() const;
    // How scene files are loaded (the reflection LODs).
    scene::GltfLoadOptions gltfOptions() const;

private:
    CommonOptions common_;
    std::map<std::string, std::string> values_;
};

// Runs `body`, catching everything: prints "<program>: error: <what>" and
// returns 1; returns 2 when --validate saw validation messages.
int runMain(const char* program, const std::function<int()>& body);

// Reports validation messages collected by `ctx`; true when there were none.
bool validationClean(gpu::Context& ctx);

// A --size value: "N" (square) or "WxH", 1..8192 pixels each; throws a
// one-line error naming the value otherwise.
std::pair<uint32_t, uint32_t> parseSize(const std::string& text);

void writePng(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba);

} // namespace glint::app
