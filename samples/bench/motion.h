#pragma once
// glint-bench --motion: reflections in motion, each frame against a
// converged reference of exactly that frame (the scene's time frozen, the
// camera still at that frame's pose):
//   - the scene's camera path with its animated objects: the reflection
//     term's FLIP at a few frames along it (flip_motion, their mean), pooled
//     by the roughness of the reflecting surface too; and a still camera at
//     the path's last pose, time frozen (flip_still, and the flicker of its
//     last frames);
//   - the built-in "mirror-motion" scene (scene::kMirrorMotion): the lamp's
//     trail on the mirror 1, 4 and 16 frames after it starts to move
//     (ghost_energy_*), and how far its reflection lags 16 frames into the
//     camera's strafe behind where the same configuration puts it with the
//     camera standing at that pose (lag_px: the temporal lag alone; what
//     screen-space tracing cannot see of the lamp, e.g. its underside, is a
//     spatial error and is left out).
// The references are rendered once and shared by every configuration.

#include "bench/measure.h"
#include "bench/report.h"
#include "common/reflection_run.h"
#include "glint/gpu/context.h"
#include "glint/metrics/image.h"
#include "glint/metrics/motion_metrics.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/scene.h"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace glint::bench {

// The mirror-motion scene's measured frames at `frameSeconds` per frame:
// 1, 4 and 16 frames after the lamp starts to move, 16 frames after the
// camera starts to strafe, and the frames a run needs.
struct MirrorMotionFrames {
    std::array<uint32_t, 3> ghost{};
    uint32_t lag = 0;
    uint32_t frames = 0;
};
inline constexpr std::array<uint32_t, 3> kGhostFramesAfter = {1, 4, 16};
inline constexpr uint32_t kLagFramesAfter = 16;
inline constexpr uint32_t kLagStillFrames = 48;
// The trail is counted a pixel beyond the reference's footprint: edges a
// pixel off are an edge error, not a trail (metrics::footprint's dilation).
inline constexpr uint32_t kGhostEdgePixels = 1;
MirrorMotionFrames mirrorMotionFrames(float frameSeconds);

// What the lamp contributes to the reference's reflection term at each
// ghost frame (metrics::contribution: the reference with the lamp minus the
// reference without it), and where the floor is at the lag frame.
// Only the floor's pixels count (the reference's roughness in the mirror
// or glossy band): the lamp's own reflection term is not its reflection.
struct MirrorReferences {
    scene::MirrorMotionLamp lamp = scene::MirrorMotionLamp::Rigid;  // how the lamp moves (measureMirror's runs too)
    MirrorMotionFrames frames;
    std::vector<metrics::Contribution> ghost;
    std::vector<std::vector<uint8_t>> ghostFloor;  // per ghost frame: 1 on the floor
    std::vector<uint8_t> lagFloor;
};

// `base` gives the size, the frame time and the backend; its scene time and
// camera are the mirror-motion scene's own.
MirrorReferences renderMirrorReferences(gpu::Context& ctx, const app::ReflectionRunOptions& base,
                                        std::optional<uint32_t> maxFrames,
                                        scene::MirrorMotionLamp lamp = scene::MirrorMotionLamp::Rigid);

struct MirrorMetrics {
    std::array<double, 3> ghostEnergy{};  // metrics::ghostEnergy at kGhostFramesAfter
    // metrics::lagPixels at the lag frame against the same configuration's
    // still camera at that pose (kLagStillFrames frames, time frozen).
    double lagPixels = 0.0;
};

// Runs of the mirror-motion scene with `options` (mode and settings; the
// scene's own time and camera), with the lamp and without: what the lamp
// contributes to their reflection terms against what it contributes to
// the references' (the trail), and the same at the lag frame with the
// camera standing there (the lag).
MirrorMetrics measureMirror(gpu::Context& ctx, const app::ReflectionRunOptions& options,
                            const MirrorReferences& references);

struct MotionSettings {
    // Size, frames along the path (pathFrames below), start time, backend,
    // frame time; the configuration's mode and settings come per run.
    app::ReflectionRunOptions base;
    uint32_t pathFrames = 64;
    uint32_t pathCaptures = 4;     // evenly along the path, the last frame last
    uint32_t stillFrames = 48;     // the still camera's run
    uint32_t flickerFrames = 16;   // its last frames, for the flicker
    double ppd = 0.0;
    std::optional<uint32_t> referenceMaxFrames;
    uint32_t warmupFrames = 0;
    // How the mirror-motion lamp moves (its instance, a joint or a morph
    // target: whose motion reflections must carry).
    scene::MirrorMotionLamp mirrorLamp = scene::MirrorMotionLamp::Rigid;
};

// Every reference a motion run compares with.
struct MotionReferences {
    std::vector<uint32_t> pathFrames;             // the captured frames
    std::vector<ReflectionTerm> path;             // the reflection term at each
    std::vector<std::vector<float>> roughness;    // each reference's roughness (-1: no reflection)
    MirrorReferences mirror;
};

MotionReferences renderMotionReferences(gpu::Context& ctx, scene::Scene& scene, const MotionSettings& settings);

// One configuration (settings.base with the configuration applied, given
// as `options`) measured in motion.
MotionRow measureMotion(gpu::Context& ctx, scene::Scene& scene, const MotionSettings& settings,
                        const app::ReflectionRunOptions& options, const MotionReferences& references);

} // namespace glint::bench
