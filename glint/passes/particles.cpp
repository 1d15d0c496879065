#include "glint/passes/particles.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/transfer.h"
#include "glint/scene/frustum.h"

#include "glint/packing.h"
#include "glint/particles_shared.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

namespace glint::passes {

namespace {

std::string unsupportedMessage(const gpu::Context& ctx, RtBackend backend) {
    const std::string device = "device '" + ctx.caps().deviceName + "'";
    switch (backend) {
        case RtBackend::RayQuery:
            return "particle trace: " + device + " has no ray query (VK_KHR_ray_query); use RtBackend::Pipeline or Auto";
        case RtBackend::Pipeline:
            return "particle trace: " + device +
                   " has no ray tracing pipeline (VK_KHR_ray_tracing_pipeline); use RtBackend::RayQuery or Auto";
        case RtBackend::Auto:
            break;
    }
    return "particle trace: " + device + " has neither ray query nor a ray tracing pipeline";
}

// Push constants of the forward pass (112 bytes).
struct ForwardPush {
    glm::mat4 viewProjection;
    shader::ParticleBillboardParams basis;
};
static_assert(sizeof(ForwardPush) == 112);


} // namespace

bool ParticlePipelines::supported(const gpu::Context& ctx, RtBackend backend) {
    switch (backend) {
        case RtBackend::RayQuery:
            return ctx.caps().rayQuery;
        case RtBackend::Pipeline:
            return ctx.caps().rayTracingPipeline;
        case RtBackend::Auto:
            return ctx.caps().rayQuery || ctx.caps().rayTracingPipeline;
    }
    return false;
}

ParticlePipelines::ParticlePipelines(gpu::Context& ctx, RtBackend backend)
    : ctx_(ctx),
      backend_(backend),
      // Every read is a texelFetch; the sampler only completes the combined
      // descriptors.
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "particles.nearest"}),
      clearer_(ctx) {
    if (backend_ == RtBackend::Auto && supported(ctx, RtBackend::Auto)) {
        // Ray query first, as the reflections' own trace (passes/rt_trace.cpp).
        backend_ = ctx.caps().rayQuery ? RtBackend::RayQuery : RtBackend::Pipeline;
    }
    if (backend_ != RtBackend::Auto) {
        backend_ = prepare(backend_);
    }

    gpu::GraphicsPipelineDesc forward;
    forward.vertexShader = "particles/forward.vert";
    forward.fragmentShader = "particles/forward.frag";
    forward.pushConstantBytes = sizeof(ForwardPush);
    forward.cullMode = VK_CULL_MODE_NONE;
    forward.colorFormats = {kGBufferLitFormat};
    forward.depthFormat = kGBufferDepthFormat;
    forward.depthTest = true;
    forward.depthWrite = false;  // particles are not surfaces: SSLR and the traces keep seeing what is behind
    // Premultiplied "over"; the lit colour's alpha is left as the G-buffer wrote it.
    VkPipelineColorBlendAttachmentState over{};
    over.blendEnable = VK_TRUE;
    over.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    over.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    over.colorBlendOp = VK_BLEND_OP_ADD;
    over.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
    over.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    over.alphaBlendOp = VK_BLEND_OP_ADD;
    over.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT;
    forward.colorBlends = {over};
    forward.name = "particles.forward";
    forward_ = gpu::createGraphicsPipeline(ctx, forward);
}

ParticlePipelines::~ParticlePipelines() = default;

RtBackend ParticlePipelines::prepare(RtBackend requested) {
    const RtBackend backend = requested == RtBackend::Auto ? backend_ : requested;
    if (backend == RtBackend::Auto || !supported(ctx_, backend)) {
        throw gpu::GpuError(unsupportedMessage(ctx_, backend));
    }
    if (backend == RtBackend::RayQuery && !query_) {
        query_ = gpu::createComputePipeline(
            ctx_, {"particles/trace_query.comp", {}, sizeof(shader::ParticleTracePush), "particles.trace_query"});
    }
    if (backend == RtBackend::Pipeline && !pipeline_) {
        // Hit record kSbtOffsetParticles is the particle group (the particle
        // TLAS's instance selects it); the record before it is the packed
        // primitives' slot of a shared SBT, empty here since this TLAS holds
        // no scene instance. Depth 1: the ray generation shader traces.
        static_assert(shader::kSbtOffsetParticles == 1u, "the hit groups below are laid out for record 1");
        pipeline_ = gpu::createRayTracingPipeline(
            ctx_, {"particles/trace.rgen",
                   {"particles/trace.rmiss"},
                   {{"", ""}, {"", "particles/trace.rahit"}},
                   {},
                   sizeof(shader::ParticleTracePush),
                   1,
                   "particles.trace_pipeline"});
        sbt_.emplace(ctx_, *pipeline_, 1, 2);
    }
    return backend;
}

