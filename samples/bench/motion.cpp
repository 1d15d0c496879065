#include "bench/motion.h"

#include "bench/measure.h"
#include "glint/metrics/flip.h"
#include "glint/scene/builtin_scenes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace glint::bench {

namespace {

uint32_t frameAt(float seconds, float frameSeconds) { return uint32_t(std::lround(seconds / frameSeconds)); }

// The mirror-motion scene's options: its own time from 0 and its own path.
app::ReflectionRunOptions mirrorOptions(const app::ReflectionRunOptions& options, const MirrorMotionFrames& frames) {
    app::ReflectionRunOptions o = options;
    o.startSeconds = 0.0f;
    o.stillPose.reset();
    o.freezeTime = false;
    o.frames = frames.frames;
    o.readResolved = true;
    return o;
}

// A reference of frame `frame` of a mirror-motion run: its reflection
// term's radiance, and where the wet floor is when `floor` is given (the
// mirror and glossy roughness bands: the lamp and the walls are rougher).
metrics::Image mirrorReference(gpu::Context& ctx, scene::Scene& scene, const app::ReflectionRunOptions& options,
                               uint32_t frame, std::optional<uint32_t> maxFrames,
                               std::vector<uint8_t>* floor = nullptr) {
    Reference r = renderReference(ctx, scene, options, maxFrames, frame);
    if (floor) {
        floor->assign(r.result.roughness.size(), 0);
        for (size_t p = 0; p < floor->size(); ++p) {
            const float roughness = r.result.roughness[p];
            (*floor)[p] = roughness >= 0.0f && metrics::roughnessBand(roughness) <= 1 ? 1 : 0;
        }
    }
    return std::move(r.term.radiance);
}

// The contribution with everything off the floor zeroed.
metrics::Contribution onFloor(metrics::Contribution c, const std::vector<uint8_t>& floor) {
    for (size_t p = 0; p < c.luminance.size(); ++p) {
        if (p >= floor.size() || floor[p] == 0) c.luminance[p] = 0.0f;
    }
    return c;
}

std::array<double, metrics::kRoughnessBands> pooledBands(
    const std::vector<std::array<metrics::BandError, metrics::kRoughnessBands>>& frames) {
    std::array<double, metrics::kRoughnessBands> out{};
    for (size_t b = 0; b < out.size(); ++b) {
        double sum = 0.0;
        uint64_t pixels = 0;
        for (const auto& f : frames) {
            if (f[b].pixels == 0) continue;
            sum += f[b].flipMean * double(f[b].pixels);
            pixels += f[b].pixels;
        }
        out[b] = pixels ? sum / double(pixels) : std::numeric_limits<double>::quiet_NaN();
    }
    return out;
}

} // namespace

MirrorMotionFrames mirrorMotionFrames(float frameSeconds) {
    if (!(frameSeconds > 0.0f)) throw std::invalid_argument("mirror-motion: the frame time must be positive");
    const scene::MirrorMotionTimeline& t = scene::kMirrorMotion;
    MirrorMotionFrames f;
    const uint32_t start = frameAt(t.objectStartSeconds, frameSeconds);
    for (size_t k = 0; k < f.ghost.size(); ++k) f.ghost[k] = start + kGhostFramesAfter[k];
    f.lag = frameAt(t.cameraStartSeconds, frameSeconds) + kLagFramesAfter;
    // The lamp must still be moving at the last ghost frame and standing at
    // the lag frame.
    if (f.ghost.back() * frameSeconds >= t.objectStopSeconds || f.lag * frameSeconds < t.objectStopSeconds) {
        throw std::invalid_argument("mirror-motion: frame time " + std::to_string(frameSeconds) +
                                    " s does not fit the scene's timeline");
    }
    f.frames = f.lag + 1;
    return f;
}

