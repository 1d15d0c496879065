#pragma once
// Runs the reflection frame (passes/reflection_frame.h) over a camera path
// and gathers what the samples report: the last frame's image, per-pass GPU
// times (median over frames), ray and pixel-class counts, BVH stats.
// Shared by glint-render and the benchmark.

#include "glint/gpu/context.h"
#include "glint/graph/types.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include <array>
#include <optional>
#include <span>
#include <string_view>
#include <string>
#include <vector>

namespace glint::app {

// The converged reference: every reflection ray traced (rt mode, no quad reuse,
// no roughness cutoff, unbounded BVH radius and ray length), one new
// sample per pixel per frame from a still camera without jitter,
// accumulated without reprojection or clamping (the temporal pass with an
// unbounded history and no spatial filter) until the image's mean
// reflected radiance changes by less than `tolerance` (relative) over
// `checkEvery` frames, through the same G-buffer and composite.
// Deterministic for a seed: the noise follows the frame index, which
// starts at seed << 20.
struct ReferenceOptions {
    bool enabled = false;
    // The mean converges long before single pixels do: the floor of 128
    // frames keeps per-pixel noise of the glossy pixels down (their
    // standard error falls as 1/sqrt(frames)).
    double tolerance = 2e-4;
    uint32_t checkEvery = 16;
    uint32_t minFrames = 128;
    uint32_t maxFrames = 2048;  // the history length is kept in half floats: exact up to 2048
    uint32_t seed = 0;
};

struct ReflectionRunOptions {
    uint32_t width = 256;
    uint32_t height = 256;
    uint32_t frames = 1;
    float startSeconds = 0.0f;     // time on the scene's camera path of the first frame
    float frameSeconds = 1.0f / 30.0f;
    bool jitter = true;            // sub-pixel jitter (only with more than one frame)
    // Waits for each frame and reads its pass times (else only the last
    // frame's are read).
    bool timeEveryFrame = true;
    // Also reads back the last frame's resolved reflections (the temporal
    // pass's output) into ReflectionRunResult::resolved: the benchmark
    // measures the reflection term's error on it, before the composite.
    bool readResolved = false;
    // Frames (indices from 0) whose resolved reflections and surface
    // roughness are read back into ReflectionRunResult::captures, waiting
    // for each: the per-frame error of a sequence in motion.
    std::vector<uint32_t> captureFrames;
    // Frames (indices from 0) that start with a camera cut besides the
    // first: ReflectionFrameSettings::resetHistory, as an engine sets it.
    std::vector<uint32_t> cutFrames;
    // A still camera at this pose on every frame (else the scene's path).
    std::optional<scene::CameraPose> stillPose;
    // The scene stays at startSeconds on every frame (else it is animated
    // along with the frames). References freeze it.
    bool freezeTime = false;
    // How pass times are taken; none: host-serial on a CPU device (lavapipe's
    // timestamps do not cover compute dispatches), GPU timestamps elsewhere.
    std::optional<rg::PassTimer> passTimer;
    // Skipped passes' barriers carried on to the next pass that runs
    // (rg::Executor::setCarrySkippedBarriers; default on).
    bool carrySkippedBarriers = true;
    passes::ReflectionRendererOptions renderer;
    passes::ReflectionFrameSettings frame;
    ReferenceOptions reference;  // when enabled, `frames` and `mode` are ignored
};

struct PassTime {
    std::string name;
    rg::Queue queue = rg::Queue::Graphics;
    double milliseconds = 0.0;  // median over the frames measured
    double meanMilliseconds = 0.0;  // mean over them (work that runs on some frames only shows here)
    std::optional<double> cpuMilliseconds;  // host-serial timing only: median process CPU time
};

// One frame read back (ReflectionRunOptions::captureFrames).
struct FrameCapture {
    uint32_t frame = 0;
    // Linear resolved reflections, width x height x 4 (as
    // ReflectionRunResult::resolved).
    std::vector<float> resolved;
    // The G-buffer's perceptual roughness per pixel; -1 where no surface
    // reflects (the sky).
    std::vector<float> roughness;
};

struct ReflectionRunResult {
    std::vector<uint8_t> rgba;  // the last frame's output, width x height x 4, sRGB-encoded
    // With ReflectionRunOptions::readResolved: the last frame's resolved
    // reflections, width x height x 4 floats, linear radiance (a > 0 where
    // the pixel has a reflection, else all zero).
    std::vector<float> resolved;
    // The last frame's roughness, as FrameCapture::roughness (with
    // readResolved).
    std::vector<float> roughness;
    std::vector<FrameCapture> captures;  // in frame order
    std::vector<PassTime> passes;
    rg::PassTimer passTimer = rg::PassTimer::GpuTimestamps;  // how `passes` were timed
    std::optional<double> reflectionMs;  // median per-frame sum of the reflection passes
    // Median of the reflection chain (its first pass to its last) timed as
    // one span with no per-pass timestamps: the other half of the frames.
    std::optional<double> reflectionSpanMs;
    // Means of the same: the hybrid's SSLR probe frames (passes/feedback.h)
    // and other work that runs on some frames only count here, not in the
    // medians.
    std::optional<double> reflectionMeanMs;
    std::optional<double> reflectionSpanMeanMs;
    std::optional<double> totalMs;       // median per-frame sum of all passes
    std::optional<double> reflectionCpuMs;  // host-serial timing only: as reflectionMs, in process CPU time
    uint32_t framesTimed = 0;
    // gpu::submitAndWait calls after the first frame (the readbacks included).
    uint64_t blockingSubmits = 0;
    // Median host time from declaring a frame to its completion (with
    // host-serial pass times, including their waits).
    std::optional<double> frameWallMs;
    // The last frame's counts (glint/reflection_frame_shared.h).
    uint64_t sslrRays = 0;
    uint64_t rtRays = 0;
    std::vector<uint64_t> pixelClasses;  // per shader::kPixel*
    // BVH work over all frames, and the last frame's TLAS.
    uint64_t blasBuilt = 0;
    uint64_t blasRebuilt = 0;
    // Frames whose plan was compiled, and those that reused a cached one
    // (rg::PlanCache).
    uint64_t planCompiles = 0;
    uint64_t planReuses = 0;
    uint32_t tlasInstances = 0;
    passes::GBufferStats gbuffer;  // the last frame's
    // The last frame's occlusion cull (shader::kOcclusionStat* words;
    // empty with occlusion culling off).
    std::vector<uint32_t> occlusion;
    passes::RtBackend backend = passes::RtBackend::Auto;
    // The mode the frames were declared in: the options' own, or ssr on a
    // device without ray tracing (passes::ReflectionRenderer::tracesRays).
    passes::ReflectionMode mode = passes::ReflectionMode::Hybrid;
    // Reference runs: frames accumulated, whether the tolerance was met
    // (else maxFrames stopped it), and the last relative change measured.
    uint32_t framesRun = 0;
    // Hybrid frames the host rendered as rt (passes::FeedbackSettings::
    // hostGate), and whether the last frame was one.
    uint32_t screenSpaceIdleFrames = 0;
    bool lastScreenSpaceIdle = false;
    uint32_t lastSslrProbeSpacing = 0;  // ReflectionFrame::sslrProbeSpacing of the last frame
    bool converged = false;
    double lastChange = 0.0;
};

// Frame i's camera: along the scene's path from startSeconds; a path of one
// key (a glTF file's framing view) becomes a slow orbit around its target,
// so temporal passes and motion vectors are exercised deterministically.
scene::CameraPose cameraPoseAt(const scene::Scene& scene, const ReflectionRunOptions& options, uint32_t frame);

// The tunable parameters by name (glint-render --set NAME=VALUE, the
// benchmark's sweeps): what each means is documented at its settings field.
// One tunable setting, stated once: what `--set` and `--list-parameters`,
// the viewer's sliders and the bench's sweeps are all made from.
struct Parameter {
    std::string_view name;
    std::string_view field;  // the settings field it sets, for --help
    // The range the viewer's slider offers; integer for counts and for
    // switches (0 or 1).
    float min = 0.0f;
    float max = 1.0f;
    bool integer = false;
    // The bench's sweep: the values tried (quickSweep with --quick; values
    // equal to the default are skipped), in the modes where the parameter
    // changes the image (hybrid, ssr, rt: passes::ReflectionMode order).
    // Empty: not swept.
    std::vector<double> sweep;
    std::vector<double> quickSweep;
    std::array<bool, 3> sweepModes{};
};
std::span<const Parameter> parameters();
// Sets one parameter; throws std::invalid_argument naming the parameter and
// the value when either is not accepted.
void setParameter(ReflectionRunOptions& options, std::string_view name, std::string_view value);
// "NAME=VALUE[,NAME=VALUE...]" (--set), in order; throws
// std::runtime_error naming --set and the item that is not accepted.
void setParameters(ReflectionRunOptions& options, std::string_view list);
// The parameter's current value.
double getParameter(const ReflectionRunOptions& options, std::string_view name);
// What glint-render --list-parameters prints: a header line, then one line
// a parameter: name, default, range, the modes the bench sweeps it in ("-":
// not swept) and the settings field it sets.
std::string parameterListing();

// Renders options.frames frames of `scene` (which it animates).
ReflectionRunResult runReflections(gpu::Context& ctx, scene::Scene& scene, const ReflectionRunOptions& options);

// The stats JSON glint-render writes (device, mode, size, frames, passes,
// reflection_ms, rays, pixel_classes, bvh).
std::string statsJson(const gpu::Context& ctx, const ReflectionRunOptions& options, const ReflectionRunResult& result);

} // namespace glint::app
