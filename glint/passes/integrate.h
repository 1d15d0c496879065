#pragma once
// Pass 5 of the reflection pipeline: integrate. One compute pass
// over every pixel picks where its reflection comes from:
//   sky                        nothing (radiance 0, a = 0)
//   env class (too rough)      the environment map
//   SSLR confidence >= threshold   SSLR alone
//   below it                   the more confident trace: RT where it traced
//                              (its miss is the true environment, so it is
//                              fully confident), else SSLR where it found
//                              anything, else the environment map
// The environment map is environmentRadiance(lighting, reflect(-V, N),
// roughness) (glint/brdf.glsl), the one the hit shaders' misses use. A
// follower pixel of a shared quad ray reads its leader's traces. It also
// counts each tile's SSLR hits and misses over the traced SSLR/hybrid rays
// and writes the tile's feedback counter (glint/feedback_shared.h), this
// frame's counts with the reprojected counts rotated behind them.
// Layouts: glint/integrate_shared.h.
//
//   passes::IntegratePipelines integratePipelines(ctx);    // once
//   each frame, after SSLR and the ray tracer:
//     const auto refl = passes::addIntegratePass(graph, integratePipelines,
//         {gbuf, rays, sslr, rt.radiance, rt.hitDistance, feedback, lighting, camera}, {});
//     ... temporal accumulation reads refl.radiance and refl.hitDistance ...
//
// With IntegrateInputs::particles the particle trace is composited in
// front of each traced pixel's reflection (see there).
//
// Frames without SSLR ("rt" mode) or without the ray tracer ("ssr" mode)
// leave those inputs empty, and a frame without the feedback pass leaves
// IntegrateInputs::feedback default (then no counters are written and
// IntegrateOutputs::counters is invalid); the pass runs a shader variant
// that neither declares nor binds what is absent.

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/feedback.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/ray_generation.h"
#include "glint/passes/sslr.h"
#include "glint/scene/camera.h"

#include "glint/gbuffer_shared.h"

#include <array>
#include <cstdint>
#include <optional>

namespace glint::passes {

inline constexpr VkFormat kReflectionRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kReflectionHitDistanceFormat = VK_FORMAT_R32_SFLOAT;
inline constexpr VkFormat kReflectionHitMotionFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kReflectionSourceDebugFormat = VK_FORMAT_R8G8B8A8_UNORM;

struct IntegrateInputs {
    GBufferOutputs gbuffer;
    RayGenerationOutputs rays;         // classes, rays (pixelFlags name a follower's leader)
    std::optional<SslrOutputs> sslr;   // absent in "rt" mode
    // The ray tracer's outputs, both or neither (invalid in "ssr" mode):
    // RGBA16F radiance, a = 1 where traced (at ray leaders); R32F hit distance.
    rg::Texture rtRadiance;
    rg::Texture rtHitDistance;
    FeedbackOutputs feedback;          // reprojected in, counters.current out
    // Optional: the particle trace's radiance (passes/particles.h,
    // ParticleTraceOutputs::radiance: RGBA16F, premultiplied rgb, a =
    // coverage, at ray leaders; the G-buffer's size). Where valid, every
    // traced pixel's reflection becomes
    //   particles.rgb + (1 - particles.a) * reflection
    // (its leader's particles, as for the traces); the hit distance stays
    // the reflected surface's.
    rg::Texture particles;
    shader::SceneLighting lighting;    // EnvironmentMap::lighting or passes::sceneLighting(...)
    // The prefiltered environment (passes/environment.h, SampledRead);
    // needed when `lighting` looks up an image, else left invalid.
    rg::Texture environment;
    scene::Camera camera;              // the G-buffer's; its unjittered matrices rebuild positions
    // SSLR confidence at which SSLR alone is trusted, and at which a traced
    // ray counts as a hit in the feedback counters. It must be SSLR's
    // (SslrInputs::confidenceThreshold), which lists the hybrid rays below
    // it for the ray tracer: the RT outputs are read only where the stored
    // SSLR confidence is below it (compared, as SSLR does, at
    // sslrStoredThreshold), since nothing clears the traces' outputs.
    float confidenceThreshold = kDefaultConfidenceThreshold;
    // Optional, with them: the ray tracer's hit motion (RtTraceOutputs::
    // hitMotion); without it the traced hits count as still.
    rg::Texture rtHitMotion;
    // A hybrid frame the host renders as rt (ReflectionRenderer's SSLR
    // gate): rt mode's variant runs, reading neither `sslr` nor the
    // feedback and writing no counters; both stay declared, so that the
    // frame keeps its plan.
    bool screenSpaceIdle = false;
    // A probe frame that renders as rt (FeedbackSettings::probesRenderAsRt:
    // SSLR handed every ray on): SSLR's hits are counted into the feedback,
    // and the reflection is the ray tracer's, as in rt mode.
    bool sslrCountsOnly = false;
    // Write IntegrateOutputs::sourceDebug (its debug view, tests). Off,
    // nothing writes it and the output is an invalid handle: 4 bytes a
    // pixel the frame does not store (the reflection frame turns it on for
    // its debug view only).
    bool debugOutputs = true;
};

struct IntegrateSettings {
    // Whether a ray-traced miss may override a partial SSLR hit. False
    // while the BVH is still building objects in range
    // (scene::BvhPlan::complete; ReflectionRenderer sets it per frame): a
    // miss may have passed where an unbuilt object stands, and the SSLR hit
    // may be that object. SSLR is the fallback while the BVH builds (the
    // Far Cry 6 talk).
    bool rtMissesTrusted = true;
};

struct IntegrateOutputs {
    rg::Texture radiance;     // kReflectionRadianceFormat: reflected radiance, a > 0 where a surface reflects,
                              // a = kReflectsNoiseFree where it is a cone trace's hit (glint/integrate_shared.h)
    rg::Texture hitDistance;  // kReflectionHitDistanceFormat: world units; kMissHitDistance for env/miss/sky
    // kReflectionHitMotionFormat: xyz, where the reflected point was last
    // frame minus where it is (world units): a ray-traced hit's instance
    // motion, an SSLR hit's G-buffer motion at the hit (at the view depth
    // last frame's camera gives it); zero at infinity.
    rg::Texture hitMotion;
    // kReflectionSourceDebugFormat: a colour per source (debug view
    // "reflection_source"); with IntegrateInputs::debugOutputs, else invalid.
    rg::Texture sourceDebug;
    rg::Buffer counters;      // the new version of feedback.counters.current (invalid without feedback)
    uint32_t width = 0;
    uint32_t height = 0;
};

// The pipelines (one variant per combination of present traces) and the
// sampler the pass records with; created once.
class IntegratePipelines {
public:
    explicit IntegratePipelines(gpu::Context& ctx);

private:
    friend IntegrateOutputs addIntegratePass(rg::Graph&, IntegratePipelines&, const IntegrateInputs&,
                                             const IntegrateSettings&);
    gpu::Context& ctx_;
    // Indexed by (SSLR bound) | (RT bound) << 1 | (feedback bound) << 2.
    std::array<gpu::Pipeline, 8> variants_;
    gpu::Sampler nearest_;
    gpu::Sampler environmentSampler_;
};

// Declares the pass (see the top of this file) on the graphics queue, with
// a small transfer pass before it that uploads the frame's constants.
IntegrateOutputs addIntegratePass(rg::Graph& graph, IntegratePipelines& pipelines, const IntegrateInputs& inputs,
                                  const IntegrateSettings& settings = {});

} // namespace glint::passes
