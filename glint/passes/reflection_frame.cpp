#include "glint/passes/reflection_frame.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/passes/lighting.h"

#include "glint/feedback_shared.h"
#include "glint/reflection_frame_shared.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace glint::passes {

namespace {

constexpr std::array<std::string_view, 3> kModeNames = {"hybrid", "ssr", "rt"};
constexpr std::array<std::string_view, 3> kBackendNames = {"auto", "query", "pipeline"};

// Passes that make up the reflections' cost, by name prefix.
constexpr std::array<std::string_view, 7> kReflectionPassPrefixes = {
    "feedback", "ray_generation", "sslr", "rt_trace", "particles.trace", "integrate", "temporal"};

} // namespace

std::string_view modeName(ReflectionMode mode) { return kModeNames.at(size_t(mode)); }

ReflectionMode parseMode(std::string_view name) {
    for (size_t i = 0; i < kModeNames.size(); ++i) {
        if (kModeNames[i] == name) return ReflectionMode(i);
    }
    throw std::invalid_argument("unknown reflection mode '" + std::string(name) + "' (hybrid, ssr, rt)");
}

std::string_view backendName(RtBackend backend) { return kBackendNames.at(size_t(backend)); }

RtBackend parseBackend(std::string_view name) {
    for (size_t i = 0; i < kBackendNames.size(); ++i) {
        if (kBackendNames[i] == name) return RtBackend(i);
    }
    throw std::invalid_argument("unknown ray tracing backend '" + std::string(name) + "' (auto, query, pipeline)");
}

bool isReflectionPass(std::string_view passName) {
    for (const std::string_view prefix : kReflectionPassPrefixes) {
        if (passName.substr(0, prefix.size()) == prefix) return true;
    }
    return false;
}

ReflectionRenderer::ReflectionRenderer(gpu::Context& ctx, const scene::Scene& scene,
                                       const ReflectionRendererOptions& options)
    : ctx_(ctx),
      scene_(scene),
      environment_(ctx, scene, options.environment),
      gbuffer_(ctx, scene, options.framesInFlight),
      planner_(options.bvh),
      bvh_(ctx.caps().canTraceRays()
               ? std::make_unique<BvhManager>(ctx, scene, options.framesInFlight, options.bvhUpdate)
               : nullptr),
      feedback_(ctx),
      rays_(ctx),
      sslr_(ctx),
      rt_(ctx.caps().canTraceRays() ? std::make_unique<RtTracePipelines>(ctx, options.backend) : nullptr),
      integrate_(ctx),
      temporal_(ctx),
      composite_(ctx),
      particles_(ctx, ctx.caps().canTraceRays() ? options.backend : RtBackend::Auto),
      tileView_(gpu::createComputePipeline(ctx, {"reflection_frame/tile_view.comp", {},
                                                 uint32_t(sizeof(shader::TileViewConstants)),
                                                 "reflection_frame.tile_view"})),
      classCount_(gpu::createComputePipeline(ctx, {"reflection_frame/class_count.comp", {},
                                                   uint32_t(sizeof(shader::ClassCountConstants)),
                                                   "reflection_frame.class_count"})) {
    if (rt_) {
        gateReadback_ = std::make_unique<rg::FrameReadback>(ctx, sizeof(uint32_t), "reflections.sslr_gate",
                                                            options.framesInFlight + 2);
    } else {
        spdlog::warn("device '{}' has no ray tracing{}: hybrid and rt reflections render as ssr, and no BVH is built",
                     ctx.caps().deviceName,
                     ctx.caps().accelerationStructure ? " (acceleration structures but neither ray query nor ray "
                                                        "tracing pipelines)"
                                                      : " (no VK_KHR_acceleration_structure, or disabled)");
    }
}

RtBackend ReflectionRenderer::backend() const { return rt_ ? rt_->backend() : RtBackend::Auto; }

const BvhGpuStats& ReflectionRenderer::bvhGpuStats() const {
    static const BvhGpuStats none{};
    return bvh_ ? bvh_->stats() : none;
}

ReflectionRenderer::~ReflectionRenderer() {
    // Before any member goes: frames in flight use every member's pipelines
    // (after a device error the caller may not have waited).
    ctx_.waitIdleForTeardown("reflection renderer");
}

void ReflectionRenderer::bind(rg::FrameResources& resources, const ReflectionFrame& frame) const {
    if (frame.bvh) {
        bvh_->bind(resources, *frame.bvh);
    }
    environment_.bind(resources, frame.environment);
    if (frame.gateReport) {
        gateReadback_->bind(resources, *frame.gateReport);
    }
}

