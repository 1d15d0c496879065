#include "glint/passes/rt_trace.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/transfer.h"
#include "glint/passes/environment.h"

#include "glint/ray_generation_shared.h"
#include "glint/rt_trace_shared.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace glint::passes {

namespace {

static_assert(shader::kRtTraceGroupSize == shader::kRayListGroupSize,
              "the ray query dispatch runs the list's own dispatch command");

// Byte offsets of the list's two indirect commands (glint/ray_generation_shared.h).
constexpr VkDeviceSize kDispatchArgsBytes = shader::kRayListDispatchOffset * sizeof(uint32_t);
constexpr VkDeviceSize kTraceArgsBytes = shader::kRayListCountOffset * sizeof(uint32_t);

// vkCmdTraceRaysIndirectKHR needs rayTracingPipelineTraceRaysIndirect; the
// context enables it wherever the device has it, so asking the device is
// asking what is enabled.
bool traceRaysIndirectSupported(const gpu::Context& ctx) {
    if (!ctx.caps().rayTracingPipeline) return false;
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &rt;
    vkGetPhysicalDeviceFeatures2(ctx.physicalDevice(), &features);
    return rt.rayTracingPipelineTraceRaysIndirect == VK_TRUE;
}

std::string unsupportedMessage(const gpu::Context& ctx, RtBackend backend) {
    const std::string device = "device '" + ctx.caps().deviceName + "'";
    switch (backend) {
        case RtBackend::RayQuery:
            return "RT trace: " + device + " has no ray query (VK_KHR_ray_query); use RtBackend::Pipeline or Auto";
        case RtBackend::Pipeline:
            return "RT trace: " + device +
                   " has no ray tracing pipeline with indirect trace rays (VK_KHR_ray_tracing_pipeline, "
                   "rayTracingPipelineTraceRaysIndirect); use RtBackend::RayQuery or Auto";
        case RtBackend::Auto:
            break;
    }
    return "RT trace: " + device + " has neither ray query nor a ray tracing pipeline";
}

} // namespace

const char* rtBackendName(RtBackend backend) {
    switch (backend) {
        case RtBackend::Auto:
            return "auto";
        case RtBackend::RayQuery:
            return "ray-query";
        case RtBackend::Pipeline:
            return "rt-pipeline";
    }
    return "?";
}

bool RtTracePipelines::supported(const gpu::Context& ctx, RtBackend backend) {
    switch (backend) {
        case RtBackend::RayQuery:
            return ctx.caps().rayQuery;
        case RtBackend::Pipeline:
            return traceRaysIndirectSupported(ctx);
        case RtBackend::Auto:
            return ctx.caps().rayQuery || traceRaysIndirectSupported(ctx);
    }
    return false;
}

RtTracePipelines::RtTracePipelines(gpu::Context& ctx, RtBackend backend)
    : ctx_(ctx),
      backend_(backend),
      // Every read is a texelFetch; the sampler only completes the combined
      // descriptors.
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "rt_trace.nearest"}),
      environmentSampler_(createEnvironmentSampler(ctx, "rt_trace.environment")),
      // The alpha masks' wrap modes are applied in the shader (one layer
      // per texture); repeating here lets bilinear filtering of a repeating
      // texture blend across its edge.
      alphaSampler_(ctx, {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT,
                          VK_LOD_CLAMP_NONE, "rt_trace.alpha_masks"}),
      clearer_(ctx) {
    VkPhysicalDeviceProperties properties{};
    vkGetPhysicalDeviceProperties(ctx.physicalDevice(), &properties);
    subPixelPrecisionBits_ = properties.limits.subPixelPrecisionBits;
    if (backend_ == RtBackend::Auto && !supported(ctx, RtBackend::Auto)) {
        throw gpu::GpuError(unsupportedMessage(ctx, RtBackend::Auto));
    }
    if (backend_ == RtBackend::Auto) {
        // Ray query first: one dispatch, no shader binding table, and the
        // hit shading stays in the same invocation.
        backend_ = ctx.caps().rayQuery ? RtBackend::RayQuery : RtBackend::Pipeline;
    }
    backend_ = prepare(backend_);
}

RtTracePipelines::~RtTracePipelines() = default;

RtBackend RtTracePipelines::prepare(RtBackend requested) {
    const RtBackend backend = requested == RtBackend::Auto ? backend_ : requested;
    if (!supported(ctx_, backend)) {
        throw gpu::GpuError(unsupportedMessage(ctx_, backend));
    }
    if (backend == RtBackend::RayQuery && !query_) {
        query_ = gpu::createComputePipeline(
            ctx_, {"rt_trace/trace_query.comp", {}, 0, "rt_trace.query"});
    }
    if (backend == RtBackend::Pipeline && !pipeline_) {
        // Depth 1: the ray generation shader traces both rays and shades;
        // the hit shaders trace nothing. The any-hit shader runs only on
        // alpha-tested geometry (the rest is opaque in its BLAS).
        pipeline_ = gpu::createRayTracingPipeline(
            ctx_, {"rt_trace/trace.rgen",
                   {"rt_trace/trace.rmiss"},
                   {{"rt_trace/trace.rchit", "rt_trace/trace.rahit"}},
                   {},
                   0,
                   1,
                   "rt_trace.pipeline"});
        sbt_.emplace(ctx_, *pipeline_, 1, 1);
    }
    return backend;
}

