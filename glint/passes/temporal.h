#pragma once
// Pass 7 of the reflection pipeline: reflection motion, temporal
// accumulation and a spatial filter for rough reflections. Two compute
// passes on the graphics queue, sharing their constants (the upload
// "temporal.constants", rg::addUpload):
//   temporal.accumulate  per pixel: sanitise this frame's radiance (NaN and
//                        Inf never reach the history), reproject through the
//                        reflected (virtual) point at the hit distance and
//                        (moved by the reflected object's own motion) and
//                        through the surface (G-buffer motion), blend the two
//                        by roughness, reject history whose surface differs
//                        (plane, normal, roughness: disocclusions), clip it
//                        to the 3x3 neighbourhood's variance in YCoCg, and
//                        accumulate with weight 1 / history length;
//   temporal.spatial     an edge-aware blur of the accumulation for rough
//                        surfaces, into the resolved image only; its taps
//                        read the surface the accumulation wrote this frame
//                        (view depth, roughness, normal in one texel).
// History lives in two graph history textures (glint/temporal_shared.h);
// the executor ping-pongs them, so two frames in flight are safe. The first
// frame finds them cleared (length 0: no history); resetHistory discards
// them on a camera cut. The pairs are named by the image size, so a graph
// holds one temporal pass per size.
//
//   passes::TemporalPipelines temporalPipelines(ctx);  // once
//   each frame, after the integrate pass:
//     const auto stable = passes::addTemporalPass(graph, temporalPipelines,
//         {gbuf, refl.radiance, refl.hitDistance, camera, frame, cut}, settings.temporal);
//     ... composite reads stable.resolved ...

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/gbuffer.h"
#include "glint/scene/camera.h"

#include <cstdint>