MirrorReferences renderMirrorReferences(gpu::Context& ctx, const app::ReflectionRunOptions& base,
                                        std::optional<uint32_t> maxFrames, scene::MirrorMotionLamp lamp) {
    MirrorReferences r;
    r.lamp = lamp;
    r.frames = mirrorMotionFrames(base.frameSeconds);
    const app::ReflectionRunOptions options = mirrorOptions(base, r.frames);
    scene::Scene with = scene::makeMirrorMotion(true, lamp);
    scene::Scene without = scene::makeMirrorMotion(false);
    // The camera stands still until the strafe: one image without the lamp
    // serves every ghost frame.
    const metrics::Image still = mirrorReference(ctx, without, options, r.frames.ghost.front(), maxFrames);
    for (const uint32_t frame : r.frames.ghost) {
        r.ghostFloor.emplace_back();
        const metrics::Image image = mirrorReference(ctx, with, options, frame, maxFrames, &r.ghostFloor.back());
        r.ghost.push_back(onFloor(metrics::contribution(image, still), r.ghostFloor.back()));
    }
    mirrorReference(ctx, with, options, r.frames.lag, maxFrames, &r.lagFloor);
    return r;
}

MirrorMetrics measureMirror(gpu::Context& ctx, const app::ReflectionRunOptions& options,
                            const MirrorReferences& references) {
    app::ReflectionRunOptions o = mirrorOptions(options, references.frames);
    o.captureFrames.assign(references.frames.ghost.begin(), references.frames.ghost.end());
    o.captureFrames.push_back(references.frames.lag);
    o.timeEveryFrame = false;
    // The lag frame again, the camera standing at its pose and the scene's
    // time frozen there: where this configuration puts the reflection when
    // nothing moves.
    app::ReflectionRunOptions standing = o;
    standing.frames = kLagStillFrames;
    standing.captureFrames = {kLagStillFrames - 1};
    standing.freezeTime = true;
    standing.startSeconds = float(references.frames.lag) * o.frameSeconds;
    {
        const scene::Scene scene = scene::makeMirrorMotion(true, references.lamp);
        standing.stillPose = app::cameraPoseAt(scene, o, references.frames.lag);
    }
    const auto run = [&](bool withLamp, const app::ReflectionRunOptions& runOptions) {
        scene::Scene scene = scene::makeMirrorMotion(withLamp, references.lamp);
        const app::ReflectionRunResult result = app::runReflections(ctx, scene, runOptions);
        if (result.captures.size() != runOptions.captureFrames.size()) {
            throw std::runtime_error("mirror-motion: " + std::to_string(result.captures.size()) + " of " +
                                     std::to_string(runOptions.captureFrames.size()) + " frames captured");
        }
        std::vector<metrics::Image> images;
        for (const app::FrameCapture& c : result.captures) {
            images.push_back(reflectionTerm(c.resolved, runOptions.width, runOptions.height,
                                            runOptions.frame.composite.exposure,
                                            std::string("mirror-motion ") + (withLamp ? "" : "without lamp ") +
                                                "frame " + std::to_string(c.frame))
                                 .radiance);
        }
        return images;
    };
    const std::vector<metrics::Image> with = run(true, o), without = run(false, o);
    const std::vector<metrics::Image> still = run(true, standing), stillWithout = run(false, standing);
    MirrorMetrics m;
    for (size_t k = 0; k < references.ghost.size(); ++k) {
        const std::vector<uint8_t> inside = metrics::footprint(references.ghost[k], 1e-3f, kGhostEdgePixels);
        m.ghostEnergy[k] = metrics::ghostEnergy(
            references.ghost[k], onFloor(metrics::contribution(with[k], without[k]), references.ghostFloor[k]), inside);
    }
    const size_t lag = references.ghost.size();
    m.lagPixels =
        metrics::lagPixels(onFloor(metrics::contribution(still[0], stillWithout[0]), references.lagFloor),
                           onFloor(metrics::contribution(with[lag], without[lag]), references.lagFloor));
    return m;
}