ParticleTraceOutputs addParticleTracePass(rg::Graph& graph, ParticlePipelines& pipelines,
                                          const ParticleTraceInputs& inputs, const ParticleTraceSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (gbuf.width == 0 || gbuf.height == 0 || inputs.rays.width != gbuf.width || inputs.rays.height != gbuf.height) {
        throw gpu::GpuError("addParticleTracePass: the G-buffer and the rays must have the same, non-zero size");
    }
    if (inputs.sslr && (inputs.sslr->width != gbuf.width || inputs.sslr->height != gbuf.height)) {
        throw gpu::GpuError("addParticleTracePass: the SSLR outputs must have the G-buffer's size");
    }
    if (inputs.rtRadiance.valid() != inputs.rtHitDistance.valid()) {
        throw gpu::GpuError("addParticleTracePass: give the ray tracer's radiance and hit distance together, or neither");
    }
    if (inputs.rtRayList.valid() != inputs.rtArgs.valid()) {
        throw gpu::GpuError("addParticleTracePass: give the RT list and its args together, or neither");
    }
    if (!particlesTraced(inputs.bvh)) {
        throw gpu::GpuError("addParticleTracePass: the BVH update built no particle TLAS this frame (no particles, or "
                            "declared without the camera); check particlesTraced()");
    }
    if (!(settings.maxDistance > 0.0f)) {
        throw gpu::GpuError("addParticleTracePass: maxDistance must be positive");
    }
    const RtBackend backend = pipelines.prepare(settings.backend);
    const bool hasSslr = inputs.sslr.has_value();
    const bool hasRt = inputs.rtRadiance.valid();
    const rg::Buffer rtList = inputs.rtRayList.valid() ? inputs.rtRayList : inputs.rays.rtRays;
    const rg::Buffer rtArgs = inputs.rtRayList.valid() ? inputs.rtArgs : inputs.rays.rtArgs;

    shader::ParticleTraceConstants constants{};
    constants.inverseViewProjection = glm::inverse(inputs.camera.viewProjection());
    constants.cameraPosition = glm::vec4(inputs.camera.position, 1.0f);
    // The basis the BVH update built this frame's quads in: the same camera's.
    const shader::ParticleBillboardParams basis = particleBasis(inputs.camera.view);
    constants.cameraRight = glm::vec4(basis.right, 0.0f);
    constants.cameraUp = glm::vec4(basis.up, 0.0f);
    constants.cameraBack = glm::vec4(basis.back, 0.0f);
    constants.size = {gbuf.width, gbuf.height};
    constants.confidenceThreshold = sslrStoredThreshold(settings.confidenceThreshold);
    constants.maxDistance = settings.maxDistance;
    constants.sslrBound = !hasSslr || inputs.screenSpaceIdle ? 0u : inputs.sslrCountsOnly ? 2u : 1u;
    constants.rtBound = hasRt ? 1u : 0u;
    constants.sslrSeesParticles = settings.sslrSeesParticles ? 1u : 0u;
    constants.rtMissesTrusted = settings.rtMissesTrusted ? 1u : 0u;
    constants.boundsMin = glm::vec4(inputs.bvh.particleBoundsMin, 0.0f);
    constants.boundsMax = glm::vec4(inputs.bvh.particleBoundsMax, 0.0f);

    const rg::Buffer uploaded = rg::addUpload(graph, "particles.constants", constants);

    rg::Texture radiance = graph.createTexture(
        "particles.radiance", {.width = gbuf.width, .height = gbuf.height, .format = kParticleRadianceFormat});
    if (settings.clearUntraced) {
        pipelines.clearer_.addClearPass(graph, "particles.clear", std::span(&radiance, 1));
    }

    struct List {
        rg::Buffer rays, args;
        uint32_t which = shader::kParticleListSslr;  // ParticleTracePush::list
    };
    struct TraceData {
        rg::Texture depth, sslrRadiance, sslrConfidence, sslrHit, rtRadiance, rtHitDistance;
        rg::Buffer classes, particles, constants;
        rg::AccelStruct tlas;
        std::vector<List> lists;
        ParticleTraceOutputs out;
    };
    const TraceData& trace = graph.addPass<TraceData>(
        "particles.trace", rg::Queue::Graphics,
        [&](rg::Builder& b, TraceData& d) {
            b.setPipeline(backend == RtBackend::RayQuery ? rg::Pipeline::Compute : rg::Pipeline::RayTracing);
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.classes = b.read(inputs.rays.classes, rg::Access::StorageRead);
            d.tlas = b.read(inputs.bvh.particleTlas, rg::Access::AccelRead);
            d.particles = b.read(inputs.bvh.particles, rg::Access::StorageRead);
            d.constants = b.read(uploaded, rg::Access::StorageRead);
            // Each list's args: the indirect command, and its length for
            // the ray query backend's last, partial group.
            const auto list = [&](rg::Buffer rays, rg::Buffer args, uint32_t which) {
                d.lists.push_back({b.read(rays, rg::Access::StorageRead), b.read(args, rg::Access::IndirectArgs), which});
                b.read(args, rg::Access::StorageRead);
            };
            if (inputs.rays.sslrListed) {
                list(inputs.rays.sslrRays, inputs.rays.sslrArgs, shader::kParticleListSslr);
            }
            if (inputs.rays.rtListed) {
                list(rtList, rtArgs, shader::kParticleListRt);
            }
            // Absent traces: the depth, which the pass reads anyway, fills
            // their bindings; the constants say not to read them.
            d.sslrRadiance = d.sslrConfidence = d.sslrHit = d.rtRadiance = d.rtHitDistance = d.depth;
            if (hasSslr) {
                d.sslrRadiance = b.read(inputs.sslr->radiance, rg::Access::SampledRead);
                d.sslrConfidence = b.read(inputs.sslr->confidence, rg::Access::SampledRead);
                d.sslrHit = b.read(inputs.sslr->hit, rg::Access::SampledRead);
            }
            if (hasRt) {
                d.rtRadiance = b.read(inputs.rtRadiance, rg::Access::SampledRead);
                d.rtHitDistance = b.read(inputs.rtHitDistance, rg::Access::SampledRead);
            }
            d.out.width = gbuf.width;
            d.out.height = gbuf.height;
            d.out.radiance = b.write(radiance, rg::Access::StorageWrite);
        },
        [&pipelines, backend](const TraceData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = backend == RtBackend::RayQuery ? *pipelines.query_ : *pipelines.pipeline_;
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            for (const List& list : d.lists) {
                gpu::PushDescriptors push(pipeline);
                push.accelerationStructure("particleTlas", pc.accel(d.tlas).handle())
                    .storageBuffer("RayList", pc.buffer(list.rays))
                    .storageBuffer("RayListArgs", pc.buffer(list.args))
                    .storageBuffer("Classes", pc.buffer(d.classes))
                    .storageBuffer("Particles", pc.buffer(d.particles))
                    .storageBuffer("Constants", pc.buffer(d.constants))
                    .storageImage("particleImage", pc.view(d.out.radiance));
                for (const auto& [name, texture] : {std::pair{"depthTexture", d.depth},
                                                    {"sslrRadianceTexture", d.sslrRadiance},
                                                    {"sslrConfidenceTexture", d.sslrConfidence},
                                                    {"sslrHitTexture", d.sslrHit},
                                                    {"rtRadianceTexture", d.rtRadiance},
                                                    {"rtHitDistanceTexture", d.rtHitDistance}}) {
                    push.sampledImage(name, pc.view(texture), sampler, pc.layout(texture));
                }
                push.push(pc.gpu(), pc.cmd());
                pipeline.pushConstants(pc.cmd(), shader::ParticleTracePush{list.which});
                if (backend == RtBackend::RayQuery) {
                    pc.dispatchIndirect(pipeline, list.args, kRayListDispatchArgsBytes);
                } else {
                    // {count, 1, 1}: one launch per entry, read by device address.
                    const gpu::ShaderBindingTable& sbt = *pipelines.sbt_;
                    pc.gpu().fn().cmdTraceRaysIndirect(pc.cmd(), &sbt.raygen(), &sbt.miss(), &sbt.hit(),
                                                       &sbt.callable(),
                                                       pc.buffer(list.args).address() + kRayListTraceArgsBytes);
                }
            }
        });
    return trace.out;
}

