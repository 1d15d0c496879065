#pragma once
// Pass 3 of the reflection pipeline: screen-space reflections.
// One compute pass, dispatched indirectly over ray generation's SSLR ray
// list (one invocation per ray: no work for an empty list), traces each ray
// leader of the SSLR and hybrid pixels across the depth buffer: a linear
// march of large steps with a per-pixel random start offset, then binary
// refinement where the ray may have met a surface (Far Cry 6 talk section
// 3; not at every step of a ray passing behind an occluder,
// shaders/sslr/trace.comp says when). It writes the lit colour at the
// hit, re-lit for the ray's direction (relightHits), and a confidence in
// [0, 1], and lists the hybrid rays below the confidence threshold, with
// indirect args, for the ray-traced pass: it appends them to ray
// generation's RT ray list. The rays ray generation marks for the cone
// trace sample a box-filtered pyramid of the lit colour, built by two
// passes before the trace that run no groups unless such a ray is listed.
// Nothing is cleared: only traced pixels are written, and read.
// Layouts: glint/sslr_shared.h.
//
//   passes::SslrPipelines sslrPipelines(ctx);           // once
//   each frame, after the ray generation:
//     const auto sslr = passes::addSslrPass(graph, sslrPipelines, {gbuf, rays, frame, camera}, {});
//     ... RT: dispatchIndirect(sslr.rtArgs, kRayListDispatchArgsBytes) over sslr.rtRayList ...

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/image_clear.h"
#include "glint/passes/ray_generation.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace glint::passes {

inline constexpr VkFormat kSslrRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kSslrConfidenceFormat = VK_FORMAT_R16_SFLOAT;
// The hit's texel as the uv of its centre. Float32: a half float's 11
// bits put uv a texel off from 2048 pixels across (readers floor uv * size
// to find the hit's depth and motion), and R32G32_SFLOAT is a storage
// format every device has.
inline constexpr VkFormat kSslrHitFormat = VK_FORMAT_R32G32_SFLOAT;

// The Far Cry 6 talk's SSLR confidence threshold; ReflectionFrameSettings
// hands one value to SSLR, integrate and the particle trace.
inline constexpr float kDefaultConfidenceThreshold = 0.9f;

struct SslrInputs {
    GBufferOutputs gbuffer;
    RayGenerationOutputs rays;
    // The frame index ray generation used: it drives the start offsets.
    uint64_t frameIndex = 0;
    // The G-buffer's unjittered camera: world -> view and view -> clip in
    // scene::perspectiveReversedZ's form (the trace inverts it per pixel
    // from four entries; glint/sslr_shared.h).
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    // Hybrid rays below this confidence go to the ray tracer. Compared as
    // the confidence image stores it (sslrStoredThreshold); integrate and
    // the particle trace must compare with the same value.
    float confidenceThreshold = kDefaultConfidenceThreshold;
    // A hybrid frame the host renders as rt (ReflectionRenderer's SSLR
    // gate): ray generation listed no SSLR ray, and the pyramid and the
    // trace are skipped (rg::Builder::skip: still declared, so that the
    // frame keeps its plan, but neither recorded nor given barriers of
    // their own); the RT list stays ray generation's.
    bool screenSpaceIdle = false;
    // A probe frame that renders as rt (FeedbackSettings::probesRenderAsRt):
    // every hybrid ray is handed on to RT, whatever its confidence (which
    // is still stored, for integrate to count).
    bool handEveryRay = false;
};

