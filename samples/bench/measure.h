#pragma once
// What every glint-bench run does per configuration: the converged
// reference at the pose of the measured runs' last frame, a measured run
// after untimed warm-up frames, and the error of an image and of its
// reflection term against the reference's.

#include "bench/report.h"
#include "common/reflection_run.h"
#include "glint/metrics/image.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace glint::bench {

// The resolved reflection term (RGBA floats) as two images: the linear
// radiance for relMSE (made for HDR radiance) and its tonemapped display
// values for FLIP, PSNR and SSIM. Pixels without a reflection are black.
struct ReflectionTerm {
    metrics::Image radiance;
    metrics::Image display;
};

ReflectionTerm reflectionTerm(const std::vector<float>& rgba, uint32_t width, uint32_t height, float exposure,
                              const std::string& name);

// A display image (linear, [0, 1]) as the RGBA8 sRGB that app::writePng takes.
std::vector<uint8_t> toSrgb8(const metrics::Image& image);

// FLIP, relMSE (on the radiances when given), PSNR and SSIM of `test`.
ErrorMetrics measure(const metrics::Image& reference, const metrics::Image& test, double ppd,
                     const metrics::Image* referenceRadiance = nullptr, const metrics::Image* testRadiance = nullptr);

// One configuration: a mode with its defaults, or with one parameter
// (app::parameters()) set.
struct Configuration {
    passes::ReflectionMode mode = passes::ReflectionMode::Hybrid;
    std::string param{kDefaultParam};  // kDefaultParam or a parameter name
    double value = 0.0;
};
// `base` in the configuration's mode with its parameter set.
app::ReflectionRunOptions configure(const app::ReflectionRunOptions& base, const Configuration& c);
// "hybrid defaults", "rt sslr_steps=32".
std::string describe(const Configuration& c);

struct Reference {
    app::ReflectionRunResult result;
    metrics::Image image;  // the final image
    ReflectionTerm term;
};

// The reference (app::ReferenceOptions) of runs made with `base`: rendered
// at the pose and scene time of their frame `frame` (default: the last), a
// still camera at that pose and the scene's time frozen there. `maxFrames`
// caps its accumulation.
Reference renderReference(gpu::Context& ctx, scene::Scene& scene, const app::ReflectionRunOptions& base,
                          std::optional<uint32_t> maxFrames = std::nullopt,
                          std::optional<uint32_t> frame = std::nullopt);

// `warmupFrames` untimed frames of the configuration, then the measured run.
// While the metrics run on the CPU the GPU idles and drops its clocks, and
// 16 frames are too few to raise them again (H200, 1080p: the same
// configuration read 0.8 or 3.4 ms of reflections from one run to the next).
app::ReflectionRunResult runMeasured(gpu::Context& ctx, scene::Scene& scene, const app::ReflectionRunOptions& options,
                                     uint32_t warmupFrames);

} // namespace glint::bench