ParticleForwardOutputs addParticleForwardPass(rg::Graph& graph, ParticlePipelines& pipelines,
                                              const ParticleForwardInputs& inputs) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    ParticleForwardOutputs result;
    result.lit = gbuf.lit;
    if (inputs.particles.empty()) {
        return result;
    }
    if (gbuf.width == 0 || gbuf.height == 0) {
        throw gpu::GpuError("addParticleForwardPass: the G-buffer has no size");
    }

    // The particles whose quads can reach the screen (a quad lies within
    // its radius of the centre), back to front along the view direction:
    // "over" does not commute. Ties keep the scene's order, so the image is
    // deterministic.
    const glm::mat4& view = inputs.camera.view;
    const scene::Frustum frustum(inputs.camera.jitteredProjection * view);
    std::vector<uint32_t> order;
    for (uint32_t i = 0; i < inputs.particles.size(); ++i) {
        if (frustum.intersects(inputs.particles[i].position, inputs.particles[i].radius)) order.push_back(i);
    }
    result.culled = uint32_t(inputs.particles.size() - order.size());
    if (order.empty()) {
        return result;
    }
    std::vector<float> viewZ(inputs.particles.size());
    for (const uint32_t i : order) {
        viewZ[i] = (view * glm::vec4(inputs.particles[i].position, 1.0f)).z;  // more negative: farther
    }
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return viewZ[a] < viewZ[b]; });
    std::vector<shader::ParticleData> data(order.size());
    for (size_t i = 0; i < order.size(); ++i) {
        const scene::Particle& p = inputs.particles[order[i]];
        data[i] = {p.position, p.radius, p.color};
    }

    ForwardPush push{};
    // As the G-buffer rasterised (jittered), so the depth test compares like with like.
    push.viewProjection = inputs.camera.jitteredProjection * view;
    push.basis = particleBasis(view);
    push.basis.count = uint32_t(data.size());

    const rg::Buffer uploaded =
        rg::addUpload(graph, "particles.forward_upload", std::as_bytes(std::span<const shader::ParticleData>(data)));

    struct ForwardData {
        rg::Buffer particles;
        rg::Texture depth, lit;
        uint32_t width = 0, height = 0;
    };
    const ForwardData& forward = graph.addPass<ForwardData>(
        "particles.forward", rg::Queue::Graphics,
        [&](rg::Builder& b, ForwardData& d) {
            b.setPipeline(rg::Pipeline::Raster);
            d.particles = b.read(uploaded, rg::Access::StorageRead);
            d.depth = b.read(gbuf.depth, rg::Access::DepthRead);
            d.lit = b.write(gbuf.lit, rg::Access::ColorAttachment);
            d.width = gbuf.width;
            d.height = gbuf.height;
        },
        [&pipelines, push](const ForwardData& d, rg::PassContext& pc) {
            const VkCommandBuffer cmd = pc.cmd();
            gpu::beginRenderingOverDepth(cmd, pc.view(d.lit), pc.layout(d.lit), pc.view(d.depth), pc.layout(d.depth),
                                         {d.width, d.height});
            const gpu::Pipeline& pipeline = pipelines.forward_;
            pipeline.bind(cmd);
            gpu::PushDescriptors(pipeline).storageBuffer("Particles", pc.buffer(d.particles)).push(pc.gpu(), cmd);
            pipeline.pushConstants(cmd, push);
            vkCmdDraw(cmd, push.basis.count * shader::kParticleQuadVertices, 1, 0, 0);
            vkCmdEndRendering(cmd);
        });
    result.lit = forward.lit;
    result.particles = uint32_t(data.size());
    return result;
}

} // namespace glint::passes