bool ReflectionRenderer::screenSpaceIdle(const ReflectionFrameSettings& settings, uint64_t frameIndex,
                                         uint32_t width, uint32_t height) {
    const FeedbackSettings& feedback = settings.feedback;
    if (settings.resetHistory) {
        // A cut: what earlier frames said no longer holds.
        gatePending_ = 0;
        sslrPays_ = true;
        probeStride_ = 1;
    }
    if (gatePending_ != 0) {
        if (const auto bytes = gateReadback_->read(gatePending_)) {
            uint32_t word = 0;
            std::memcpy(&word, bytes->data(), sizeof(word));
            const bool pays = shader::sslrPays(word, feedbackMinFrameHits(feedback, width, height), false, false);
            // A probe that found SSLR still not paying: the next ones come
            // half as often, down to one in sslrProbeIntervalMax frames.
            const uint32_t maxStride =
                std::max(feedback.sslrProbeIntervalMax / std::max(feedback.sslrProbeInterval, 1u), 1u);
            probeStride_ = pays ? 1 : sslrPays_ ? probeStride_ : std::min(probeStride_ * 2, maxStride);
            sslrPays_ = pays;
            spdlog::debug("SSLR gate: frame {} read report {}: {} SSLR hits last frame, SSLR {}; a probe every {} frames",
                          frameIndex, gatePending_, word - std::min(word, shader::kFeedbackFrameHitsStart),
                          sslrPays_ ? "pays" : "does not pay", feedback.sslrProbeInterval * probeStride_);
            gatePending_ = 0;
        } else if (gateReadback_->overwritten(gatePending_)) {
            gatePending_ = 0;
        }
    }
    return !sslrPays_ && !settings.resetHistory &&
           !hostProbeFrame(frameIndex, feedback.sslrProbeInterval, probeStride_);
}

