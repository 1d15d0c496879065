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

// integrate.glsl's bindings.
constexpr uint32_t kBindingDepth = 0, kBindingNormal = 1, kBindingRoughness = 2, kBindingConstants = 3,
                   kBindingRays = 4, kBindingClasses = 5, kBindingRadiance = 6, kBindingHitDistance = 7,
                   kBindingSource = 8, kBindingReprojected = 9, kBindingCounters = 10, kBindingSslrRadiance = 11,
                   kBindingSslrConfidence = 12, kBindingSslrHit = 13, kBindingRtRadiance = 14,
                   kBindingRtHitDistance = 15, kBindingParticles = 16, kBindingEnvironment = 17;

std::string variantShader(uint32_t variant) {
    const bool sslr = (variant & kVariantSslr) != 0;
    const bool rt = (variant & kVariantRt) != 0;
    const char* traces = sslr && rt ? "hybrid" : sslr ? "ssr" : rt ? "rt" : "env";
    return std::string("integrate/") + traces + ((variant & kVariantFeedback) != 0 ? "" : "_no_feedback") + ".comp";
}

std::vector<gpu::Binding> variantBindings(uint32_t variant) {
    constexpr VkShaderStageFlags kStage = VK_SHADER_STAGE_COMPUTE_BIT;
    constexpr VkDescriptorType kSampled = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    constexpr VkDescriptorType kStorage = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    constexpr VkDescriptorType kImage = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    std::vector<gpu::Binding> bindings = {
        {kBindingDepth, kSampled, kStage},     {kBindingNormal, kSampled, kStage},
        {kBindingRoughness, kSampled, kStage}, {kBindingConstants, kStorage, kStage},
        {kBindingRays, kStorage, kStage},      {kBindingClasses, kStorage, kStage},
        {kBindingRadiance, kImage, kStage},    {kBindingHitDistance, kImage, kStage},
        {kBindingSource, kImage, kStage},      {kBindingParticles, kSampled, kStage},
        {kBindingEnvironment, kSampled, kStage},
    };
    if ((variant & kVariantFeedback) != 0) {
        bindings.push_back({kBindingReprojected, kStorage, kStage});
        bindings.push_back({kBindingCounters, kStorage, kStage});
    }
    if ((variant & kVariantSslr) != 0) {
        bindings.push_back({kBindingSslrRadiance, kSampled, kStage});
        bindings.push_back({kBindingSslrConfidence, kSampled, kStage});
        bindings.push_back({kBindingSslrHit, kSampled, kStage});
    }
    if ((variant & kVariantRt) != 0) {
        bindings.push_back({kBindingRtRadiance, kSampled, kStage});
        bindings.push_back({kBindingRtHitDistance, kSampled, kStage});
    }
    return bindings;
}

