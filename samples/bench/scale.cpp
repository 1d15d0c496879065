#include "bench/scale.h"

#include "bench/measure.h"
#include "glint/scene/error.h"

#include "glint/occlusion_shared.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <stdexcept>
#include <string>

namespace glint::bench {

std::vector<uint32_t> parseScale(std::string_view text) {
    std::vector<uint32_t> sizes;
    for (size_t start = 0; start <= text.size();) {
        const size_t end = std::min(text.find(',', start), text.size());
        const std::string_view item = text.substr(start, end - start);
        uint32_t n = 0;
        const auto [last, error] = std::from_chars(item.data(), item.data() + item.size(), n);
        if (item.empty() || error != std::errc() || last != item.data() + item.size()) {
            throw std::runtime_error("--scale: '" + std::string(item) + "' is not a number of instances");
        }
        if (n < scene::kCityMinInstances || n > scene::kCityMaxInstances) {
            throw std::runtime_error("--scale: " + std::to_string(n) + " instances is outside " +
                                     std::to_string(scene::kCityMinInstances) + ".." +
                                     std::to_string(scene::kCityMaxInstances));
        }
        if (std::find(sizes.begin(), sizes.end(), n) != sizes.end()) {
            throw std::runtime_error("--scale: " + std::to_string(n) + " given twice");
        }
        sizes.push_back(n);
        start = end + 1;
    }
    return sizes;
}

std::vector<ScaleRow> runScale(gpu::Context& ctx, const ScaleSettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    const auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    std::vector<ScaleRow> rows;
    for (size_t s = 0; s < settings.instances.size(); ++s) {
        if (settings.deadline && std::chrono::steady_clock::now() >= *settings.deadline) {
            spdlog::warn("scale: the time limit passed after {} of {} sizes ({:.0f} s); the rest are not measured", s,
                         settings.instances.size(), elapsed());
            break;
        }
        scene::CityOptions city = settings.city;
        city.instances = settings.instances[s];
        scene::Scene scene = scene::makeCity(city);
        const uint64_t triangles = scene::instancedTriangleCount(scene);
        spdlog::info("scale {}/{}: city of {} buildings, {} instances, {:.1f}M instanced triangles ({:.0f} s)", s + 1,
                     settings.instances.size(), city.instances, scene.instances.size(), double(triangles) * 1e-6,
                     elapsed());
        // Each size against its own converged reference.
        const Reference reference = renderReference(ctx, scene, settings.base, settings.referenceMaxFrames);
        for (const passes::ReflectionMode mode : settings.modes) {
            app::ReflectionRunOptions options = settings.base;
            options.frame.mode = mode;
            const app::ReflectionRunResult result = runMeasured(ctx, scene, options, settings.warmupFrames);
            const metrics::Image image = metrics::imageFromSrgb8(options.width, options.height, result.rgba, 4,
                                                                 std::string(passes::modeName(mode)));
            ScaleRow row;
            row.scene = "city";
            row.mode = std::string(passes::modeName(mode));
            row.instances = city.instances;
            row.triangles = triangles;
            row.width = options.width;
            row.height = options.height;
            row.reflectionMs = result.reflectionMs;
            row.reflectionSpanMs = result.reflectionSpanMs;
            row.reflectionMeanMs = result.reflectionMeanMs;
            row.reflectionSpanMeanMs = result.reflectionSpanMeanMs;
            row.totalMs = result.totalMs;
            row.rtRays = result.rtRays;
            row.sslrRays = result.sslrRays;
            row.flipMean = measure(reference.image, image, settings.ppd).flipMean;
            for (const app::PassTime& p : result.passes) row.passes.emplace_back(p.name, p.milliseconds);
            row.draws = result.gbuffer.draws;
            row.trianglesDrawn = result.gbuffer.triangles;
            if (!result.occlusion.empty()) {
                row.trianglesDrawn = result.occlusion[shader::kOcclusionStatTriangles];
                row.instancesOccluded = result.occlusion[shader::kOcclusionStatOccluded];
            }
            row.tlasInstances = result.tlasInstances;
            row.referenceFrames = reference.result.framesRun;
            spdlog::info("  {}: reflections {:.3f} ms (span {:.3f} ms), total {:.2f} ms, {} RT rays, FLIP {:.4f} "
                         "({:.0f} s)",
                         row.mode, row.reflectionMs.value_or(0.0), row.reflectionSpanMs.value_or(0.0),
                         row.totalMs.value_or(0.0), row.rtRays, row.flipMean, elapsed());
            rows.push_back(std::move(row));
            if (settings.onRow) settings.onRow(rows);
        }
    }
    return rows;
}

} // namespace glint::bench