namespace glint::passes {

inline constexpr VkFormat kTemporalResolvedFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kTemporalMotionFormat = VK_FORMAT_R16G16_SFLOAT;
inline constexpr VkFormat kTemporalHistoryLengthFormat = VK_FORMAT_R16_SFLOAT;
// Half floats, rounded stochastically by the accumulation: at a weight of
// 1/64 per frame, rounding to nearest would stall the average up to 32 of
// a half float's steps (2^-11 to 2^-10 relative) from the mean (64 where
// stores round towards zero, as Vulkan allows for 16-bit floats), a bias of
// 2-6%, visible as darkening. The shader stores one of the two half floats
// around each value, the upper with probability proportional to the
// distance from the lower, so the stored value's mean is the value itself
// and no rounding mode applies (shaders/temporal/accumulate.comp). Half the
// bytes of RGBA32F for every history tap and spatial filter tap.
inline constexpr VkFormat kTemporalRadianceHistoryFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kTemporalSurfaceHistoryFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

struct TemporalInputs {
    GBufferOutputs gbuffer;   // depth, normal, roughnessMetal, motion
    // Reflection radiance (any float format), a > 0 where a surface
    // reflects; a = shader::kReflectsNoiseFree where this frame's value
    // carries no ray's noise (IntegrateOutputs::radiance: the SSLR cone
    // trace's hits).
    rg::Texture radiance;
    rg::Texture hitDistance;  // r: distance to the reflected hit; >= shader::kMissHitDistance: at infinity
    // This and last frame's unjittered matrices and positions (the
    // G-buffer's camera).
    scene::Camera camera;
    // The frame's index: the history's stochastic rounding draws its noise
    // from it (glint/sampling.glsl's kNoiseHistoryRounding).
    uint64_t frameIndex = 0;
    // Discard the history (a camera cut, a teleport, a new scene).
    bool resetHistory = false;
    // Optional: xyz, where the reflected point was last frame minus where it
    // is (world units; IntegrateOutputs::hitMotion). A moving object's
    // reflection is reprojected with it; without it reflected points count
    // as still and only the camera's motion reprojects.
    rg::Texture hitMotion;
    // Perceptual roughness from which neighbouring pixels share rays (ray
    // generation's RayGenerationSettings::reuseRoughness with its reuse on;
    // 0 with its checkerboard; above 1: nowhere): there the clip box spans
    // TemporalSettings::clampRadius.
    float sharedRayRoughness = 2.0f;
    // Perceptual roughness above which a pixel reflects the environment
    // map alone (ray generation's RayGenerationSettings::roughnessCutoff;
    // above 1: nowhere). Such a pixel traces no ray: its radiance has no
    // noise and follows its normal smoothly. Its history is taken wherever
    // last frame's holds a finite one, without the surface tests (which
    // rejected it at every edge the jitter moves across, leaving those
    // pixels unaccumulated, i.e. aliased: on the plaza at 1080p FLIP 0.0617
    // -> 0.0603 in hybrid, in motion 0.2900 -> 0.2868,
    // docs/results/log/05-2026-12-06-a.md),
    // and its clip box is 3x3 (it shares no rays), which is what bounds a
    // disocclusion's ghost there.
    float environmentRoughness = 2.0f;
    // Write TemporalOutputs::reflectionMotion and historyLength (their
    // debug views, tests). Off, nothing writes them and the outputs are
    // invalid handles: 6 bytes a pixel the frame does not store (the
    // reflection frame turns them on for their debug views only).
    bool debugOutputs = true;
};

struct TemporalSettings {
    // The longest history, in frames: a new frame's weight never drops
    // below 1 / maxHistoryFrames. 64 (was 32) from glint-bench --motion on
    // the plaza at 1080p (docs/results/log/03-2026-12-03-04.md): with the 5x5 clamp it flickers
    // a sixth less than 32 at the same FLIP in motion, and the clamp keeps
    // it from lagging (trails stay under 1% of the object's energy).
    float maxHistoryFrames = 64.0f;
    // Variance clipping in YCoCg over the 3x3 neighbourhood, to
    // mean +- clampGamma * sigma (Salvi, GDC 2016, suggests gamma near 1;
    // the little extra keeps single-ray noise from clipping a converged
    // history every frame).
    bool neighbourhoodClamp = true;
    float clampGamma = 1.25f;
    // The neighbourhood's radius where quads share rays
    // (TemporalInputs::sharedRayRoughness and above): (2 r + 1)^2 pixels, at
    // most shader::kTemporalMaxClampRadius; elsewhere 3x3 (Salvi's). Where
    // quads share one ray a 3x3 window holds only two to four independent
    // samples, and a box estimated from so few jumps from frame to frame
    // and drags the history with it: on the plaza at 1080p 5x5 there halves
    // the flicker of 3x3 (glint-bench --motion, docs/results/log/03-2026-12-03-04.md); where
    // every pixel has its own ray 5x5 only admits more stale history in
    // motion (DamagedHelmet: FLIP in motion +9%).
    uint32_t clampRadius = 2;
    // History rejection: a history texel counts only if last frame's
    // surface there lies within planeTolerance x view depth of this pixel's
    // tangent plane, its normal within acos(normalTolerance) and its
    // roughness within roughnessTolerance (at pixels that trace rays:
    // TemporalInputs::environmentRoughness). Glint's starting values: 2%
    // passes 16-bit depth and motion rounding at every distance and rejects
    // any object a visible distance in front.
    float planeTolerance = 0.02f;
    float normalTolerance = 0.9f;  // ~26 degrees
    float roughnessTolerance = 0.1f;
    // Reflection motion: mirrors follow the virtual point, surfaces from
    // start to end blend towards the surface motion (a rough reflection is
    // a blur of many directions and moves with its surface). Glint's
    // starting values, set around ray generation's first quad-reuse
    // roughness (0.1).
    float surfaceMotionRoughnessStart = 0.1f;
    float surfaceMotionRoughnessEnd = 0.3f;
    // On: every pixel looks its history up once, at the blended motion (the
    // reflected point's for a mirror, the surface's from the end roughness
    // on), and at the surface's motion alone where that finds nothing (a
    // disocclusion). Off: between those roughnesses the history is looked
    // up at both motions and the two histories blended (each a bilinear
    // lookup of four taps, two texels a tap): twice the reads there, and
    // warps that hold glossy pixels beside others run both ways. On an H100
    // at 1080p the accumulation 0.1141 -> 0.1002 ms in the city, 0.0916 ->
    // 0.0865 on the plaza, for FLIP +0.09% on the plaza (hybrid 0.060277 ->
    // 0.060331), +0.003% in the city's hybrid, +0.9% in its rt; in motion
    // +0.02-0.03%, flicker unchanged
    // (docs/results/log/08-2026-12-07-thirteenth.md).
    bool oneHistoryCandidate = true;
    // Radiance is clamped to [0, maxRadiance] before it is accumulated: the
    // largest half float, so neither the RGBA16F history nor the resolved
    // image overflows to Inf.
    float maxRadiance = 65504.0f;
    // The spatial filter: a (2 radius + 1)^2 edge-aware Gaussian, off below
    // spatialRoughnessStart (mirrors need none), full from
    // spatialRoughnessEnd. Radius 0 turns it off; at most
    // shader::kTemporalMaxSpatialRadius. Glint's starting values: rays are
    // traced up to the roughness cutoff and are noisiest there.
    uint32_t spatialRadius = 2;
    float spatialRoughnessStart = 0.1f;
    float spatialRoughnessEnd = 0.2f;
    // Tap weights: exp(-plane distance / (spatialPlaneSigma x view depth)),
    // max(N.Ntap, 0)^spatialNormalPower, exp(-|roughness difference| /
    // spatialRoughnessSigma). SVGF's normal power (Schied et al., HPG 2017).
    float spatialPlaneSigma = 0.01f;
    float spatialNormalPower = 128.0f;
    float spatialRoughnessSigma = 0.05f;
    // Pixels rougher than this are not filtered: above ray generation's
    // roughness cutoff a pixel takes the environment, which has no noise to
    // remove (the frame passes its cutoff; on the plaza that skips the 5x5
    // filter on over half the pixels).
    float spatialRoughnessMax = 1.0f;
    // The filter's radius at pixels whose radiance this frame is
    // noise-free (TemporalInputs::radiance's a = shader::kReflectsNoiseFree:
    // the SSLR cone trace's hits, which the colour pyramid has already
    // blurred by the lobe), where it is below spatialRadius; 0 (default):
    // those pixels are not filtered. On an H100 at 1080p
    // (docs/results/log/07-2026-12-07.md, eleventh session) 0 takes the
    // filter from 0.075 to 0.036 ms in the city of 1,024 buildings, where
    // most filtered pixels are such hits (0.044 -> 0.038 on the plaza), at
    // the same FLIP (+0.1%), for 13% more flicker there at cone roughness
    // 0.1 (1: 0.051 ms, +4%).
    uint32_t spatialNoiseFreeRadius = 0;
};

struct TemporalOutputs {
    rg::Texture resolved;          // kTemporalResolvedFormat: reflections after both passes, a = 1 where they exist
    // With TemporalInputs::debugOutputs (else invalid):
    rg::Texture reflectionMotion;  // kTemporalMotionFormat: pixels to last frame (debug view "reflection_motion")
    rg::Texture historyLength;     // kTemporalHistoryLengthFormat: frames, 0 = none (debug view "history_length")
    uint32_t width = 0;
    uint32_t height = 0;
};

// The pipelines and the sampler the pass records with; created once.
class TemporalPipelines {
public:
    explicit TemporalPipelines(gpu::Context& ctx);

private:
    friend TemporalOutputs addTemporalPass(rg::Graph&, TemporalPipelines&, const TemporalInputs&,
                                           const TemporalSettings&);
    gpu::Context& ctx_;
    gpu::Pipeline accumulate_;
    gpu::Pipeline spatial_;
    gpu::Sampler nearest_;
};

// Declares the passes (see the top of this file) on the graphics queue.
TemporalOutputs addTemporalPass(rg::Graph& graph, TemporalPipelines& pipelines, const TemporalInputs& inputs,
                                const TemporalSettings& settings = {});

} // namespace glint::passes
