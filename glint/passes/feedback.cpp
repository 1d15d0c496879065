#include "glint/passes/feedback.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"

#include "glint/feedback_shared.h"
#include "glint/ray_generation_shared.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace glint::passes {

namespace {

constexpr uint32_t kGroupSize = 64;  // reproject.comp's local_size_x

} // namespace

FeedbackPipelines::FeedbackPipelines(gpu::Context& ctx)
    : ctx_(ctx),
      reproject_(gpu::createComputePipeline(ctx, {"feedback/reproject.comp", {},
                                                  uint32_t(sizeof(shader::FeedbackConstants)),
                                                  "feedback.reproject"})),
      // The motion is read texel by texel (texelFetch); the sampler only
      // completes the combined descriptor.
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "feedback.nearest"}) {}

uint32_t feedbackMinFrameHits(const FeedbackSettings& settings, uint32_t width, uint32_t height) {
    return uint32_t(std::ceil(double(settings.sslrMinHitShare) * double(width) * double(height)));
}

bool hostProbeFrame(uint64_t frame, uint32_t probeInterval, uint32_t stride) {
    const uint64_t block = frame / std::max(probeInterval, 1u);
    return shader::feedbackProbeFrame(uint32_t(frame), probeInterval) && block % std::max(stride, 1u) == 0;
}

FeedbackOutputs addFeedbackPass(rg::Graph& graph, FeedbackPipelines& pipelines, const FeedbackInputs& inputs,
                                const FeedbackSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (gbuf.width == 0 || gbuf.height == 0) {
        throw gpu::GpuError("addFeedbackPass: the G-buffer has no size");
    }
    const auto fraction = [](float f) { return f >= 0.0f && f <= 1.0f; };
    if (!fraction(settings.sslrMissFraction) || !fraction(settings.rtHitFraction)) {
        throw gpu::GpuError("addFeedbackPass: sslrMissFraction and rtHitFraction must lie in [0, 1] (got " +
                            std::to_string(settings.sslrMissFraction) + ", " + std::to_string(settings.rtHitFraction) +
                            ")");
    }
    if (!fraction(settings.sslrMinHitShare) || settings.sslrProbeInterval == 0) {
        throw gpu::GpuError("addFeedbackPass: sslrMinHitShare must lie in [0, 1] and sslrProbeInterval be at least 1 "
                            "(got " + std::to_string(settings.sslrMinHitShare) + ", " +
                            std::to_string(settings.sslrProbeInterval) + ")");
    }
    if (settings.sslrProbeIntervalMax < settings.sslrProbeInterval) {
        throw gpu::GpuError("addFeedbackPass: sslrProbeIntervalMax (" + std::to_string(settings.sslrProbeIntervalMax) +
                            ") must be at least sslrProbeInterval (" + std::to_string(settings.sslrProbeInterval) + ")");
    }
    FeedbackOutputs out;
    out.tilesX = (gbuf.width + shader::kTileSize - 1) / shader::kTileSize;
    out.tilesY = (gbuf.height + shader::kTileSize - 1) / shader::kTileSize;
    const uint32_t tiles = out.tilesX * out.tilesY;
    const uint64_t tileBytes = uint64_t(tiles) * sizeof(uint32_t);
    out.minFrameHits = feedbackMinFrameHits(settings, gbuf.width, gbuf.height);
    // The tiles' counters and the frame's sum of hits. A resize starts the
    // pair afresh (zeroed); the shaders still bound their indices by the
    // buffer's own length.
    out.counters = graph.createHistoryBuffer(kFeedbackHistoryName, {tileBytes + sizeof(uint32_t)});

    shader::FeedbackConstants constants{};
    constants.size = {gbuf.width, gbuf.height};
    constants.tiles = {out.tilesX, out.tilesY};
    // The same 32-bit frame as the rest of the noise (glint/sampling.glsl).
    constants.frame = uint32_t(inputs.frameIndex);
    constants.minRays = settings.minRays;
    constants.sslrMissFraction = settings.sslrMissFraction;
    constants.rtHitFraction = settings.rtHitFraction;
    constants.adaptive = settings.adaptive ? 1u : 0u;
    constants.resetHistory = inputs.resetHistory ? 1u : 0u;
    constants.minFrameHits = out.minFrameHits;
    constants.probeInterval = settings.sslrProbeInterval;
    // The report holds last frame's hits when last frame wrote counters.
    const bool reports = inputs.report.valid() && inputs.reportLastFrame;
    constants.report = !reports                  ? shader::kFeedbackReportNone
                       : inputs.screenSpaceIdle ? shader::kFeedbackReportOnly
                                                : shader::kFeedbackReport;

    struct ReprojectData {
        rg::Texture motion;
        rg::Buffer previous, report;
        FeedbackOutputs out;
    };
    const ReprojectData& reproject = graph.addPass<ReprojectData>(
        "feedback", rg::Queue::Graphics,
        [&](rg::Builder& b, ReprojectData& d) {
            d.motion = b.read(gbuf.motion, rg::Access::SampledRead);
            d.previous = b.read(out.counters.previous, rg::Access::StorageRead);
            if (inputs.report.valid()) d.report = b.write(inputs.report, rg::Access::StorageWrite);
            d.out = out;
            // Starts the frame's sum of hits; integrate writes the rest.
            d.out.counters.current = b.write(out.counters.current, rg::Access::StorageWrite);
            d.out.reprojected =
                b.write(b.createBuffer("feedback.reprojected", {tileBytes}), rg::Access::StorageWrite);
            d.out.tileModes = b.write(b.createBuffer("feedback.tile_modes", {tileBytes}), rg::Access::StorageWrite);
            // A frame rendered as rt reads no counter: nothing to do unless
            // the report goes out (rg::Builder::skip: no barrier either).
            if (inputs.screenSpaceIdle && !reports) b.skip();
        },
        [&pipelines, constants, tiles](const ReprojectData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.reproject_;
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .sampledImage("motionTexture", pc.view(d.motion), pipelines.nearest_.handle(), pc.layout(d.motion))
                .storageBuffer("Previous", pc.buffer(d.previous))
                .storageBuffer("Reprojected", pc.buffer(d.out.reprojected))
                .storageBuffer("TileModes", pc.buffer(d.out.tileModes))
                .storageBuffer("Current", pc.buffer(d.out.counters.current))
                .storageBuffer("Report", pc.buffer(d.report.valid() ? d.report : d.out.counters.current))
                .push(pipelines.ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            const bool reportOnly = constants.report == shader::kFeedbackReportOnly;
            pc.dispatch(pipeline, reportOnly ? 1u : (tiles + kGroupSize - 1) / kGroupSize);
        });
    return reproject.out;
}

} // namespace glint::passes
