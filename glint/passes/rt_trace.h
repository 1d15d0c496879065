#pragma once
// Pass 4 of the reflection pipeline: ray-traced hits and
// lighting. Traces the rays of the RT ray list (glint/ray_generation_shared.h,
// kRayList*: ray generation's RT pixels and the hybrid rays SSLR could not
// resolve) through the BVH update's TLAS, dispatched indirectly from the
// list's args, so only listed rays cost anything. Per ray:
//   - the origin is the G-buffer surface at the entry's pixel (the quad
//     leader's for shared rays; the integrate pass resolves the followers),
//     moved off the surface along its normal by an offset that scales with
//     the position's magnitude (Wächter and Binder, Ray Tracing Gems ch. 6)
//     and with the depth reconstruction's error (the rasteriser's
//     sub-pixel snapping included);
//   - its length is maxDistance (the BVH's radius), shrinking as the
//     surface's roughness grows (Far Cry 6 talk);
//   - a hit reads its triangle from the packed primitive pool through the
//     primitive offset buffer, interpolates it at the barycentrics and
//     lights it as the G-buffer lights its surfaces (glint/brdf.glsl's
//     shadeSurface), the sun's visibility from the G-buffer's shadow map
//     where it covers the hit, else from a shadow ray
//     (RtTraceSettings::shadowMapAtHits), plus its
//     geometry's emission (the BVH's material rows);
//   - both rays pass through the cut-outs of alpha-tested geometry
//     (glint/rt_geometry.glsl, passes/bvh_hit_materials.h);
//   - a miss takes the environment (glint/brdf.glsl's environmentRadiance).
// Two backends with bit-identical results (one shared GLSL file,
// glint/rt_trace.glsl): ray query in a compute shader (its candidate loop
// runs the alpha test), or a ray tracing pipeline with one hit group (a
// closest-hit shader, and an any-hit shader for the alpha test) and an
// empty miss shader (NVIDIA has no ray query). Layouts:
// glint/rt_trace_shared.h.
//
//   passes::RtTracePipelines rtPipelines(ctx);          // once
//   each frame, after SSLR (which completes the RT list):
//     const auto rt = passes::addRtTracePass(graph, rtPipelines,
//         {gbuf, rays.rtRays, rays.rtArgs, bvh, passes::sceneLighting(scene, gbufSettings.lighting), camera, frame});
//     ... integrate reads rt.radiance, rt.hitDistance and rt.hitMotion ...

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/bvh_update.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/image_clear.h"
#include "glint/scene/camera.h"

#include "glint/gbuffer_shared.h"

#include <cstdint>
#include <optional>

