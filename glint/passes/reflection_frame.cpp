#include "glint/passes/reflection_frame.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/passes/lighting.h"

#include "glint/reflection_frame_shared.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>

namespace glint::passes {

namespace {

constexpr std::array<std::string_view, 3> kModeNames = {"hybrid", "ssr", "rt"};
constexpr std::array<std::string_view, 3> kBackendNames = {"auto", "query", "pipeline"};

// Debug views: name, what they show. Kept in one table so the list printed
// by --help, the parser and the wiring agree.
constexpr std::array<std::string_view, 24> kDebugViews = {
    "final",              // the composited, tonemapped image
    "lit",                // G-buffer: lit colour of the opaque scene
    "ray_classes",        // ray generation: sky black, env grey, SSLR blue, hybrid purple, RT red
    "tile_modes",         // feedback: the tile decisions ray generation used (hybrid mode)
    "feedback_counters",  // integrate: SSLR hits green, misses red, per 8x8 tile
    "sslr_radiance",      // SSLR: lit colour at the hit
    "sslr_confidence",    // SSLR: [0, 1]
    "sslr_hits",          // SSLR: hit uv, confidence
    "rt_radiance",        // RT: radiance along the traced rays
    "rt_hit_distance",    // RT: world distance, 0..100
    "particles",          // particles trace: particles seen in the reflections (premultiplied)
    "transparent",        // transparent pass: blended surfaces (premultiplied; scenes with alphaMode BLEND)
    "shadow_map",         // G-buffer: the sun's shadow map (reversed depth)
    "lit_pyramid",        // SSLR: the cone trace's colour pyramid (level 0)
    "reflection_source",  // integrate: which trace each pixel used
    "reflections",        // integrate: reflection radiance
    "hit_distance",       // integrate: world distance to the reflected point, 0..100
    "resolved",           // temporal: accumulated reflections
    "reflection_motion",  // temporal: the reprojection's motion, pixels
    "history_length",     // temporal: frames accumulated
    "motion",             // G-buffer: surface motion, pixels
    "normal",             // G-buffer: world normal
    "albedo",             // G-buffer: base colour
    "roughness",          // G-buffer: perceptual roughness
};

// Passes that make up the reflections' cost, by name prefix.
constexpr std::array<std::string_view, 7> kReflectionPassPrefixes = {
    "feedback", "ray_generation", "sslr", "rt_trace", "particles.trace", "integrate", "temporal"};

std::vector<gpu::Binding> storageBindings(uint32_t buffers, bool lastIsImage) {
    std::vector<gpu::Binding> bindings;
    for (uint32_t i = 0; i < buffers; ++i) {
        bindings.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_SHADER_STAGE_COMPUTE_BIT});
    }
    if (lastIsImage) {
        bindings.push_back({buffers, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_SHADER_STAGE_COMPUTE_BIT});
    }
    return bindings;
}

uint32_t groups(uint32_t n) { return (n + shader::kTileSize - 1) / shader::kTileSize; }

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

