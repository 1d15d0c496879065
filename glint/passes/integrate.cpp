#include "glint/passes/integrate.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/transfer.h"
#include "glint/passes/environment.h"

#include "glint/integrate_shared.h"
#include "glint/ray_generation_shared.h"

#include <string>
#include <vector>

namespace glint::passes {

namespace {

// Which inputs a variant binds: bits of the variant index.
constexpr uint32_t kVariantSslr = 1u;
constexpr uint32_t kVariantRt = 2u;
constexpr uint32_t kVariantFeedback = 4u;

std::string variantShader(uint32_t variant) {
    const bool sslr = (variant & kVariantSslr) != 0;
    const bool rt = (variant & kVariantRt) != 0;
    const char* traces = sslr && rt ? "hybrid" : sslr ? "ssr" : rt ? "rt" : "env";
    return std::string("integrate/") + traces + ((variant & kVariantFeedback) != 0 ? "" : "_no_feedback") + ".comp";
}

std::array<gpu::Pipeline, 8> createVariants(gpu::Context& ctx) {
    std::array<gpu::Pipeline, 8> variants;
    for (uint32_t v = 0; v < variants.size(); ++v) {
        const std::string shader = variantShader(v);
        // The layout is the variant's own bindings (integrate.glsl), reflected.
        variants[v] = gpu::createComputePipeline(ctx, {shader, {}, 0, shader});
    }
    return variants;
}

} // namespace

IntegratePipelines::IntegratePipelines(gpu::Context& ctx)
    : ctx_(ctx),
      variants_(createVariants(ctx)),
      // Every read is a texelFetch; the sampler only completes the combined
      // descriptor.
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "integrate.nearest"}),
      environmentSampler_(createEnvironmentSampler(ctx, "integrate.environment")) {}