ReflectionFrame ReflectionRenderer::addFrame(rg::Graph& graph, const scene::Camera& camera,
                                             const ReflectionFrameSettings& settings) {
    // Without ray tracing every mode is ssr (the constructor said so once).
    if (!(settings.reach > 0.0f)) {
        throw gpu::GpuError("ReflectionFrameSettings::reach " + std::to_string(settings.reach) + ": must be positive");
    }
    if (!(settings.confidenceThreshold >= 0.0f && settings.confidenceThreshold <= 1.0f)) {
        throw gpu::GpuError("ReflectionFrameSettings::confidenceThreshold " +
                            std::to_string(settings.confidenceThreshold) + ": must be in [0, 1]");
    }
    const ReflectionMode mode = rt_ ? settings.mode : ReflectionMode::Ssr;
    const std::string_view view = settings.debugView;
    const uint64_t frameIndex = camera.frameIndex;
    const bool traces = mode != ReflectionMode::Ssr;
    const bool screenSpace = mode != ReflectionMode::Rt;
    // The sky colours and the prefiltered image are the environment map's,
    // computed once per environment, not per frame.
    environment_.update();
    const shader::SceneLighting lighting = environment_.lighting(settings.gbuffer.lighting);

    ReflectionFrame f;
    f.environment = importEnvironment(graph, environment_);
    f.mode = mode;
    f.width = camera.resolution.x;
    f.height = camera.resolution.y;

    // 0. BVH: only when something traces; on the async compute queue.
    if (traces) {
        scene::BvhPlan plan = planner_.plan(scene_, camera, settings.reach);
        plan.particleTlas = plan.particleTlas && settings.reflectParticles;
        lastPlanStats_ = plan.stats;
        f.bvhComplete = plan.complete();
        f.bvh = addBvhUpdatePass(graph, *bvh_, plan, camera);
    }
    // 1. G-buffer; with SSLR particles, the particles drawn into its lit
    // colour before anything samples it.
    f.gbuffer = addGBufferPass(graph, gbuffer_, {camera, lighting, f.environment}, settings.gbuffer);
    if (settings.sslrParticles) {
        f.gbuffer.lit = addParticleForwardPass(graph, particles_, {f.gbuffer, scene_.particles, camera}).lit;
    }
    // 6 (of last frame). Feedback: only the hybrid band follows tile modes.
    RayGenerationInputs rayInputs{f.gbuffer, frameIndex, camera};
    rayInputs.mode = mode;
    rayInputs.sslrMinDistance = settings.reach;
    rayInputs.debugOutputs = view == "ray_classes";
    const bool sslrFallback = !f.bvhComplete && settings.sslrWhileBvhBuilds && screenSpace;
    // The traces write only their rays' pixels; a debug view of their raw
    // outputs shows the rest cleared rather than stale.
    const bool viewsSslr = view.substr(0, 5) == "sslr_" || view == "lit_pyramid";
    const bool viewsRt = view.substr(0, 3) == "rt_";
    if (mode == ReflectionMode::Hybrid) {
        const FeedbackSettings& fs = settings.feedback;
        // The host's gate: where SSLR did not pay on the last frame read
        // back, a frame that is not a probe frame renders as rt.
        const bool hostGate = fs.hostGate && fs.adaptive && fs.sslrMinHitShare > 0.0f;
        FeedbackInputs feedbackInputs{f.gbuffer, frameIndex, settings.resetHistory};
        if (hostGate) {
            // Views of what the feedback and SSLR write need them written.
            const bool viewsScreenSpace = viewsSslr || view == "tile_modes" || view == "feedback_counters";
            f.screenSpaceIdle =
                screenSpaceIdle(settings, frameIndex, f.width, f.height) && !sslrFallback && !viewsScreenSpace;
            f.sslrProbeSpacing = sslrPays_ ? 0 : fs.sslrProbeInterval * probeStride_;
            // A probe while the gate is closed: counted, rendered as rt.
            f.sslrCountsOnly = fs.probesRenderAsRt && !sslrPays_ && !f.screenSpaceIdle && !sslrFallback &&
                               !viewsScreenSpace;
            f.gateReport = gateReadback_->declare(graph);
            // The report holds last frame's hits when last frame tried SSLR
            // (else it is not written).
            const bool reports = lastFrame_ == LastFrame::TriedSslr && !settings.resetHistory;
            if (f.gateReport) {
                feedbackInputs.report = f.gateReport->buffer;
                feedbackInputs.reportLastFrame = reports;
                if (reports) gatePending_ = f.gateReport->sequence;
            }
            feedbackInputs.screenSpaceIdle = f.screenSpaceIdle;
            // A frame rendered as rt wrote no counters: the next one that
            // decides starts without evidence, as after a cut.
            feedbackInputs.resetHistory = feedbackInputs.resetHistory ||
                                          (lastFrame_ == LastFrame::RenderedAsRt && !f.screenSpaceIdle);
        }
        f.feedback = addFeedbackPass(graph, feedback_, feedbackInputs, fs);
        rayInputs.tileModes = f.feedback->tileModes;
        rayInputs.screenSpaceIdle = f.screenSpaceIdle;
    }
    lastFrame_ = mode != ReflectionMode::Hybrid ? LastFrame::Other
                 : f.screenSpaceIdle            ? LastFrame::RenderedAsRt
                                                : LastFrame::TriedSslr;
    // 2. Ray generation and tile classification.
    RayGenerationSettings raySettings = settings.rays;
    raySettings.sslrFirst = raySettings.sslrFirst || (sslrFallback && mode == ReflectionMode::Hybrid);
    f.rays = addRayGenerationPass(graph, rays_, rayInputs, raySettings);
    // 3. SSLR, extending the RT list with what it cannot resolve.
    rg::Buffer rtList = f.rays.rtRays;
    rg::Buffer rtArgs = f.rays.rtArgs;
    if (screenSpace) {
        SslrSettings sslrSettings = settings.sslr;
        sslrSettings.clearUntraced = sslrSettings.clearUntraced || viewsSslr;
        f.sslr = addSslrPass(graph, sslr_,
                             {f.gbuffer, f.rays, frameIndex, camera.view, camera.projection,
                              settings.confidenceThreshold, f.screenSpaceIdle, f.sslrCountsOnly},
                             sslrSettings);
        rtList = f.sslr->rtRayList;
        rtArgs = f.sslr->rtArgs;
    }
    // 4. Ray-traced hits.
    if (traces) {
        RtTraceInputs rtInputs;
        rtInputs.gbuffer = f.gbuffer;
        rtInputs.rayList = rtList;
        rtInputs.rayListArgs = rtArgs;
        rtInputs.bvh = *f.bvh;
        rtInputs.lighting = lighting;
        rtInputs.environment = f.environment;
        rtInputs.camera = camera;
        rtInputs.frameIndex = frameIndex;
        rtInputs.maxDistance = settings.reach;
        rtInputs.shadowDistance = 2.0f * settings.reach;
        RtTraceSettings rtSettings = settings.rt;
        rtSettings.clearUntraced = rtSettings.clearUntraced || viewsRt;
        f.rt = addRtTracePass(graph, *rt_, rtInputs, rtSettings);
    }
    // 5'. Particles seen in the reflections, cut at each ray's reflected
    // surface (the particle TLAS exists only when the scene has particles).
    if (f.bvh && particlesTraced(*f.bvh)) {
        ParticleTraceInputs particleInputs;
        particleInputs.gbuffer = f.gbuffer;
        particleInputs.rays = f.rays;
        particleInputs.sslr = f.sslr;
        if (f.rt) {
            particleInputs.rtRadiance = f.rt->radiance;
            particleInputs.rtHitDistance = f.rt->hitDistance;
            particleInputs.rtRayList = rtList;
            particleInputs.rtArgs = rtArgs;
        }
        particleInputs.bvh = *f.bvh;
        particleInputs.camera = camera;
        particleInputs.screenSpaceIdle = f.screenSpaceIdle;
        particleInputs.sslrCountsOnly = f.sslrCountsOnly;
        ParticleTraceSettings particleSettings;
        particleSettings.backend = rt_->backend();
        particleSettings.confidenceThreshold = settings.confidenceThreshold;
        particleSettings.maxDistance = settings.reach;
        particleSettings.sslrSeesParticles = settings.sslrParticles && f.sslr.has_value();
        particleSettings.rtMissesTrusted = !sslrFallback;
        particleSettings.clearUntraced = view == "particles";
        f.particles = addParticleTracePass(graph, particles_, particleInputs, particleSettings);
    }
    // 5. Integrate.
    IntegrateInputs integrateInputs;
    integrateInputs.gbuffer = f.gbuffer;
    integrateInputs.rays = f.rays;
    integrateInputs.sslr = f.sslr;
    if (f.rt) {
        integrateInputs.rtRadiance = f.rt->radiance;
        integrateInputs.rtHitDistance = f.rt->hitDistance;
        integrateInputs.rtHitMotion = f.rt->hitMotion;
    }
    if (f.feedback) {
        integrateInputs.feedback = *f.feedback;
    }
    integrateInputs.lighting = lighting;
    integrateInputs.environment = f.environment;
    integrateInputs.camera = camera;
    integrateInputs.confidenceThreshold = settings.confidenceThreshold;
    integrateInputs.screenSpaceIdle = f.screenSpaceIdle;
    integrateInputs.sslrCountsOnly = f.sslrCountsOnly;
    integrateInputs.debugOutputs = view == "reflection_source";
    if (f.particles) {
        integrateInputs.particles = f.particles->radiance;
    }
    IntegrateSettings integrateSettings = settings.integrate;
    integrateSettings.rtMissesTrusted = integrateSettings.rtMissesTrusted && !sslrFallback;
    f.integrate = addIntegratePass(graph, integrate_, integrateInputs, integrateSettings);
    // 7. Reflection motion and temporal accumulation.
    TemporalInputs temporalInputs;
    temporalInputs.gbuffer = f.gbuffer;
    temporalInputs.radiance = f.integrate.radiance;
    temporalInputs.hitDistance = f.integrate.hitDistance;
    if (settings.reflectedMotion) {
        temporalInputs.hitMotion = f.integrate.hitMotion;
    }
    temporalInputs.sharedRayRoughness = settings.rays.checkerboard ? 0.0f
                                        : settings.rays.reuse      ? settings.rays.reuseRoughness
                                                                   : 2.0f;
    temporalInputs.environmentRoughness = settings.rays.roughnessCutoff;
    temporalInputs.debugOutputs =
        settings.temporalDebugOutputs || view == "reflection_motion" || view == "history_length";
    temporalInputs.camera = camera;
    temporalInputs.frameIndex = frameIndex;
    temporalInputs.resetHistory = settings.resetHistory;
    TemporalSettings temporalSettings = settings.temporal;
    temporalSettings.spatialRoughnessMax = std::min(temporalSettings.spatialRoughnessMax, settings.rays.roughnessCutoff);
    f.temporal = addTemporalPass(graph, temporal_, temporalInputs, temporalSettings);

    if (settings.countRays) {
        addStatsPasses(graph, f, rtArgs);
    }
    // 8. Composite and tonemap, or the debug view in its place.
    addOutput(graph, f, camera, settings);
    return f;
}

} // namespace glint::passes