float rtRasterErrorPerDistance(const glm::mat4& projection, uint32_t width, uint32_t height,
                               uint32_t subPixelBits) {
    // One pixel's angle (its size at unit distance) across and down.
    const float across = 2.0f / (std::abs(projection[0][0]) * float(std::max(width, 1u)));
    const float down = 2.0f / (std::abs(projection[1][1]) * float(std::max(height, 1u)));
    return std::max(across, down) * std::ldexp(1.0f, -int(subPixelBits));
}

RtTraceOutputs addRtTracePass(rg::Graph& graph, RtTracePipelines& pipelines, const RtTraceInputs& inputs,
                              const RtTraceSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (gbuf.width == 0 || gbuf.height == 0) {
        throw gpu::GpuError("addRtTracePass: the G-buffer has no size");
    }
    if (!inputs.rayList.valid() || !inputs.rayListArgs.valid()) {
        throw gpu::GpuError("addRtTracePass: the RT ray list and its args are required");
    }
    if (!inputs.bvh.tlas.valid() || !inputs.bvh.primitivePool.valid() || !inputs.bvh.primitiveOffsets.valid() ||
        !inputs.bvh.materials.valid() || !inputs.bvh.alphaTriangles.valid() || !inputs.bvh.alphaMasks.valid() ||
        !inputs.bvh.deformMotion.valid()) {
        throw gpu::GpuError("addRtTracePass: the BVH update's TLAS, primitive pool, offsets, material rows, alpha "
                            "test data and deform motion are required");
    }
    if (!(inputs.maxDistance > 0.0f) || !(settings.shortRangeFraction >= 0.0f) ||
        !(inputs.shadowDistance >= 0.0f) || !(settings.originOffsetScale >= 0.0f)) {
        throw gpu::GpuError("addRtTracePass: maxDistance must be positive; shortRangeFraction, shadowDistance and "
                            "originOffsetScale not negative");
    }
    const RtBackend backend = pipelines.prepare(settings.backend);

    shader::RtTraceConstants constants{};
    // The matrices the G-buffer was rasterised with, jitter included: a
    // pixel's depth belongs to its jittered sample, so reconstructing there
    // puts the origin on the surface (the unjittered matrix would move it up
    // to half a pixel's footprint along the view ray, which on a surface
    // seen at a grazing angle is nearly along its normal). In double: far
    // from the world's origin a float inverse adds error of its own.
    const glm::dmat4 viewProjection =
        glm::dmat4(inputs.camera.jitteredProjection) * glm::dmat4(inputs.camera.view);
    constants.inverseViewProjection = glm::mat4(glm::inverse(viewProjection));
    constants.cameraPosition = glm::vec4(inputs.camera.position, 1.0f);
    constants.lighting = inputs.lighting;
    if (inputs.lighting.environment.x != 0.0f && !inputs.environment.valid()) {
        throw gpu::GpuError("rt_trace: the lighting looks up an environment image but no environment texture was given "
                            "(passes::importEnvironment)");
    }
    constants.size = {gbuf.width, gbuf.height};
    constants.maxDistance = inputs.maxDistance;
    constants.shortRangeRoughness = settings.shortRangeRoughness;
    constants.shortRangeFraction = settings.shortRangeFraction;
    constants.shadowDistance = inputs.shadowDistance;
    constants.originOffsetScale = settings.originOffsetScale;
    constants.rasterErrorPerDistance =
        rtRasterErrorPerDistance(inputs.camera.projection, gbuf.width, gbuf.height, pipelines.subPixelPrecisionBits_);
    constants.shadows = settings.shadows ? 1u : 0u;
    constants.instanceMask = settings.instanceMask & 0xFFu;
    constants.alphaTest = settings.alphaTest ? 1u : 0u;
    // The map is read only where the G-buffer rendered one this frame.
    const bool shadowMap = settings.shadows && settings.shadowMapAtHits && gbuf.shadowMap.valid() &&
                           gbuf.shadow.enabled != 0u;
    constants.shadowMapAtHits = shadowMap ? 1u : 0u;
    constants.shadow = gbuf.shadow;

    // This frame's constants, which are larger than push constants
    // guarantee. The outputs are written at the listed rays' pixels only,
    // and read nowhere else (passes/integrate.h): no clear, unless asked for.
    const rg::Buffer uploaded = rg::addUpload(graph, "rt_trace.constants", constants);
    const auto texture = [&](const char* name, VkFormat format) {
        return graph.createTexture(name, {.width = gbuf.width, .height = gbuf.height, .format = format});
    };
    std::array<rg::Texture, 3> outputs{texture("rt_trace.radiance", kRtRadianceFormat),
                                       texture("rt_trace.hit_distance", kRtHitDistanceFormat),
                                       texture("rt_trace.hit_motion", kRtHitMotionFormat)};
    if (settings.clearUntraced) {
        pipelines.clearer_.addClearPass(graph, "rt_trace.clear", outputs);
    }
    const auto [radiance, hitDistance, hitMotion] = outputs;

    struct TraceData {
        rg::Texture depth, normal, roughnessMetal;
        rg::Texture environment;  // the prefiltered image, or the normal as a stand-in (never read)
        rg::Texture shadowMap;    // the G-buffer's shadow map, or the depth as a stand-in (never read)
        rg::Texture alphaMasks;
        rg::Buffer rayList, rayListArgs, pool, offsets, materials, alphaTriangles, deformMotion, constants;
        rg::AccelStruct tlas;
        RtTraceOutputs out;
    };
    const TraceData& trace = graph.addPass<TraceData>(
        "rt_trace", rg::Queue::Graphics,
        [&](rg::Builder& b, TraceData& d) {
            b.setPipeline(backend == RtBackend::RayQuery ? rg::Pipeline::Compute : rg::Pipeline::RayTracing);
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            // The procedural sky reads no texture: the normal fills the binding.
            d.environment = inputs.environment.valid() ? b.read(inputs.environment, rg::Access::SampledRead) : d.normal;
            d.shadowMap = shadowMap ? b.read(gbuf.shadowMap, rg::Access::SampledRead) : d.depth;
            d.rayList = b.read(inputs.rayList, rg::Access::StorageRead);
            // The indirect command, and the list's length for the ray query
            // backend's last, partial group.
            d.rayListArgs = b.read(inputs.rayListArgs, rg::Access::IndirectArgs);
            b.read(inputs.rayListArgs, rg::Access::StorageRead);
            d.tlas = b.read(inputs.bvh.tlas, rg::Access::AccelRead);
            d.pool = b.read(inputs.bvh.primitivePool, rg::Access::StorageRead);
            d.offsets = b.read(inputs.bvh.primitiveOffsets, rg::Access::StorageRead);
            d.materials = b.read(inputs.bvh.materials, rg::Access::StorageRead);
            d.alphaTriangles = b.read(inputs.bvh.alphaTriangles, rg::Access::StorageRead);
            d.alphaMasks = b.read(inputs.bvh.alphaMasks, rg::Access::SampledRead);
            d.deformMotion = b.read(inputs.bvh.deformMotion, rg::Access::StorageRead);
            d.constants = b.read(uploaded, rg::Access::StorageRead);
            d.out.width = gbuf.width;
            d.out.height = gbuf.height;
            d.out.radiance = b.write(radiance, rg::Access::StorageWrite);
            d.out.hitDistance = b.write(hitDistance, rg::Access::StorageWrite);
            d.out.hitMotion = b.write(hitMotion, rg::Access::StorageWrite);
        },
        [&pipelines, backend](const TraceData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = backend == RtBackend::RayQuery ? *pipelines.query_ : *pipelines.pipeline_;
            const VkSampler sampler = pipelines.nearest_.handle();
            const VkSampler environmentSampler =
                d.environment == d.normal ? sampler : pipelines.environmentSampler_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .accelerationStructure("tlas", pc.accel(d.tlas).handle())
                .sampledImage("environmentTexture", pc.view(d.environment), environmentSampler,
                              pc.layout(d.environment))
                .sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("shadowMapTexture", pc.view(d.shadowMap), sampler, pc.layout(d.shadowMap))
                .sampledImage("normalTexture", pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage("roughnessMetalTexture", pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                .storageBuffer("RayList", pc.buffer(d.rayList))
                .storageBuffer("RayListArgs", pc.buffer(d.rayListArgs))
                .storageBuffer("Pool", pc.buffer(d.pool))
                .storageBuffer("Offsets", pc.buffer(d.offsets))
                .storageBuffer("GeometryMaterials", pc.buffer(d.materials))
                .storageBuffer("AlphaTriangles", pc.buffer(d.alphaTriangles))
                .sampledImage("alphaMasks", pc.view(d.alphaMasks), pipelines.alphaSampler_.handle(),
                              pc.layout(d.alphaMasks))
                .storageBuffer("DeformMotions", pc.buffer(d.deformMotion))
                .storageBuffer("Constants", pc.buffer(d.constants))
                .storageImage("radianceImage", pc.view(d.out.radiance))
                .storageImage("hitDistanceImage", pc.view(d.out.hitDistance))
                .storageImage("hitMotionImage", pc.view(d.out.hitMotion))
                .push(pc.gpu(), pc.cmd());
            if (backend == RtBackend::RayQuery) {
                pc.dispatchIndirect(pipeline, d.rayListArgs, kDispatchArgsBytes);
            } else {
                // {count, 1, 1}: one launch per entry, read by device address.
                const gpu::ShaderBindingTable& sbt = *pipelines.sbt_;
                pc.gpu().fn().cmdTraceRaysIndirect(pc.cmd(), &sbt.raygen(), &sbt.miss(), &sbt.hit(), &sbt.callable(),
                                                   pc.buffer(d.rayListArgs).address() + kTraceArgsBytes);
            }
        });
    return trace.out;
}

} // namespace glint::passes