std::array<gpu::Pipeline, 8> createVariants(gpu::Context& ctx) {
    std::array<gpu::Pipeline, 8> variants;
    for (uint32_t v = 0; v < variants.size(); ++v) {
        const std::string shader = variantShader(v);
        variants[v] = gpu::createComputePipeline(ctx, {shader, variantBindings(v), 0, shader});
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
    if (inputs.rtRadiance.valid() != inputs.rtHitDistance.valid()) {
        throw gpu::GpuError("addIntegratePass: give the ray tracer's radiance and hit distance together, or neither");
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
    const uint32_t variant = (inputs.sslr ? kVariantSslr : 0u) | (hasRt ? kVariantRt : 0u) |
                             (hasFeedback ? kVariantFeedback : 0u);

    IntegrateOutputs out;
    out.width = gbuf.width;
    out.height = gbuf.height;
    const uint32_t tilesX = (gbuf.width + shader::kTileSize - 1) / shader::kTileSize;
    const uint32_t tilesY = (gbuf.height + shader::kTileSize - 1) / shader::kTileSize;

    shader::IntegrateConstants constants{};
    constants.inverseViewProjection = glm::inverse(inputs.camera.viewProjection());
    constants.cameraPosition = glm::vec4(inputs.camera.position, 1.0f);
    constants.lighting = inputs.lighting;
    constants.size = {gbuf.width, gbuf.height};
    constants.tiles = {tilesX, tilesY};
    constants.confidenceThreshold = sslrStoredThreshold(settings.confidenceThreshold);
    constants.particlesBound = hasParticles ? 1u : 0u;
    constants.rtMissesTrusted = settings.rtMissesTrusted ? 1u : 0u;

    // The constants outgrow push constants (glint/integrate_shared.h); a
    // transfer inside the frame keeps their lifetime the graph's.
    const rg::Buffer uploaded = rg::addUpload(graph, "integrate.constants", constants);

    struct IntegrateData {
        rg::Texture depth, normal, roughnessMetal;
        rg::Buffer constants, rays, classes, reprojected;
        rg::Texture sslrRadiance, sslrConfidence, sslrHit, rtRadiance, rtHitDistance;
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
                d.sslrHit = b.read(inputs.sslr->hitDebug, rg::Access::SampledRead);
            }
            if (hasRt) {
                d.rtRadiance = b.read(inputs.rtRadiance, rg::Access::SampledRead);
                d.rtHitDistance = b.read(inputs.rtHitDistance, rg::Access::SampledRead);
            }
            d.out = out;
            const auto texture = [&](const char* name, VkFormat format) {
                return b.write(b.createTexture(name, {.width = gbuf.width, .height = gbuf.height, .format = format}),
                               rg::Access::StorageWrite);
            };
            d.out.radiance = texture("integrate.radiance", kReflectionRadianceFormat);
            d.out.hitDistance = texture("integrate.hit_distance", kReflectionHitDistanceFormat);
            d.out.sourceDebug = texture("integrate.source_debug", kReflectionSourceDebugFormat);
            if (hasFeedback) {
                d.reprojected = b.read(feedback.reprojected, rg::Access::StorageRead);
                d.out.counters = b.write(feedback.counters.current, rg::Access::StorageWrite);
            }
        },
        [&pipelines, variant](const IntegrateData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.variants_[variant];
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors push(pipeline);
            // Layouts as the plan chose them (a sampled depth image stays depth read-only).
            push.sampledImage(kBindingDepth, pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage(kBindingNormal, pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage(kBindingRoughness, pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                .storageBuffer(kBindingConstants, pc.buffer(d.constants))
                .storageBuffer(kBindingRays, pc.buffer(d.rays))
                .storageBuffer(kBindingClasses, pc.buffer(d.classes))
                .storageImage(kBindingRadiance, pc.view(d.out.radiance))
                .storageImage(kBindingHitDistance, pc.view(d.out.hitDistance))
                .storageImage(kBindingSource, pc.view(d.out.sourceDebug))
                .sampledImage(kBindingParticles, pc.view(d.particles), sampler, pc.layout(d.particles))
                .sampledImage(kBindingEnvironment, pc.view(d.environment),
                              d.environment == d.normal ? sampler : pipelines.environmentSampler_.handle(),
                              pc.layout(d.environment));
            if ((variant & kVariantFeedback) != 0) {
                push.storageBuffer(kBindingReprojected, pc.buffer(d.reprojected))
                    .storageBuffer(kBindingCounters, pc.buffer(d.out.counters));
            }
            if ((variant & kVariantSslr) != 0) {
                push.sampledImage(kBindingSslrRadiance, pc.view(d.sslrRadiance), sampler, pc.layout(d.sslrRadiance))
                    .sampledImage(kBindingSslrConfidence, pc.view(d.sslrConfidence), sampler,
                                  pc.layout(d.sslrConfidence))
                    .sampledImage(kBindingSslrHit, pc.view(d.sslrHit), sampler, pc.layout(d.sslrHit));
            }
            if ((variant & kVariantRt) != 0) {
                push.sampledImage(kBindingRtRadiance, pc.view(d.rtRadiance), sampler, pc.layout(d.rtRadiance))
                    .sampledImage(kBindingRtHitDistance, pc.view(d.rtHitDistance), sampler,
                                  pc.layout(d.rtHitDistance));
            }
            push.push(pipelines.ctx_, pc.cmd());
            pc.dispatch(pipeline, (d.out.width + shader::kTileSize - 1) / shader::kTileSize,
                        (d.out.height + shader::kTileSize - 1) / shader::kTileSize);
        });
    return integrate.out;
}

} // namespace glint::passes