namespace glint::passes {

inline constexpr VkFormat kRtRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kRtHitDistanceFormat = VK_FORMAT_R32_SFLOAT;
inline constexpr VkFormat kRtHitMotionFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

// Auto: ray query where the device has it (one compute dispatch, no shader
// binding table), else the ray tracing pipeline.
enum class RtBackend { Auto, RayQuery, Pipeline };
const char* rtBackendName(RtBackend backend);

struct RtTraceInputs {
    GBufferOutputs gbuffer;          // depth, normal, roughnessMetal read (SampledRead)
    rg::Buffer rayList;              // shader::PackedRay entries (glint/ray_generation_shared.h)
    rg::Buffer rayListArgs;          // kRayListArgsWords uints, layout in ray_generation_shared.h (IndirectArgs)
    // tlas (AccelRead); primitivePool, primitiveOffsets, materials,
    // alphaTriangles (StorageRead); alphaMasks (SampledRead).
    BvhUpdateOutputs bvh;
    shader::SceneLighting lighting;  // EnvironmentMap::lighting or passes::sceneLighting(scene, gbufferSettings.lighting)
    // The G-buffer's camera. Origins are reconstructed with the jittered
    // matrices it was rasterised with (passes/rt_trace.cpp says why).
    scene::Camera camera;
    // The trace draws no random numbers (the rays carry ray generation's
    // noise); kept so every pass of a frame is declared alike.
    uint64_t frameIndex = 0;
    // The prefiltered environment (passes/environment.h, SampledRead) for
    // misses and the hits' ambient light; needed when `lighting` looks up an
    // image, else left invalid.
    rg::Texture environment;
    // Ray length at roughness 0: the BVH's radius around the camera (Far
    // Cry 6 talk; ReflectionFrameSettings::reach); beyond it the TLAS holds
    // nothing.
    float maxDistance = scene::kDefaultBvhRadius;
    // Length of shadow rays: the BVH's diameter, so that an occluder anywhere
    // in the TLAS can shadow a hit anywhere in it.
    float shadowDistance = 2.0f * scene::kDefaultBvhRadius;
};

struct RtTraceSettings {
    // Auto: the backend RtTracePipelines was created for. Naming the other
    // one creates its pipeline on first use (throws where unsupported).
    // Switching between frames changes the trace's shader stages (compute
    // or ray tracing), and the graph orders a frame after the previous one
    // as if that ran the same plan: wait for the device before the first
    // frame of the other backend.
    RtBackend backend = RtBackend::Auto;
    // The length falls linearly with perceptual roughness to
    // shortRangeFraction * RtTraceInputs::maxDistance at shortRangeRoughness: rough
    // reflections blur distant detail away (the talk's range shrinking;
    // the numbers are Glint's starting values, the bench sweeps them).
    // 0.22 is FidelityFX's roughness cutoff: from there on rays are at
    // their shortest (ray generation traces up to its own cutoff).
    float shortRangeRoughness = 0.22f;
    float shortRangeFraction = 0.25f;
    // Sun visibility at hits from a shadow ray; off, hits are lit unshadowed
    // (as the G-buffer's lit colour is).
    bool shadows = true;
    // With shadows: a hit the G-buffer's shadow map covers (inside its fit,
    // nearer the camera than its fade) takes the sun's visibility from the
    // map, filtered as the G-buffer filters it (the shadows SSLR's hits
    // and the direct view show), instead of tracing a shadow ray; the rest
    // trace theirs. The shadow rays were a quarter of the trace's time: on
    // an H100 at 1080p the plaza's reflections 0.667 -> 0.619 ms (hybrid)
    // and 0.593 -> 0.527 (rt) at FLIP 0.06028 -> 0.06026 and 0.06108 ->
    // 0.06105 against the exact reference; the city of 1,024 buildings
    // 0.661 -> 0.631 and 0.902 -> 0.783 at the same FLIP
    // (docs/results/log/06-2026-12-06-b.md, fifth session). Off: a shadow
    // ray from every hit (the reference's).
    bool shadowMapAtHits = true;
    // Multiplies the robust origin offset (glint/rt_trace_shared.h); 0 turns
    // it off, which tests and the bench use to show what it prevents.
    float originOffsetScale = 1.0f;
    // TLAS instance groups the rays see (glint/packing.h kInstanceMask*).
    uint32_t instanceMask = 0xFFu;
    // Rays pass through the cut-outs of alpha-tested geometry (glTF alphaMode
    // MASK; passes/bvh_hit_materials.h). Off, every triangle is opaque to
    // them (no any-hit shader runs): what the test costs is the difference.
    bool alphaTest = true;
    // Zero the outputs before the trace, so that pixels it does not trace
    // read as "not traced" (debug views). Integrate and the particle trace
    // read only the pixels whose rays were listed and need no clear.
    bool clearUntraced = false;
};

struct RtTraceOutputs {
    // kRtRadianceFormat: rgb radiance along the ray (the hit lit, or the
    // environment on a miss), a = 1, at the pixels of the listed rays; the
    // rest is left as the memory held it (zero with clearUntraced).
    rg::Texture radiance;
    // kRtHitDistanceFormat: world distance to the hit; kMissHitDistance
    // (glint/ray_generation_shared.h) on a miss; at the listed rays' pixels.
    rg::Texture hitDistance;
    // kRtHitMotionFormat: xyz, where the hit point was last frame minus
    // where it is, in world units (its instance's motion from the BVH's
    // material rows, plus a skinned or morphed triangle's own movement from
    // BvhUpdateOutputs::deformMotion; zero on a miss); at the listed rays'
    // pixels. Temporal
    // accumulation reprojects a moving object's reflection with it.
    rg::Texture hitMotion;
    uint32_t width = 0;
    uint32_t height = 0;
};

// The pipelines and the sampler the pass records with; created once.
class RtTracePipelines {
public:
    // Creates the pipeline of `backend` (Auto: ray query where the device
    // has it, else the ray tracing pipeline). Throws gpu::GpuError naming
    // the device when it cannot run that backend.
    explicit RtTracePipelines(gpu::Context& ctx, RtBackend backend = RtBackend::Auto);
    ~RtTracePipelines();
    RtTracePipelines(const RtTracePipelines&) = delete;
    RtTracePipelines& operator=(const RtTracePipelines&) = delete;

    // The backend Auto resolved to (or the one asked for).
    RtBackend backend() const { return backend_; }
    // The device's VkPhysicalDeviceLimits::subPixelPrecisionBits: how far
    // the rasteriser may have moved the G-buffer's surfaces (robust origins).
    uint32_t subPixelPrecisionBits() const { return subPixelPrecisionBits_; }
    // Whether the device can run `backend` (Auto: either).
    static bool supported(const gpu::Context& ctx, RtBackend backend);

private:
    friend RtTraceOutputs addRtTracePass(rg::Graph&, RtTracePipelines&, const RtTraceInputs&, const RtTraceSettings&);
    // The concrete backend `requested` means, its pipeline created if needed.
    RtBackend prepare(RtBackend requested);

    gpu::Context& ctx_;
    RtBackend backend_;
    uint32_t subPixelPrecisionBits_ = 4;
    std::optional<gpu::Pipeline> query_;
    std::optional<gpu::Pipeline> pipeline_;
    std::optional<gpu::ShaderBindingTable> sbt_;
    gpu::Sampler nearest_;
    gpu::Sampler environmentSampler_;
    gpu::Sampler alphaSampler_;  // the alpha masks: linear, repeating
    ImageClearer clearer_;
};

// The rasteriser's share of a reconstructed G-buffer position's error
// along its normal, per unit of distance from the camera: the larger pixel
// angle of `projection` on a width x height image times 2^-subPixelBits
// (twice the largest vertex snap; glint/rt_trace_shared.h).
float rtRasterErrorPerDistance(const glm::mat4& projection, uint32_t width, uint32_t height,
                               uint32_t subPixelBits);

// Declares the pass (see the top of this file) on the graphics queue: a
// small clear/setup pass (outputs cleared, scene constants uploaded) and
// the trace. The list's capacity is not checked: entries past its length
// are never read.
RtTraceOutputs addRtTracePass(rg::Graph& graph, RtTracePipelines& pipelines, const RtTraceInputs& inputs,
                              const RtTraceSettings& settings = {});

} // namespace glint::passes
