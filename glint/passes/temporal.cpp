#include "glint/passes/temporal.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/transfer.h"

#include "glint/temporal_shared.h"

#include <cmath>
#include <string>
#include <vector>

namespace glint::passes {

namespace {

// Workgroups of `side` pixels across `pixels`.
uint32_t groups(uint32_t pixels, uint32_t side) { return (pixels + side - 1) / side; }

void checkSettings(const TemporalSettings& s) {
    const bool ok = std::isfinite(s.maxHistoryFrames) && s.maxHistoryFrames >= 1.0f && std::isfinite(s.clampGamma) &&
                    s.clampGamma > 0.0f && s.maxRadiance > 0.0f && s.maxRadiance <= 65504.0f &&
                    s.planeTolerance > 0.0f && s.roughnessTolerance >= 0.0f &&
                    s.surfaceMotionRoughnessStart <= s.surfaceMotionRoughnessEnd &&
                    s.spatialRoughnessStart <= s.spatialRoughnessEnd &&
                    s.spatialRadius <= shader::kTemporalMaxSpatialRadius &&
                    s.spatialNoiseFreeRadius <= shader::kTemporalMaxSpatialRadius &&
                    s.clampRadius <= shader::kTemporalMaxClampRadius && s.spatialPlaneSigma > 0.0f &&
                    s.spatialRoughnessSigma > 0.0f;
    if (!ok) {
        throw gpu::GpuError(
            "addTemporalPass: invalid settings (maxHistoryFrames >= 1, clampGamma > 0, 0 < maxRadiance <= 65504, "
            "positive tolerances and sigmas, ramps with start <= end, spatialRadius and spatialNoiseFreeRadius <= 4, "
            "clampRadius <= 3)");
    }
}

shader::TemporalFrame frameConstants(const TemporalInputs& in, const TemporalSettings& s) {
    const scene::Camera& c = in.camera;
    shader::TemporalFrame f{};
    f.viewProjection = c.viewProjection();
    f.inverseViewProjection = glm::inverse(c.jitteredProjection * c.view);
    f.previousViewProjection = c.previousViewProjection();
    f.previousInverseViewProjection = glm::inverse(c.previousJitteredProjection * c.previousView);
    f.cameraPosition = glm::vec4(c.position, 1.0f);
    f.previousCameraPosition = glm::vec4(c.previousPosition, 1.0f);
    f.size = {in.gbuffer.width, in.gbuffer.height};
    // The first frame needs no flag: the executor creates the history
    // cleared, and a length of 0 is no history.
    f.resetHistory = in.resetHistory ? 1u : 0u;
    f.neighbourhoodClamp = s.neighbourhoodClamp ? 1u : 0u;
    f.maxHistoryFrames = s.maxHistoryFrames;
    f.clampGamma = s.clampGamma;
    f.planeTolerance = s.planeTolerance;
    f.normalTolerance = s.normalTolerance;
    f.roughnessTolerance = s.roughnessTolerance;
    f.surfaceMotionRoughnessStart = s.surfaceMotionRoughnessStart;
    f.surfaceMotionRoughnessEnd = s.surfaceMotionRoughnessEnd;
    f.maxRadiance = s.maxRadiance;
    f.spatialRadius = s.spatialRadius;
    f.spatialRoughnessStart = s.spatialRoughnessStart;
    f.spatialRoughnessEnd = s.spatialRoughnessEnd;
    f.spatialPlaneSigma = s.spatialPlaneSigma;
    f.spatialNormalPower = s.spatialNormalPower;
    f.spatialRoughnessSigma = s.spatialRoughnessSigma;
    f.spatialRoughnessMax = s.spatialRoughnessMax;
    f.hitMotionBound = in.hitMotion.valid() ? 1u : 0u;
    f.clampRadius = s.clampRadius;
    f.sharedRayRoughness = in.sharedRayRoughness;
    f.environmentRoughness = in.environmentRoughness;
    f.debugOutputs = in.debugOutputs ? 1u : 0u;
    f.frame = uint32_t(in.frameIndex);
    f.spatialNoiseFreeRadius = s.spatialNoiseFreeRadius;
    f.oneHistoryCandidate = s.oneHistoryCandidate ? 1u : 0u;
    return f;
}

} // namespace

TemporalPipelines::TemporalPipelines(gpu::Context& ctx)
    : ctx_(ctx),
      accumulate_(
          gpu::createComputePipeline(ctx, {"temporal/accumulate.comp", {}, 0, "temporal.accumulate"})),
      spatial_(gpu::createComputePipeline(ctx, {"temporal/spatial.comp", {}, 0, "temporal.spatial"})),
      // Every read is a texelFetch; the sampler only completes the combined
      // descriptor.
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "temporal.nearest"}) {}

