#pragma once
// Pass 2 of the reflection pipeline: ray generation and tile
// classification. One compute pass reads the G-buffer and, per pixel,
//   - classifies it: sky (no ray), env (rougher than the cutoff: the
//     environment map, no ray), RT (near), SSLR (far, beyond the BVH) or
//     hybrid (between; the feedback counters decide later);
//   - draws one reflection direction from GGX visible normals (Heitz 2018)
//     with per-pixel, per-frame low-discrepancy noise (glint/sampling.glsl);
//   - on rough quads, shares one ray per 2x2 quad (the leader rotates with
//     the frame);
// and lists the ray leaders of the SSLR and hybrid pixels in the SSLR ray
// list and those of the RT pixels in the RT ray list (which SSLR extends
// with the hybrid rays it cannot resolve), each with args for a compute
// dispatch and for vkCmdTraceRaysIndirectKHR. Layouts:
// glint/ray_generation_shared.h.
//
//   passes::RayGenerationPipelines pipelines(ctx);     // once
//   each frame, after the G-buffer:
//     const auto rays = passes::addRayGenerationPass(graph, pipelines, {gbuf, frame, camera}, {});
//     ... SSLR: dispatchIndirect(rays.sslrArgs, kRayListDispatchArgsBytes) over rays.sslrRays ...

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/gbuffer.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/camera.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace glint::passes {

// Byte offsets of a ray list's compute dispatch and trace-rays commands in
// its args (RayGenerationOutputs::sslrArgs, rtArgs).
inline constexpr VkDeviceSize kRayListDispatchArgsBytes = 0;
inline constexpr VkDeviceSize kRayListTraceArgsBytes = 3 * sizeof(uint32_t);

// Which trace resolves a pixel's reflection: SSLR first and the ray
// tracer where it has no confidence, SSLR only, or the ray tracer only.
enum class ReflectionMode : uint32_t { Hybrid, Ssr, Rt };

inline constexpr VkFormat kRayClassDebugFormat = VK_FORMAT_R8G8B8A8_UNORM;

struct RayGenerationInputs {
    GBufferOutputs gbuffer;
    // Drives all noise: the same index, the same rays.
    uint64_t frameIndex = 0;
    // This frame's unjittered matrices and position; the G-buffer's camera.
    scene::Camera camera;
    // The feedback pass's tile modes (u32 per tile, glint/feedback_shared.h)
    // for the hybrid band; without them (invalid) hybrid pixels stay hybrid.
    rg::Buffer tileModes;
    // The frame's mode: which classes a pixel may take.
    ReflectionMode mode = ReflectionMode::Hybrid;
    // Pixels at or beyond this distance from the camera go to SSLR only:
    // the BVH holds nothing farther (ReflectionFrameSettings::reach; Far
    // Cry 6: 100 around the camera).
    float sslrMinDistance = scene::kDefaultBvhRadius;
    // A hybrid frame the host renders as rt (ReflectionRenderer's SSLR
    // gate, FeedbackSettings::hostGate): every traced pixel goes to RT, as
    // in rt mode, and `tileModes`, still declared so that the frame keeps
    // its plan, is not read.
    bool screenSpaceIdle = false;
    // Write RayGenerationOutputs::classDebug (its debug view, tests). Off,
    // nothing writes it and the output is an invalid handle: 4 bytes a
    // pixel the frame does not store (the reflection frame turns it on for
    // its debug view only).
    bool debugOutputs = true;
};

struct RayGenerationSettings {
    // Perceptual roughness above which a pixel takes the environment map
    // and traces nothing. 0.3 from glint-bench --motion at 1080p
    // (docs/results/log/03-2026-12-03-04.md): against FidelityFX Hybrid
    // Reflections' 0.22 it lowers FLIP in motion 2.4% on the plaza and 6%
    // on DamagedHelmet for 0.02 ms; 0.5 lowers it further but, every rough
    // pixel traced with one ray, flickers more than the target allows.
    float roughnessCutoff = 0.3f;
    // Perceptual roughness from which a 2x2 quad shares one ray. 0.15 from
    // glint-bench --motion at 1080p (docs/results/log/03-2026-12-03-04.md):
    // against the starting value 0.1 (alpha 0.01, a lobe of a few degrees)
    // it lowers FLIP in motion 2.5% on DamagedHelmet and 0.2% on the plaza
    // and flicker 9-20%, for 0.007-0.035 ms; 1 (never shared) is a little
    // more accurate again for twice that cost.
    float reuseRoughness = 0.15f;
    bool reuse = true;
    // Half-rate rays on the smooth hybrid and RT pixels: on a checkerboard
    // that swaps every frame, the pixels of the off squares share their
    // row neighbour's ray (FidelityFX Hybrid Reflections' checkerboarded
    // hybrid tiles); temporal accumulation sees each pixel's own ray every
    // other frame. Off by default until the bench's plot shows it on the
    // Pareto front.
    bool checkerboard = false;
    // Pixels nearer than this (world units from the camera) go straight to
    // RT. Glint's starting value (the talk gives none): near reflections
    // are where SSLR most often leaves the screen. Measured on the plaza
    // (1080p, NVIDIA): at 10 units half the floor (14% of all pixels) went
    // straight to RT and hybrid traced 93% of rt mode's rays; at 3 units
    // only the player's arm and what is at arm's length does, and the
    // feedback decides the floor. The bench sweeps it (rt_near_distance).
    float rtMaxDistance = 3.0f;
    // SSLR and hybrid pixels at least this rough (perceptual) cone-trace in
    // SSLR: they march the mirror direction and sample a box-filtered
    // pyramid of the lit colour at the GGX lobe's footprint, noise-free,
    // instead of the lit colour at one stochastic ray's hit (the talk's
    // "fast cone trace for rough tiles"; SslrSettings::coneTrace turns it
    // off). Ray generation marks those rays (kRayCone) and opens SSLR's
    // pyramid passes only when it lists one, so a frame without builds no
    // pyramid. Its hits are noise-free, and the spatial filter leaves them
    // alone (TemporalSettings::spatialNoiseFreeRadius). 0.05 (was 0.1)
    // from glint-bench on an H100 at 1080p with that filter
    // (docs/results/log/07-2026-12-07.md, eleventh session): in the city of
    // 1,024 buildings 0.002-0.004 ms faster, as accurate still and in motion,
    // and 13% less flicker, which is what leaving the hits unfiltered had
    // cost; 1 (no cone trace) flickers 4.5x as much there, 22% more on
    // the plaza.
    float coneRoughness = 0.05f;
    // Share of the hybrid-band pixels of a tile the feedback sends to RT that
    // stay hybrid (tried with SSLR first) this frame, so that the tile's
    // counters keep seeing SSLR and it can return to SSLR (Far Cry 6
    // talk). Glint's starting value; the bench sweeps it.
    float rtToHybridShare = 1.0f / 16.0f;
    // Where the random numbers of ray generation (the GGX samples, the
    // pixels kept hybrid) and of SSLR (its start offsets, which follow this
    // choice through RayGenerationOutputs) come from, each use its own
    // dimension (glint/sampling.glsl): spatiotemporal blue noise
    // (glint/sampling/blue_noise.h), blue in space and over a pixel's
    // frames, so that the temporal filter averages out the error faster;
    // false: per-pixel hashed low-discrepancy sequences (R2 for the GGX
    // sample, a Weyl sequence for each other use). The bench compares both.
    bool blueNoise = true;
    // Hybrid mode: every pixel that would be traced alone (nearer than
    // rtMaxDistance, or in a tile the feedback sends to RT) tries SSLR
    // first. Set by ReflectionRenderer while the BVH is still building
    // objects in range (scene::BvhPlan::complete), so that their
    // reflections come from SSLR rather than from rays that pass through.
    bool sslrFirst = false;
};

struct RayGenerationOutputs {
    rg::Buffer rays;          // shader::PackedRay per pixel
    rg::Buffer classes;       // uint per pixel: shader::kPixel*
    rg::Buffer sslrRays;      // SSLR ray list: shader::PackedRay per SSLR/hybrid ray leader (capacity: one per pixel)
    rg::Buffer sslrArgs;      // shader::kSslrArgsWords: dispatch at kRayListDispatchArgsBytes, SSLR's pyramid after it
    rg::Buffer rtRays;        // RT ray list: shader::PackedRay per RT ray leader (capacity: one per pixel)
    rg::Buffer rtArgs;        // shader::kRayListArgsWords: dispatch at kRayListDispatchArgsBytes, trace at kRayListTraceArgsBytes
    // kRayClassDebugFormat: a colour per class (debug view "ray_classes");
    // with RayGenerationInputs::debugOutputs, else invalid.
    rg::Texture classDebug;
    // Whether each list can hold entries this frame: ssr mode lists nothing
    // for RT (SSLR's failures take the environment), rt mode and a frame
    // the gate renders as rt nothing for SSLR. A pass that walks a list
    // that cannot would pay an empty launch.
    bool sslrListed = true;
    bool rtListed = true;
    // Whether the rays were drawn from the blue noise, and its buffer
    // (owned by RayGenerationPipelines, uploaded once when they were
    // created and never written again, so no pass needs to order itself
    // against it): SSLR draws its start offsets the same way.
    bool blueNoise = false;
    const gpu::Buffer* blueNoiseBuffer = nullptr;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t tilesX = 0;
    uint32_t tilesY = 0;
};

// The pipeline, the sampler and the blue noise the pass records with;
// created once. The blue noise is read from "noise/blue_noise.bin" beside
// the shaders (gpu::shaderDirectory(); the build generates it) and
// uploaded to a device-local buffer; a missing or mismatched file throws
// gpu::GpuError naming it.
class RayGenerationPipelines {
public:
    explicit RayGenerationPipelines(gpu::Context& ctx);

    const gpu::Buffer& blueNoise() const { return blueNoise_; }

private:
    friend RayGenerationOutputs addRayGenerationPass(rg::Graph&, RayGenerationPipelines&, const RayGenerationInputs&,
                                                     const RayGenerationSettings&);
    gpu::Context& ctx_;
    gpu::Pipeline classify_;
    gpu::Sampler nearest_;
    gpu::Buffer blueNoise_;
};

// The blue noise file the passes read, and its texels as the shaders
// index them (uvec2 per texel: glint/sampling.glsl's blueNoise*). Throws
// gpu::GpuError naming the file when it is missing or not the size and
// channels the shaders expect.
std::filesystem::path blueNoisePath();
std::vector<uint32_t> loadBlueNoiseWords();

// Declares the pass (see the top of this file) on the graphics queue.
RayGenerationOutputs addRayGenerationPass(rg::Graph& graph, RayGenerationPipelines& pipelines,
                                          const RayGenerationInputs& inputs,
                                          const RayGenerationSettings& settings = {});

} // namespace glint::passes
