#pragma once
// glint-bench --scale: the reflections' cost against scene size. The city
// (scene::makeCity) at each instance count, each size with its own
// converged reference, every mode with its defaults.

#include "bench/report.h"
#include "common/reflection_run.h"
#include "glint/gpu/context.h"
#include "glint/scene/builtin_scenes.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace glint::bench {

struct ScaleSettings {
    std::vector<uint32_t> instances;  // the sizes, as CityOptions::instances
    scene::CityOptions city;          // triangles and seed; instances replaced per size
    app::ReflectionRunOptions base;   // size, frames, start time, jitter, backend
    std::vector<passes::ReflectionMode> modes;
    uint32_t warmupFrames = 0;
    double ppd = 0.0;
    std::optional<uint32_t> referenceMaxFrames;
    // No city size starts after this (glint-bench --time-limit).
    std::optional<std::chrono::steady_clock::time_point> deadline;
    // Called with the rows so far after each one: glint-bench writes its
    // CSV and JSON there, so a run that is stopped keeps what it measured.
    std::function<void(std::span<const ScaleRow>)> onRow;
};

// "16,64,256": each in CityOptions' range, no repeats; throws naming --scale.
std::vector<uint32_t> parseScale(std::string_view text);

// One row per size and mode, in that order; fewer where the deadline
// passed before a size started.
std::vector<ScaleRow> runScale(gpu::Context& ctx, const ScaleSettings& settings);

} // namespace glint::bench
