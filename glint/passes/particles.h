#pragma once
// Particles in the reflections and in the
// direct view. Two passes on the graphics queue:
//
// The particle trace. For every traced reflection ray - the ray leaders
// of ray generation's SSLR, hybrid and RT pixels, whichever trace resolved
// them - one ray through the BVH update's particle TLAS (three quads per
// particle, one facing each camera axis; the ray's cull mask picks the
// axis its direction is largest along, so it meets each particle once,
// never edge-on: glint/particles_shared.h) from the G-buffer surface along the ray's
// direction, up to the distance integrate will give the pixel's
// reflection: the particle pass reads the same SSLR and RT outputs as
// integrate and makes the same choice (glint/integrate_shared.h's
// chooseReflectionTrace), so it runs before integrate and particles behind
// the reflected surface are not composited. (Reading integrate's hit
// distance instead would put the trace after integrate, which composites
// it.) The trace walks ray generation's two lists, one launch each: the
// SSLR list's leaders, then the RT list's RT pixels (its hybrid entries,
// SSLR's failures, were in the SSLR list), so it costs what the traced
// rays cost: a launch over every pixel paid 0.030 ms at 1080p on the H200
// for the invocations alone, whose pixels trace nothing. It writes the
// leaders' texels only, as the traces do (integrate reads nothing else);
// ParticleTraceSettings::clearUntraced zeroes the rest for the debug view.
// Soft round particles: traversal offers every quad the ray crosses
// (non-opaque geometry, nothing committed), the nearest
// kParticleMaxHits that cover the hit point are kept in a sorted list and
// composited front to back (glint/particles_shared.h): exact up to that
// many overlapping particles, independent of traversal order. Two backends
// with identical results (glint/particles_trace.glsl): ray query in a
// compute shader, or a ray tracing pipeline with ONE hit group (an any-hit
// shader, no closest hit) and an empty miss. Output: RGBA16F, premultiplied
// particle radiance and a = coverage, at ray leaders; integrate composites
// it (IntegrateInputs::particles): particles.rgb + (1 - a) * reflection.
//
// The forward pass. The particles drawn into the G-buffer's lit colour as
// camera-facing billboards (the trace's back-axis quads, the same coverage),
// premultiplied "over" blending, depth-tested against the G-buffer's
// reversed-Z depth without writing it, back to front.
//
// Where the forward pass goes. SSLR samples the lit colour: particles drawn
// into it before SSLR would be reflected twice at SSLR-resolved pixels (by
// SSLR, and by the particle trace, which covers SSLR's rays too), and
// SSLR would see only the particles on screen, lit-colour-deep (no depth),
// smeared onto the surface behind them. So declare the forward pass after
// the last pass that samples lit for reflections (SSLR; its cone-trace
// pyramid included) and before composite, which then adds the reflections
// to a lit colour with the particles in it. Known limitation: composite
// adds a surface's reflection on top of a particle in front of that
// surface without attenuating it by the particle's coverage.
//
//   passes::ParticlePipelines particles(ctx, backend);   // once
//   each frame:
//     const auto bvh = passes::addBvhUpdatePass(graph, bvhManager, plan, camera);
//     ... G-buffer, ray generation, SSLR, RT trace ...
//     std::optional<passes::ParticleTraceOutputs> traced;
//     if (passes::particlesTraced(bvh))            // no particles: no pass
//         traced = passes::addParticleTracePass(graph, particles,
//             {gbuf, rays, sslr, rt.radiance, rt.hitDistance, rtList, rtArgs, bvh, camera},
//             {.confidenceThreshold = ...});
//     integrateInputs.particles = traced ? traced->radiance : rg::Texture{};
//     ... integrate ...
//     const auto lit = passes::addParticleForwardPass(graph, particles, {gbuf, scene.particles, camera});
//     ... composite reads lit.lit instead of gbuf.lit ...

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/bvh_update.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/image_clear.h"
#include "glint/passes/ray_generation.h"
#include "glint/passes/rt_trace.h"
#include "glint/passes/sslr.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include <cstdint>
#include <optional>
#include <span>