MotionReferences renderMotionReferences(gpu::Context& ctx, scene::Scene& scene, const MotionSettings& settings) {
    if (settings.pathFrames == 0 || settings.pathCaptures == 0 || settings.pathCaptures > settings.pathFrames ||
        settings.flickerFrames < 2 || settings.flickerFrames > settings.stillFrames) {
        throw std::invalid_argument("--motion: need 1 <= captures <= path frames and 2 <= flicker frames <= still "
                                    "frames");
    }
    MotionReferences r;
    app::ReflectionRunOptions base = settings.base;
    base.frames = settings.pathFrames;
    base.readResolved = true;
    for (uint32_t k = 1; k <= settings.pathCaptures; ++k) {
        r.pathFrames.push_back(settings.pathFrames * k / settings.pathCaptures - 1);
    }
    for (const uint32_t frame : r.pathFrames) {
        const Reference ref = renderReference(ctx, scene, base, settings.referenceMaxFrames, frame);
        r.path.push_back(ref.term);
        r.roughness.push_back(ref.result.roughness);
    }
    r.mirror = renderMirrorReferences(ctx, base, settings.referenceMaxFrames, settings.mirrorLamp);
    return r;
}

MotionRow measureMotion(gpu::Context& ctx, scene::Scene& scene, const MotionSettings& settings,
                        const app::ReflectionRunOptions& options, const MotionReferences& references) {
    const uint32_t w = options.width, h = options.height;
    const float exposure = options.frame.composite.exposure;
    MotionRow row;
    row.width = w;
    row.height = h;

    // 1. Along the path, each captured frame against its own reference.
    app::ReflectionRunOptions path = options;
    path.frames = settings.pathFrames;
    path.readResolved = true;
    path.captureFrames = references.pathFrames;
    const app::ReflectionRunResult moving = runMeasured(ctx, scene, path, settings.warmupFrames);
    row.reflectionMs = moving.reflectionMs;
    std::vector<std::array<metrics::BandError, metrics::kRoughnessBands>> bands;
    double sum = 0.0;
    for (size_t k = 0; k < moving.captures.size(); ++k) {
        const ReflectionTerm t = reflectionTerm(moving.captures[k].resolved, w, h, exposure, "path frame");
        const metrics::FlipResult f = metrics::flip(references.path[k].display, t.display, settings.ppd);
        row.flipPerFrame.push_back(f.stats.mean);
        sum += f.stats.mean;
        bands.push_back(metrics::flipByRoughness(f, references.roughness[k]));
    }
    row.flipMotion = sum / double(row.flipPerFrame.size());
    row.flipBand = pooledBands(bands);

    // 2. A still camera at the path's last pose, the scene's time frozen
    // there: the same reference as the last path frame.
    app::ReflectionRunOptions still = options;
    const uint32_t last = references.pathFrames.back();
    still.stillPose = app::cameraPoseAt(scene, path, last);
    still.startSeconds = options.startSeconds + float(last) * options.frameSeconds;
    still.freezeTime = true;
    still.frames = settings.stillFrames;
    still.timeEveryFrame = false;
    still.captureFrames.clear();
    for (uint32_t k = settings.stillFrames - settings.flickerFrames; k < settings.stillFrames; ++k) {
        still.captureFrames.push_back(k);
    }
    const app::ReflectionRunResult standing = app::runReflections(ctx, scene, still);
    std::vector<metrics::Image> frames;
    for (const app::FrameCapture& c : standing.captures) {
        frames.push_back(reflectionTerm(c.resolved, w, h, exposure, "still frame").display);
    }
    row.flipStill = metrics::flip(references.path.back().display, frames.back(), settings.ppd).stats.mean;
    row.flicker = metrics::flicker(frames);

    // 3. The mirror-motion scene: trails and lag.
    const MirrorMetrics mirror = measureMirror(ctx, options, references.mirror);
    row.ghostEnergy = mirror.ghostEnergy;
    row.lagPixels = mirror.lagPixels;
    return row;
}

} // namespace glint::bench