std::span<const std::string_view> debugViewNames() { return kDebugViews; }

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
      tileView_(gpu::createComputePipeline(ctx, {"reflection_frame/tile_view.comp", storageBindings(1, true),
                                                 uint32_t(sizeof(shader::TileViewConstants)),
                                                 "reflection_frame.tile_view"})),
      classCount_(gpu::createComputePipeline(ctx, {"reflection_frame/class_count.comp", storageBindings(4, false),
                                                   uint32_t(sizeof(shader::ClassCountConstants)),
                                                   "reflection_frame.class_count"})) {
    if (!rt_) {
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
}

ReflectionFrame ReflectionRenderer::addFrame(rg::Graph& graph, const scene::Camera& camera,
                                             const ReflectionFrameSettings& settings) {
    // Without ray tracing every mode is ssr (the constructor said so once).
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
        scene::BvhPlan plan = planner_.plan(scene_, camera);
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
    if (mode == ReflectionMode::Hybrid) {
        f.feedback = addFeedbackPass(graph, feedback_, {f.gbuffer, frameIndex}, settings.feedback);
        rayInputs.tileModes = f.feedback->tileModes;
    }
    // 2. Ray generation and tile classification.
    RayGenerationSettings raySettings = settings.rays;
    raySettings.mode = mode;
    const bool sslrFallback = !f.bvhComplete && settings.sslrWhileBvhBuilds && screenSpace;
    raySettings.sslrFirst = raySettings.sslrFirst || (sslrFallback && mode == ReflectionMode::Hybrid);
    // The traces write only their rays' pixels; a debug view of their raw
    // outputs shows the rest cleared rather than stale.
    const bool viewsSslr = view.substr(0, 5) == "sslr_" || view == "lit_pyramid";
    const bool viewsRt = view.substr(0, 3) == "rt_";
    f.rays = addRayGenerationPass(graph, rays_, rayInputs, raySettings);
    // 3. SSLR, extending the RT list with what it cannot resolve.
    rg::Buffer rtList = f.rays.rtRays;
    rg::Buffer rtArgs = f.rays.rtArgs;
    if (screenSpace) {
        SslrSettings sslrSettings = settings.sslr;
        sslrSettings.clearUntraced = sslrSettings.clearUntraced || viewsSslr;
        f.sslr = addSslrPass(graph, sslr_, {f.gbuffer, f.rays, frameIndex, camera.view, camera.projection},
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
        }
        particleInputs.bvh = *f.bvh;
        particleInputs.camera = camera;
        ParticleTraceSettings particleSettings;
        particleSettings.backend = rt_->backend();
        particleSettings.confidenceThreshold = settings.sslr.confidenceThreshold;
        particleSettings.maxDistance = settings.rt.maxDistance;
        particleSettings.sslrSeesParticles = settings.sslrParticles && f.sslr.has_value();
        particleSettings.rtMissesTrusted = !sslrFallback;
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
    }
    if (f.feedback) {
        integrateInputs.feedback = *f.feedback;
    }
    integrateInputs.lighting = lighting;
    integrateInputs.environment = f.environment;
    integrateInputs.camera = camera;
    if (f.particles) {
        integrateInputs.particles = f.particles->radiance;
    }
    IntegrateSettings integrateSettings = settings.integrate;
    integrateSettings.confidenceThreshold = settings.sslr.confidenceThreshold;
    integrateSettings.rtMissesTrusted = integrateSettings.rtMissesTrusted && !sslrFallback;
    f.integrate = addIntegratePass(graph, integrate_, integrateInputs, integrateSettings);
    // 7. Reflection motion and temporal accumulation.
    TemporalInputs temporalInputs;
    temporalInputs.gbuffer = f.gbuffer;
    temporalInputs.radiance = f.integrate.radiance;
    temporalInputs.hitDistance = f.integrate.hitDistance;
    temporalInputs.camera = camera;
    temporalInputs.frameIndex = frameIndex;
    temporalInputs.resetHistory = settings.resetHistory;
    TemporalSettings temporalSettings = settings.temporal;
    temporalSettings.spatialRoughnessMax = std::min(temporalSettings.spatialRoughnessMax, settings.rays.roughnessCutoff);
    f.temporal = addTemporalPass(graph, temporal_, temporalInputs, temporalSettings);

    if (settings.countRays) {
        struct ClearData {
            rg::Buffer counts;
        };
        const ClearData& clear = graph.addPass<ClearData>(
            "stats.clear", rg::Queue::Graphics,
            [&](rg::Builder& b, ClearData& d) {
                d.counts = b.write(b.createBuffer("stats.counts", {shader::kReflectionCountWords * 4u}),
                                   rg::Access::TransferDst);
            },
            [](const ClearData& d, rg::PassContext& pc) {
                vkCmdFillBuffer(pc.cmd(), pc.buffer(d.counts).handle(), 0, VK_WHOLE_SIZE, 0);
            });
        struct CountData {
            rg::Buffer classes, rays, rtArgs, counts;
        };
        shader::ClassCountConstants constants{};
        constants.size = {f.width, f.height};
        constants.rtListCounted = traces ? 1u : 0u;
        const CountData& count = graph.addPass<CountData>(
            "stats.count_rays", rg::Queue::Graphics,
            [&](rg::Builder& b, CountData& d) {
                d.classes = b.read(f.rays.classes, rg::Access::StorageRead);
                d.rays = b.read(f.rays.rays, rg::Access::StorageRead);
                d.rtArgs = b.read(rtArgs, rg::Access::StorageRead);
                d.counts = b.write(clear.counts, rg::Access::StorageReadWrite);
            },
            [this, constants](const CountData& d, rg::PassContext& pc) {
                classCount_.bind(pc.cmd());
                gpu::PushDescriptors(classCount_)
                    .storageBuffer(0, pc.buffer(d.classes))
                    .storageBuffer(1, pc.buffer(d.rays))
                    .storageBuffer(2, pc.buffer(d.rtArgs))
                    .storageBuffer(3, pc.buffer(d.counts))
                    .push(ctx_, pc.cmd());
                classCount_.pushConstants(pc.cmd(), constants);
                pc.dispatch(classCount_, groups(constants.size.x), groups(constants.size.y));
            });
        f.counts = count.counts;
    }

    // 8. Composite and tonemap, or the debug view in its place. Without
    // SSLR particles the particles are drawn into the lit colour only now:
    // SSLR (and its cone pyramid) must not see them, or the trace and SSLR
    // would both reflect them. The blended surfaces' layer, when the scene
    // has any, goes over everything.
    const auto transparentLayer = [&](bool declareEmpty) {
        f.transparent = addTransparentPass(graph, gbuffer_, {f.gbuffer, f.environment, declareEmpty}).layer;
        return f.transparent;
    };
    if (view.empty() || view == "final") {
        GBufferOutputs composited = f.gbuffer;
        if (!settings.sslrParticles) {
            composited.lit = addParticleForwardPass(graph, particles_, {f.gbuffer, scene_.particles, camera}).lit;
        }
        f.output = addCompositePass(graph, composite_, {composited, f.temporal.resolved, camera, transparentLayer(false)},
                                    settings.composite);
        graph.markOutput(f.output.color);
        return f;
    }
    const auto show = [&](rg::Texture texture, DebugViewKind kind, float minValue = 0.0f, float maxValue = 1.0f) {
        if (!texture.valid()) {
            throw gpu::GpuError("debug view '" + std::string(view) + "' is not produced in mode " +
                                std::string(modeName(mode)));
        }
        DebugViewSettings s;
        s.kind = kind;
        s.minValue = minValue;
        s.maxValue = maxValue;
        s.exposure = settings.composite.exposure;
        f.output = addDebugViewPass(graph, composite_, texture, f.width, f.height, s);
        graph.markOutput(f.output.color);
    };
    const auto showTiles = [&](rg::Buffer tiles, uint32_t what) {
        if (!tiles.valid()) {
            throw gpu::GpuError("debug view '" + std::string(view) + "' is not produced in mode " +
                                std::string(modeName(mode)));
        }
        struct TileData {
            rg::Buffer tiles;
            rg::Texture image;
        };
        shader::TileViewConstants constants{};
        constants.size = {f.width, f.height};
        constants.tilesX = f.rays.tilesX;
        constants.what = what;
        const TileData& data = graph.addPass<TileData>(
            "debug_view.tiles", rg::Queue::Graphics,
            [&](rg::Builder& b, TileData& d) {
                d.tiles = b.read(tiles, rg::Access::StorageRead);
                d.image = b.write(b.createTexture("debug_view.tiles", {.width = f.width,
                                                                      .height = f.height,
                                                                      .format = VK_FORMAT_R8G8B8A8_UNORM}),
                                  rg::Access::StorageWrite);
            },
            [this, constants](const TileData& d, rg::PassContext& pc) {
                tileView_.bind(pc.cmd());
                gpu::PushDescriptors(tileView_)
                    .storageBuffer(0, pc.buffer(d.tiles))
                    .storageImage(1, pc.view(d.image))
                    .push(ctx_, pc.cmd());
                tileView_.pushConstants(pc.cmd(), constants);
                pc.dispatch(tileView_, groups(constants.size.x), groups(constants.size.y));
            });
        show(data.image, DebugViewKind::Raw);
    };
    const rg::Texture none;
    if (view == "lit") show(f.gbuffer.lit, DebugViewKind::Color);
    else if (view == "ray_classes") show(f.rays.classDebug, DebugViewKind::Raw);
    else if (view == "tile_modes") showTiles(f.feedback ? f.feedback->tileModes : rg::Buffer{}, shader::kTileViewModes);
    else if (view == "feedback_counters") showTiles(f.feedback ? f.integrate.counters : rg::Buffer{}, shader::kTileViewCounters);
    else if (view == "sslr_radiance") show(f.sslr ? f.sslr->radiance : none, DebugViewKind::Color);
    else if (view == "sslr_confidence") show(f.sslr ? f.sslr->confidence : none, DebugViewKind::Scalar);
    else if (view == "sslr_hits") show(f.sslr ? f.sslr->hitDebug : none, DebugViewKind::Raw);
    else if (view == "rt_radiance") show(f.rt ? f.rt->radiance : none, DebugViewKind::Color);
    else if (view == "rt_hit_distance") show(f.rt ? f.rt->hitDistance : none, DebugViewKind::Scalar, 0.0f, 100.0f);
    else if (view == "particles") show(f.particles ? f.particles->radiance : none, DebugViewKind::Color);
    else if (view == "transparent") show(transparentLayer(true), DebugViewKind::Color);
    else if (view == "shadow_map") show(f.gbuffer.shadowMap, DebugViewKind::Scalar);
    else if (view == "lit_pyramid") show(f.sslr ? f.sslr->litPyramid : none, DebugViewKind::Color);
    else if (view == "reflection_source") show(f.integrate.sourceDebug, DebugViewKind::Raw);
    else if (view == "reflections") show(f.integrate.radiance, DebugViewKind::Color);
    else if (view == "hit_distance") show(f.integrate.hitDistance, DebugViewKind::Scalar, 0.0f, 100.0f);
    else if (view == "resolved") show(f.temporal.resolved, DebugViewKind::Color);
    else if (view == "reflection_motion") show(f.temporal.reflectionMotion, DebugViewKind::Scalar, -8.0f, 8.0f);
    else if (view == "history_length") show(f.temporal.historyLength, DebugViewKind::Scalar, 0.0f, 32.0f);
    else if (view == "motion") show(f.gbuffer.motion, DebugViewKind::Scalar, -8.0f, 8.0f);
    else if (view == "normal") show(f.gbuffer.normal, DebugViewKind::Raw);
    else if (view == "albedo") show(f.gbuffer.albedo, DebugViewKind::Raw);
    else if (view == "roughness") show(f.gbuffer.roughnessMetal, DebugViewKind::Scalar);
    else {
        std::string names;
        for (const std::string_view n : kDebugViews) names += (names.empty() ? "" : ", ") + std::string(n);
        throw gpu::GpuError("unknown debug view '" + std::string(view) + "' (available: " + names + ")");
    }
    return f;
}

} // namespace glint::passes