struct SslrSettings {
    // Large linear steps, then refinement steps: the Far Cry 6 talk's
    // linear-then-refine trace, 64 + 8 by default.
    uint32_t linearSteps = 64;
    uint32_t refineSteps = 8;
    // A ray takes fewer linear steps when its on-screen length has fewer
    // pixels than linearSteps * minStepPixels: steps finer than a pixel
    // read the same depth texels again (the refinement still resolves the
    // crossing below a pixel). The march is a chain of dependent reads, so
    // its latency, not bandwidth, bounds SSLR at low ray counts. 0: always
    // linearSteps. Glint's starting value; the bench sweeps it.
    float minStepPixels = 1.0f;
    // A hit counts when the refined point lies at most this fraction of
    // the surface's view distance behind the depth buffer (which has no
    // thickness of its own; a relative test holds at every distance), or,
    // where more, what the surface's depth changes over half a pixel (seen
    // at a slant, a surface spans that much behind its texel's one depth:
    // shaders/sslr/trace.comp, hitTolerance). Hits fade out from half of
    // it (confidence). Chosen on the bench's plot: 0.02 until 2026-12-07
    // took rays passing just behind thin objects for hits on them, which
    // the plaza's mirrors and glossy street showed in motion
    // (docs/results/log/09-2026-12-07-fourteenth.md); thinner costs time,
    // since rays that stopped there march on and more go to the ray
    // tracer (0.005 took the city's hybrid from 0.79x rt to 0.85x on an
    // H100). 0.01 is the cheapest whose plaza in motion is within 1% of
    // rt's FLIP (docs/results/log/10-2026-12-07-fifteenth.md).
    float thickness = 0.01f;
    // Length of a ray in view units; a ray that meets nothing within it misses.
    float maxDistance = 1000.0f;
    // Confidence fades to zero over this fraction of the image at each
    // border, where neighbouring rays start to leave the screen (FidelityFX
    // SSSR's hit validation fades the same way). Glint's starting value.
    float edgeFade = 0.05f;
    // A hit's lit colour is the surface as the camera sees it; the ray
    // sees it from another side. On, the hit is re-lit for the ray's
    // direction (the sun's specular reflection, the lighting's one term
    // that depends on it, swapped: shaders/sslr/trace.comp, relit), as the
    // ray-traced hits are lit; the cone trace re-lights its hit texel, not
    // the pyramid's wider levels. Off: the lit colour as it is.
    bool relightHits = true;
    // The rays ray generation marks (RayGenerationSettings::coneRoughness)
    // cone-trace over a pyramid of the lit colour; off, every ray marches
    // its own GGX direction and no pyramid is declared.
    bool coneTrace = true;
    // Zero the radiance, confidence and hit images before the trace, so
    // that pixels it does not write read as "no hit" (debug views). The
    // frame's own readers look only at traced pixels and need no clear.
    bool clearUntraced = false;
};

// The confidence threshold as SSLR compares it: the nearest value the
// confidence image (half float) holds. A reader that finds a hybrid ray's
// stored confidence below it knows SSLR handed the ray to the ray tracer
// (glint/sslr_shared.h).
float sslrStoredThreshold(float threshold);

struct SslrOutputs {
    rg::Texture radiance;    // kSslrRadianceFormat: lit colour at the hit, a = hit
    rg::Texture confidence;  // kSslrConfidenceFormat, [0, 1]
    rg::Texture hit;         // kSslrHitFormat: uv of the hit texel's centre (where radiance.a says a hit)
    rg::Buffer rtRayList;    // ray generation's RT ray list with the unresolved hybrid rays appended
    rg::Buffer rtArgs;       // its args (glint/ray_generation_shared.h kRayList*)
    rg::Texture litPyramid;  // the cone trace's colour pyramid (invalid without cone trace; unbuilt without cone rays)
    uint32_t width = 0;
    uint32_t height = 0;
};

// The pipeline and the sampler the pass records with; created once.
class SslrPipelines {
public:
    explicit SslrPipelines(gpu::Context& ctx);

private:
    friend SslrOutputs addSslrPass(rg::Graph&, SslrPipelines&, const SslrInputs&, const SslrSettings&);
    gpu::Context& ctx_;
    gpu::Pipeline trace_;
    gpu::Pipeline pyramidBase_;
    gpu::Pipeline pyramidDown_;
    gpu::Sampler nearest_;
    gpu::Sampler trilinear_;
    ImageClearer clearer_;
};

// Declares the pass (see the top of this file) on the graphics queue.
SslrOutputs addSslrPass(rg::Graph& graph, SslrPipelines& pipelines, const SslrInputs& inputs,
                        const SslrSettings& settings = {});

} // namespace glint::passes