IntegrateOutputs addIntegratePass(rg::Graph& graph, IntegratePipelines& pipelines, const IntegrateInputs& inputs,
                                  const IntegrateSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    const RayGenerationOutputs& rays = inputs.rays;
    const FeedbackOutputs& feedback = inputs.feedback;
    if (gbuf.width == 0 || gbuf.height == 0 || rays.width != gbuf.width || rays.height != gbuf.height) {
        throw gpu::GpuError("addIntegratePass: the G-buffer and the rays must have the same, non-zero size");
    }
    if (inputs.sslr && (inputs.sslr->width != gbuf.width || inputs.sslr->height != gbuf.height)) {
        throw gpu::GpuError("addIntegratePass: the SSLR outputs must have the G-buffer's size");
    }
    if (inputs.rtRadiance.valid() != inputs.rtHitDistance.valid() ||
        (inputs.rtHitMotion.valid() && !inputs.rtRadiance.valid())) {
        throw gpu::GpuError("addIntegratePass: give the ray tracer's radiance and hit distance together, or neither "
                            "(its hit motion only with them)");
    }
    const bool hasFeedback = feedback.counters.current.valid();
    if (hasFeedback && (!feedback.reprojected.valid() || feedback.tilesX != rays.tilesX ||
                        feedback.tilesY != rays.tilesY)) {
        throw gpu::GpuError("addIntegratePass: the feedback outputs must come from this frame's G-buffer size");
    }
    if (inputs.lighting.environment.x != 0.0f && !inputs.environment.valid()) {
        throw gpu::GpuError("addIntegratePass: the lighting looks up an environment image but no environment texture "
                            "was given (passes::importEnvironment)");
    }
    const bool hasRt = inputs.rtRadiance.valid();
    const bool hasParticles = inputs.particles.valid();
    // A frame the host renders as rt records rt mode's variant; it declares
    // what the frames around it declare (their plan).
    const bool idle = inputs.screenSpaceIdle;
    const uint32_t variant = (inputs.sslr && !idle ? kVariantSslr : 0u) | (hasRt ? kVariantRt : 0u) |
                             (hasFeedback && !idle ? kVariantFeedback : 0u);

    IntegrateOutputs out;
    out.width = gbuf.width;
    out.height = gbuf.height;
    const uint32_t tilesX = (gbuf.width + shader::kTileSize - 1) / shader::kTileSize;
    const uint32_t tilesY = (gbuf.height + shader::kTileSize - 1) / shader::kTileSize;

    shader::IntegrateConstants constants{};
    constants.inverseViewProjection = glm::inverse(inputs.camera.viewProjection());
    constants.previousViewProjection = inputs.camera.previousViewProjection();
    constants.previousInverseViewProjection = glm::inverse(constants.previousViewProjection);
    constants.cameraPosition = glm::vec4(inputs.camera.position, 1.0f);
    constants.previousCameraPosition = glm::vec4(inputs.camera.previousPosition, 1.0f);
    constants.lighting = inputs.lighting;
    constants.size = {gbuf.width, gbuf.height};
    constants.tiles = {tilesX, tilesY};
    constants.confidenceThreshold = sslrStoredThreshold(inputs.confidenceThreshold);
    constants.particlesBound = hasParticles ? 1u : 0u;
    constants.rtMissesTrusted = settings.rtMissesTrusted ? 1u : 0u;
    constants.rtHitMotionBound = inputs.rtHitMotion.valid() ? 1u : 0u;
    constants.minFrameHits = (variant & kVariantFeedback) != 0 ? feedback.minFrameHits : 0u;
    constants.sslrCountsOnly = inputs.sslrCountsOnly && (variant & kVariantSslr) != 0 ? 1u : 0u;
    constants.debugOutputs = inputs.debugOutputs ? 1u : 0u;

    // The constants outgrow push constants (glint/integrate_shared.h); a
    // transfer inside the frame keeps their lifetime the graph's.
    const rg::Buffer uploaded = rg::addUpload(graph, "integrate.constants", constants);

    struct IntegrateData {
        rg::Texture depth, normal, roughnessMetal, motion;
        rg::Buffer constants, rays, classes, reprojected;
        rg::Texture sslrRadiance, sslrConfidence, sslrHit, rtRadiance, rtHitDistance;
        rg::Texture rtHitMotion;  // the trace's hit motion, or its hit distance as a stand-in (never read)
        rg::Texture particles;    // the particle trace, or the normal as a stand-in (never read)
        rg::Texture environment;  // the prefiltered image, or the normal as a stand-in (never read)
        IntegrateOutputs out;
    };
    const IntegrateData& integrate = graph.addPass<IntegrateData>(
        "integrate", rg::Queue::Graphics,
        [&](rg::Builder& b, IntegrateData& d) {
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            d.motion = b.read(gbuf.motion, rg::Access::SampledRead);
            // The shader declares the particles in every variant (one flag
            // in the constants rather than twice the variants); without
            // them a texture this pass reads anyway fills the binding.
            d.particles = hasParticles ? b.read(inputs.particles, rg::Access::SampledRead) : d.normal;
            d.environment = inputs.environment.valid() ? b.read(inputs.environment, rg::Access::SampledRead) : d.normal;
            d.constants = b.read(uploaded, rg::Access::StorageRead);
            d.rays = b.read(rays.rays, rg::Access::StorageRead);
            d.classes = b.read(rays.classes, rg::Access::StorageRead);
            if (inputs.sslr) {
                d.sslrRadiance = b.read(inputs.sslr->radiance, rg::Access::SampledRead);
                d.sslrConfidence = b.read(inputs.sslr->confidence, rg::Access::SampledRead);
                d.sslrHit = b.read(inputs.sslr->hit, rg::Access::SampledRead);
            }
            if (hasRt) {
                d.rtRadiance = b.read(inputs.rtRadiance, rg::Access::SampledRead);
                d.rtHitDistance = b.read(inputs.rtHitDistance, rg::Access::SampledRead);
                d.rtHitMotion = inputs.rtHitMotion.valid() ? b.read(inputs.rtHitMotion, rg::Access::SampledRead)
                                                           : d.rtHitDistance;
            }
            d.out = out;
            const auto texture = [&](const char* name, VkFormat format) {
                return b.write(b.createTexture(name, {.width = gbuf.width, .height = gbuf.height, .format = format}),
                               rg::Access::StorageWrite);
            };
            d.out.radiance = texture("integrate.radiance", kReflectionRadianceFormat);
            d.out.hitDistance = texture("integrate.hit_distance", kReflectionHitDistanceFormat);
            d.out.hitMotion = texture("integrate.hit_motion", kReflectionHitMotionFormat);
            d.out.sourceDebug = texture("integrate.source_debug", kReflectionSourceDebugFormat);
            if (hasFeedback) {
                d.reprojected = b.read(feedback.reprojected, rg::Access::StorageRead);
                // The tiles' counters, and the frame's sum of hits added to
                // the start the feedback pass wrote.
                d.out.counters = b.write(feedback.counters.current, rg::Access::StorageReadWrite);
            }
        },
        [&pipelines, variant](const IntegrateData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.variants_[variant];
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors push(pipeline);
            // Layouts as the plan chose them (a sampled depth image stays depth read-only).
            push.sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("normalTexture", pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage("roughnessMetalTexture", pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                .sampledImage("motionTexture", pc.view(d.motion), sampler, pc.layout(d.motion))
                .storageBuffer("Constants", pc.buffer(d.constants))
                .storageBuffer("Rays", pc.buffer(d.rays))
                .storageBuffer("Classes", pc.buffer(d.classes))
                .storageImage("radianceImage", pc.view(d.out.radiance))
                .storageImage("hitDistanceImage", pc.view(d.out.hitDistance))
                .storageImage("hitMotionImage", pc.view(d.out.hitMotion))
                .storageImage("sourceImage", pc.view(d.out.sourceDebug))
                .sampledImage("particlesTexture", pc.view(d.particles), sampler, pc.layout(d.particles))
                .sampledImage("environmentTexture", pc.view(d.environment),
                              d.environment == d.normal ? sampler : pipelines.environmentSampler_.handle(),
                              pc.layout(d.environment));
            if ((variant & kVariantFeedback) != 0) {
                push.storageBuffer("Reprojected", pc.buffer(d.reprojected))
                    .storageBuffer("Counters", pc.buffer(d.out.counters));
            }
            if ((variant & kVariantSslr) != 0) {
                push.sampledImage("sslrRadianceTexture", pc.view(d.sslrRadiance), sampler, pc.layout(d.sslrRadiance))
                    .sampledImage("sslrConfidenceTexture", pc.view(d.sslrConfidence), sampler,
                                  pc.layout(d.sslrConfidence))
                    .sampledImage("sslrHitTexture", pc.view(d.sslrHit), sampler, pc.layout(d.sslrHit));
            }
            if ((variant & kVariantRt) != 0) {
                push.sampledImage("rtRadianceTexture", pc.view(d.rtRadiance), sampler, pc.layout(d.rtRadiance))
                    .sampledImage("rtHitDistanceTexture", pc.view(d.rtHitDistance), sampler,
                                  pc.layout(d.rtHitDistance))
                    .sampledImage("rtHitMotionTexture", pc.view(d.rtHitMotion), sampler, pc.layout(d.rtHitMotion));
            }
            push.push(pipelines.ctx_, pc.cmd());
            pc.dispatch(pipeline, (d.out.width + shader::kTileSize - 1) / shader::kTileSize,
                        (d.out.height + shader::kTileSize - 1) / shader::kTileSize);
        });
    IntegrateOutputs result = integrate.out;
    if (!inputs.debugOutputs) {
        // Declared (the binding needs an image) but never stored to.
        result.sourceDebug = {};
    }
    return result;
}

} // namespace glint::passes