namespace glint::passes {

inline constexpr VkFormat kParticleRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

// Whether the BVH update built a particle TLAS this frame, i.e. whether
// the particle trace can (and needs to) run.
inline bool particlesTraced(const BvhUpdateOutputs& bvh) {
    return bvh.particleTlas.valid() && bvh.particles.valid();
}

struct ParticleTraceInputs {
    GBufferOutputs gbuffer;            // depth (SampledRead)
    RayGenerationOutputs rays;         // rays, classes (StorageRead)
    // The traces integrate reads, as given to it: SSLR (absent in "rt"
    // mode) and the ray tracer's radiance and hit distance (both or
    // neither; invalid in "ssr" mode).
    std::optional<SslrOutputs> sslr;
    rg::Texture rtRadiance;
    rg::Texture rtHitDistance;
    // The RT list and its args as the ray tracer walked them (after SSLR's
    // appends: SslrOutputs::rtRayList, rtArgs); absent: rays.rtRays and
    // rays.rtArgs. The trace walks the lists `rays` says are listed
    // (RayGenerationOutputs::sslrListed, rtListed).
    rg::Buffer rtRayList;
    rg::Buffer rtArgs;
    BvhUpdateOutputs bvh;              // particleTlas (AccelRead), particles (StorageRead)
    scene::Camera camera;              // the G-buffer's; unjittered, as integrate reconstructs
    // A hybrid frame the host renders as rt (ReflectionRenderer's SSLR
    // gate): `sslr`, declared but not traced this frame, is not read.
    bool screenSpaceIdle = false;
    // A probe frame that renders as rt (IntegrateInputs::sslrCountsOnly):
    // hybrid pixels' reflections end where the ray tracer's do.
    bool sslrCountsOnly = false;
};

struct ParticleTraceSettings {
    // Auto: the backend ParticlePipelines resolved to; naming the other
    // creates its pipeline on first use (throws where unsupported).
    RtBackend backend = RtBackend::Auto;
    // Integrate's IntegrateInputs::confidenceThreshold: the trace picks
    // the reflection's end as integrate does.
    float confidenceThreshold = kDefaultConfidenceThreshold;
    // How far a ray whose reflection missed (the environment) looks for
    // particles: the BVH's radius (RtTraceInputs::maxDistance).
    float maxDistance = scene::kDefaultBvhRadius;
    // The Far Cry 6 talk's "SSLR particles": the forward pass drew the
    // particles into the lit colour before SSLR sampled it, so a pixel
    // whose reflection integrate takes from SSLR shows the particles SSLR
    // saw there, and the trace skips it (0 written); the trace covers only
    // what the ray tracer and the environment resolve. Each particle
    // reaches a pixel by one road, never both. Cheaper (fewer particle
    // rays), at a cost: SSLR sees a particle only where it is on screen,
    // at the depth of the surface behind it.
    bool sslrSeesParticles = false;
    // Integrate's IntegrateSettings::rtMissesTrusted: the same choice of
    // trace, so the same reflection distance.
    bool rtMissesTrusted = true;
    // Zero the output before the trace, so that texels it does not write
    // (all but the traced rays' leaders) read as "no particles" (the debug
    // view; integrate reads the leaders only and needs no clear).
    bool clearUntraced = false;
};

struct ParticleTraceOutputs {
    // kParticleRadianceFormat: premultiplied particle radiance, a =
    // coverage, at the ray leaders of traced pixels; elsewhere as the
    // memory held it (zero with clearUntraced).
    rg::Texture radiance;
    uint32_t width = 0;
    uint32_t height = 0;
};

struct ParticleForwardInputs {
    GBufferOutputs gbuffer;                     // lit (ColorAttachment), depth (DepthRead)
    std::span<const scene::Particle> particles;  // scene.particles; read while the pass is declared
    scene::Camera camera;                       // the G-buffer's (jittered, as it rasterised)
};

struct ParticleForwardOutputs {
    // The lit colour with the particles blended in: the next version of
    // gbuffer.lit, or gbuffer.lit itself when no particle is in view (then
    // nothing is declared).
    rg::Texture lit;
    uint32_t particles = 0;  // drawn
    uint32_t culled = 0;     // outside the view frustum, not drawn
};

// The pipelines the passes record with; created once. The trace's
// pipeline for `backend` (Auto: ray query where the device has it, else
// the ray tracing pipeline) is created where the device supports one; a
// device with neither can still draw the forward pass, and
// addParticleTracePass throws on it.
class ParticlePipelines {
public:
    explicit ParticlePipelines(gpu::Context& ctx, RtBackend backend = RtBackend::Auto);
    ~ParticlePipelines();
    ParticlePipelines(const ParticlePipelines&) = delete;
    ParticlePipelines& operator=(const ParticlePipelines&) = delete;

    // The backend Auto resolved to (Auto where the device has neither).
    RtBackend backend() const { return backend_; }
    // Whether the device can run the trace with `backend` (Auto: either).
    static bool supported(const gpu::Context& ctx, RtBackend backend);

private:
    friend ParticleTraceOutputs addParticleTracePass(rg::Graph&, ParticlePipelines&, const ParticleTraceInputs&,
                                                     const ParticleTraceSettings&);
    friend ParticleForwardOutputs addParticleForwardPass(rg::Graph&, ParticlePipelines&, const ParticleForwardInputs&);
    RtBackend prepare(RtBackend requested);

    gpu::Context& ctx_;
    RtBackend backend_;
    std::optional<gpu::Pipeline> query_;
    std::optional<gpu::Pipeline> pipeline_;
    std::optional<gpu::ShaderBindingTable> sbt_;
    gpu::Pipeline forward_;
    gpu::Sampler nearest_;
    ImageClearer clearer_;
};

// Declares the particle trace (see the top of this file) on the graphics
// queue: a small upload of its constants, the clear with clearUntraced,
// and the trace. Throws
// gpu::GpuError when inputs.bvh has no particle TLAS (check
// particlesTraced) or the inputs' sizes differ.
ParticleTraceOutputs addParticleTracePass(rg::Graph& graph, ParticlePipelines& pipelines,
                                          const ParticleTraceInputs& inputs, const ParticleTraceSettings& settings = {});

// Declares the forward pass (see the top of this file) on the graphics
// queue: an upload of the particles sorted back to front, and the draw.
ParticleForwardOutputs addParticleForwardPass(rg::Graph& graph, ParticlePipelines& pipelines,
                                              const ParticleForwardInputs& inputs);

} // namespace glint::passes
