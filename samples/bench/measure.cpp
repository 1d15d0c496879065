#include "bench/measure.h"

#include "glint/metrics/flip.h"
#include "glint/metrics/pixel_metrics.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace glint::bench {

namespace {

// Khronos PBR Neutral, as shaders/composite/tonemap.glsl (the "resolved"
// debug view's operator): LDR-FLIP, PSNR and SSIM need display values in
// [0, 1], and these are the ones the debug view shows.
glm::vec3 tonemapNeutral(glm::vec3 c) {
    c = glm::max(c, glm::vec3(0.0f));
    const float startCompression = 0.8f - 0.04f;
    const float desaturation = 0.15f;
    const float x = std::min(c.r, std::min(c.g, c.b));
    const float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
    c -= offset;
    const float peak = std::max(c.r, std::max(c.g, c.b));
    if (peak >= startCompression) {
        const float d = 1.0f - startCompression;
        const float newPeak = 1.0f - d * d / (peak + d - startCompression);
        c *= newPeak / peak;
        const float g = 1.0f - 1.0f / (desaturation * (peak - newPeak) + 1.0f);
        c = glm::mix(c, glm::vec3(newPeak), g);
    }
    return glm::clamp(c, glm::vec3(0.0f), glm::vec3(1.0f));
}

} // namespace

ReflectionTerm reflectionTerm(const std::vector<float>& rgba, uint32_t width, uint32_t height, float exposure,
                              const std::string& name) {
    ReflectionTerm t;
    t.radiance = {width, height, {}, name + " (reflection radiance)"};
    t.display = {width, height, {}, name + " (reflection, tonemapped)"};
    t.radiance.linear.resize(size_t(width) * height);
    t.display.linear.resize(size_t(width) * height);
    for (size_t p = 0; p < t.radiance.linear.size(); ++p) {
        glm::vec3 c(rgba[p * 4], rgba[p * 4 + 1], rgba[p * 4 + 2]);
        if (!(rgba[p * 4 + 3] > 0.0f) || !std::isfinite(c.r + c.g + c.b)) c = glm::vec3(0.0f);
        t.radiance.linear[p] = c;
        t.display.linear[p] = tonemapNeutral(c * exposure);
    }
    return t;
}

std::vector<uint8_t> toSrgb8(const metrics::Image& image) {
    std::vector<uint8_t> rgba(image.linear.size() * 4, 255);
    for (size_t p = 0; p < image.linear.size(); ++p) {
        for (int c = 0; c < 3; ++c) {
            rgba[p * 4 + c] = uint8_t(std::lround(metrics::linearToSrgb(image.linear[p][c]) * 255.0f));
        }
    }
    return rgba;
}

ErrorMetrics measure(const metrics::Image& reference, const metrics::Image& test, double ppd,
                     const metrics::Image* referenceRadiance, const metrics::Image* testRadiance) {
    ErrorMetrics m;
    m.flipMean = metrics::flip(reference, test, ppd).stats.mean;
    m.relMse = referenceRadiance ? metrics::relMse(*referenceRadiance, *testRadiance) : metrics::relMse(reference, test);
    m.psnr = metrics::psnr(reference, test);
    m.ssim = metrics::ssim(reference, test);
    return m;
}

app::ReflectionRunOptions configure(const app::ReflectionRunOptions& base, const Configuration& c) {
    app::ReflectionRunOptions options = base;
    options.frame.mode = c.mode;
    if (c.param != kDefaultParam) app::setParameter(options, c.param, formatValue(c.value));
    return options;
}

std::string describe(const Configuration& c) {
    const std::string mode(passes::modeName(c.mode));
    return c.param == kDefaultParam ? mode + " defaults" : mode + " " + c.param + "=" + formatValue(c.value);
}

Reference renderReference(gpu::Context& ctx, scene::Scene& scene, const app::ReflectionRunOptions& base,
                          std::optional<uint32_t> maxFrames, std::optional<uint32_t> frame) {
    const uint32_t at = frame.value_or(std::max(base.frames, 1u) - 1);
    app::ReflectionRunOptions options = base;
    options.reference.enabled = true;
    options.startSeconds = base.freezeTime ? base.startSeconds : base.startSeconds + float(at) * base.frameSeconds;
    options.stillPose = base.stillPose ? *base.stillPose : app::cameraPoseAt(scene, base, at);
    options.captureFrames.clear();
    if (maxFrames) {
        if (*maxFrames == 0 || *maxFrames > 2048) {
            throw std::runtime_error("--reference-max-frames: expected 1..2048");
        }
        options.reference.maxFrames = *maxFrames;
        options.reference.minFrames = std::min(options.reference.minFrames, *maxFrames);
        options.reference.checkEvery = std::min(options.reference.checkEvery, *maxFrames);
    }
    spdlog::info("reference: {}x{} at the pose of frame {} ({:.3f} s)", base.width, base.height, at,
                 options.startSeconds);
    Reference r;
    r.result = app::runReflections(ctx, scene, options);
    r.image = metrics::imageFromSrgb8(base.width, base.height, r.result.rgba, 4, "reference");
    r.term = reflectionTerm(r.result.resolved, base.width, base.height, base.frame.composite.exposure, "reference");
    return r;
}

app::ReflectionRunResult runMeasured(gpu::Context& ctx, scene::Scene& scene, const app::ReflectionRunOptions& options,
                                     uint32_t warmupFrames) {
    if (warmupFrames > 0) {
        app::ReflectionRunOptions warmup = options;
        warmup.frames = warmupFrames;
        warmup.readResolved = false;
        warmup.timeEveryFrame = false;
        warmup.captureFrames.clear();
        app::runReflections(ctx, scene, warmup);
    }
    return app::runReflections(ctx, scene, options);
}

} // namespace glint::bench