TemporalOutputs addTemporalPass(rg::Graph& graph, TemporalPipelines& pipelines, const TemporalInputs& inputs,
                                const TemporalSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (gbuf.width == 0 || gbuf.height == 0) {
        throw gpu::GpuError("addTemporalPass: the G-buffer has no pixels");
    }
    if (!inputs.radiance.valid() || !inputs.hitDistance.valid()) {
        throw gpu::GpuError("addTemporalPass: the radiance and the hit distance are required");
    }
    checkSettings(settings);
    for (const rg::Texture t : {inputs.radiance, inputs.hitDistance, inputs.hitMotion}) {
        if (!t.valid()) continue;
        if (t.graph == graph.id() && t.index < graph.declaration().resources.size()) {
            const rg::TextureDesc& d = graph.declaration().resources[t.index].texture;
            if (d.width != gbuf.width || d.height != gbuf.height) {
                const std::string name(graph.declaration().resources[t.index].name);
                throw gpu::GpuError("addTemporalPass: '" + name + "' must have the G-buffer's size");
            }
        }
    }

    TemporalOutputs out;
    out.width = gbuf.width;
    out.height = gbuf.height;
    const auto desc = [&](VkFormat format) {
        return rg::TextureDesc{.width = gbuf.width, .height = gbuf.height, .format = format};
    };
    // The executor keeps history pairs by name; the size in the name makes
    // a new resolution start from a new, cleared pair instead of reusing
    // images of the old size.
    const std::string suffix = "." + std::to_string(gbuf.width) + "x" + std::to_string(gbuf.height);
    const rg::HistoryTexture radianceHistory =
        graph.createHistoryTexture("temporal.radiance" + suffix, desc(kTemporalRadianceHistoryFormat));
    const rg::HistoryTexture surfaceHistory =
        graph.createHistoryTexture("temporal.surface" + suffix, desc(kTemporalSurfaceHistoryFormat));

    // The constants (four matrices: more than push constants guarantee)
    // reach the shaders through a uniform buffer the graph owns, filled on
    // the GPU timeline so frames in flight never share one.
    const rg::Buffer uploaded = rg::addUpload(graph, "temporal.constants", frameConstants(inputs, settings));

    struct AccumulateData {
        rg::Buffer frame;
        rg::Texture depth, normal, roughnessMetal, motion, radiance, hitDistance, previousRadiance, previousSurface;
        rg::Texture hitMotion;  // the reflected points' motion, or the hit distance as a stand-in (never read)
        rg::Texture radianceOut, surfaceOut, motionOut, lengthOut;
    };
    const AccumulateData& accumulate = graph.addPass<AccumulateData>(
        "temporal.accumulate", rg::Queue::Graphics,
        [&](rg::Builder& b, AccumulateData& d) {
            d.frame = b.read(uploaded, rg::Access::SampledRead);
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            d.motion = b.read(gbuf.motion, rg::Access::SampledRead);
            d.radiance = b.read(inputs.radiance, rg::Access::SampledRead);
            d.hitDistance = b.read(inputs.hitDistance, rg::Access::SampledRead);
            d.hitMotion = inputs.hitMotion.valid() ? b.read(inputs.hitMotion, rg::Access::SampledRead) : d.hitDistance;
            d.previousRadiance = b.read(radianceHistory.previous, rg::Access::SampledRead);
            d.previousSurface = b.read(surfaceHistory.previous, rg::Access::SampledRead);
            d.radianceOut = b.write(radianceHistory.current, rg::Access::StorageWrite);
            d.surfaceOut = b.write(surfaceHistory.current, rg::Access::StorageWrite);
            d.motionOut = b.write(b.createTexture("temporal.reflection_motion", desc(kTemporalMotionFormat)),
                                  rg::Access::StorageWrite);
            d.lengthOut = b.write(b.createTexture("temporal.history_length", desc(kTemporalHistoryLengthFormat)),
                                  rg::Access::StorageWrite);
        },
        [&pipelines, width = gbuf.width, height = gbuf.height](const AccumulateData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.accumulate_;
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .uniformBuffer("Frame", pc.buffer(d.frame))
                .sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("normalTexture", pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage("roughnessMetalTexture", pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                .sampledImage("motionTexture", pc.view(d.motion), sampler, pc.layout(d.motion))
                .sampledImage("radianceTexture", pc.view(d.radiance), sampler, pc.layout(d.radiance))
                .sampledImage("hitDistanceTexture", pc.view(d.hitDistance), sampler, pc.layout(d.hitDistance))
                .sampledImage("hitMotionTexture", pc.view(d.hitMotion), sampler, pc.layout(d.hitMotion))
                .sampledImage("previousRadianceTexture", pc.view(d.previousRadiance), sampler,
                              pc.layout(d.previousRadiance))
                .sampledImage("previousSurfaceTexture", pc.view(d.previousSurface), sampler,
                              pc.layout(d.previousSurface))
                .storageImage("radianceHistory", pc.view(d.radianceOut))
                .storageImage("surfaceHistory", pc.view(d.surfaceOut))
                .storageImage("motionImage", pc.view(d.motionOut))
                .storageImage("lengthImage", pc.view(d.lengthOut))
                .push(pipelines.ctx_, pc.cmd());
            constexpr uint32_t side = shader::kTemporalAccumulateGroupSize;
            pc.dispatch(pipeline, groups(width, side), groups(height, side));
        });

    struct SpatialData {
        rg::Buffer frame;
        rg::Texture depth, surface, accumulated, radiance;
        rg::Texture resolved;
    };
    const SpatialData& spatial = graph.addPass<SpatialData>(
        "temporal.spatial", rg::Queue::Graphics,
        [&](rg::Builder& b, SpatialData& d) {
            d.frame = b.read(accumulate.frame, rg::Access::SampledRead);
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.surface = b.read(accumulate.surfaceOut, rg::Access::SampledRead);
            d.accumulated = b.read(accumulate.radianceOut, rg::Access::SampledRead);
            d.radiance = b.read(inputs.radiance, rg::Access::SampledRead);
            d.resolved = b.write(b.createTexture("temporal.resolved", desc(kTemporalResolvedFormat)),
                                 rg::Access::StorageWrite);
        },
        [&pipelines, width = gbuf.width, height = gbuf.height](const SpatialData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.spatial_;
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .uniformBuffer("Frame", pc.buffer(d.frame))
                .sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("surfaceTexture", pc.view(d.surface), sampler, pc.layout(d.surface))
                .sampledImage("accumulatedTexture", pc.view(d.accumulated), sampler, pc.layout(d.accumulated))
                .sampledImage("radianceTexture", pc.view(d.radiance), sampler, pc.layout(d.radiance))
                .storageImage("resolvedImage", pc.view(d.resolved))
                .push(pipelines.ctx_, pc.cmd());
            constexpr uint32_t side = shader::kTemporalSpatialGroupSize;
            pc.dispatch(pipeline, groups(width, side), groups(height, side));
        });

    out.resolved = spatial.resolved;
    if (inputs.debugOutputs) {
        out.reflectionMotion = accumulate.motionOut;
        out.historyLength = accumulate.lengthOut;
    }
    return out;
}

} // namespace glint::passes
