#pragma once
// The whole hybrid-reflections frame wired
// from the pass functions: what glint-render, the benchmark, the viewer and
// the golden-image tests declare every frame, and the reference for an
// engine that wires the passes into its own frame.
//
//   BVH update (async compute) -> G-buffer -> feedback -> ray generation
//   -> SSLR -> ray-traced hits -> particles trace -> integrate -> temporal
//   -> particles forward -> transparent (when blended surfaces are in view)
//   -> composite
// (with ReflectionFrameSettings::sslrParticles the particles forward pass
// comes right after the G-buffer, so that SSLR sees the particles)
//
// Each mode declares only what it uses: ssr has no BVH, no ray-traced pass
// and no reflected particles (the direct view still draws them), rt no
// SSLR and no feedback; a scene without particles no particle passes.
//
//   passes::ReflectionRenderer renderer(ctx, scene, {});
//   each frame (after scene::advanceScene and camera.advance):
//     rg::Graph graph(executor.queueCaps());
//     const passes::ReflectionFrame frame = renderer.addFrame(graph, camera, settings);
//     rg::FrameResources resources;
//     renderer.bind(resources, frame);
//     executor.run(graph.compile(executor.compileOptions()), resources);

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/passes/bvh_update.h"
#include "glint/passes/composite.h"
#include "glint/passes/environment.h"
#include "glint/passes/feedback.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/integrate.h"
#include "glint/passes/particles.h"
#include "glint/passes/ray_generation.h"
#include "glint/passes/rt_trace.h"
#include "glint/passes/sslr.h"
#include "glint/passes/temporal.h"
#include "glint/passes/transparent.h"
#include "glint/scene/bvh_planner.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace glint::passes {

std::string_view modeName(ReflectionMode mode);
// "hybrid", "ssr" or "rt"; throws std::invalid_argument naming the value otherwise.
ReflectionMode parseMode(std::string_view name);
std::string_view backendName(RtBackend backend);
// "auto", "query" or "pipeline"; throws std::invalid_argument otherwise.
RtBackend parseBackend(std::string_view name);

struct ReflectionRendererOptions {
    uint32_t framesInFlight = 2;  // at least the executor's
    RtBackend backend = RtBackend::Auto;
    scene::BvhSettings bvh;
    BvhUpdateOptions bvhUpdate;
    EnvironmentSettings environment;  // the prefilter of an equirectangular environment
};

struct ReflectionFrameSettings {
    ReflectionMode mode = ReflectionMode::Hybrid;
    GBufferSettings gbuffer;
    // How far reflections reach: the BVH's radius around the camera (Far
    // Cry 6: 100 m). The ray tracer's ray length at roughness 0, the
    // distance from which pixels take SSLR only, the particle trace's range,
    // the shadow rays' length at hits (twice it: across the BVH) and the
    // distance debug views' range all derive from it.
    float reach = scene::kDefaultBvhRadius;
    // SSLR confidence below which a hybrid ray goes to the ray tracer, and
    // at which integrate and the particle trace take SSLR alone (Far Cry 6:
    // 0.9). One value for the three: they must agree.
    float confidenceThreshold = kDefaultConfidenceThreshold;
    RayGenerationSettings rays;
    SslrSettings sslr;
    RtTraceSettings rt;
    FeedbackSettings feedback;
    IntegrateSettings integrate;  // rtMissesTrusted is cleared while the BVH builds (sslrWhileBvhBuilds)
    TemporalSettings temporal;    // spatialRoughnessMax is at most rays.roughnessCutoff
    CompositeSettings composite;
    // The Far Cry 6 talk's "SSLR particles": the particles are drawn into
    // the lit colour before SSLR samples it, and the particle trace covers
    // only the reflections SSLR did not resolve
    // (ParticleTraceSettings::sslrSeesParticles). Off: drawn after SSLR,
    // and every traced reflection takes its particles from the trace.
    bool sslrParticles = false;
    // Particles in the reflections: off, no particle TLAS is built and no
    // particle trace runs (the direct view still draws the particles); what
    // reflected particles cost is the difference.
    bool reflectParticles = true;
    // While the BVH is still building objects in range (its first-build
    // budget, scene::BvhSettings), SSLR is the fallback (the Far Cry 6
    // talk): in hybrid mode every pixel tries SSLR first, and a ray-traced
    // miss no longer overrides a partial SSLR hit
    // (RayGenerationSettings::sslrFirst, IntegrateSettings::rtMissesTrusted).
    // Off: the incomplete BVH is traced as it is.
    bool sslrWhileBvhBuilds = true;
    // Reflected objects carry their own motion: temporal accumulation
    // reprojects a reflection through where its reflected point was last
    // frame (a ray-traced hit's instance motion, an SSLR hit's G-buffer
    // motion; IntegrateOutputs::hitMotion). Off: only the camera's motion
    // reprojects, and a moving object's reflection looks its history up
    // where the object no longer is (the temporal pass's clip hides most of
    // the trail that leaves, docs/results/log/03-2026-12-03-04.md, but the
    // history is lost).
    bool reflectedMotion = true;
    // Empty or "final": the composited image; otherwise one of
    // debugViews(), shown in `output` instead.
    std::string debugView;
    // Discards the temporal history (first frame, camera cut).
    bool resetHistory = false;
    // Declares a small pass counting pixel classes and traced rays into
    // ReflectionFrame::counts (for stats).
    bool countRays = false;
    // Writes the temporal pass's reflection motion and history length
    // (ReflectionFrame::temporal; TemporalInputs::debugOutputs) for a caller
    // that reads them; their debug views turn them on of themselves.
    bool temporalDebugOutputs = false;
};

// Everything a frame declared, for debug views, readbacks and stats.
struct ReflectionFrame {
    // The mode declared: the settings' own, or ssr on a device without ray
    // tracing (ReflectionRenderer::tracesRays).
    ReflectionMode mode = ReflectionMode::Hybrid;
    GBufferOutputs gbuffer;
    std::optional<BvhUpdateOutputs> bvh;
    // The TLAS holds every object in range (scene::BvhPlan::complete);
    // false while first builds wait for their budget.
    bool bvhComplete = true;
    std::optional<FeedbackOutputs> feedback;
    // A hybrid frame the host rendered as rt (FeedbackSettings::hostGate):
    // its feedback, pyramid and SSLR passes recorded nothing.
    bool screenSpaceIdle = false;
    // While the host's gate holds SSLR back: frames between its probes
    // (sslrProbeInterval, backing off to sslrProbeIntervalMax); 0 while
    // SSLR pays, or without the host's gate.
    uint32_t sslrProbeSpacing = 0;
    // A probe frame of the host's closed gate that renders as rt
    // (FeedbackSettings::probesRenderAsRt): SSLR's hits counted, not used.
    bool sslrCountsOnly = false;
    // Where the feedback pass copied last frame's SSLR hits for the gate.
    std::optional<rg::FrameReadback::Target> gateReport;
    RayGenerationOutputs rays;
    std::optional<SslrOutputs> sslr;
    std::optional<RtTraceOutputs> rt;
    std::optional<ParticleTraceOutputs> particles;  // reflected particles (a BVH with particles)
    IntegrateOutputs integrate;
    TemporalOutputs temporal;
    // The blended surfaces' layer (passes/transparent.h); invalid when none
    // is in view or a debug view other than "transparent" is shown.
    rg::Texture transparent;
    CompositeOutputs output;  // RGBA8, sRGB-encoded: the image or the debug view
    // The prefiltered environment image (passes/environment.h); invalid for
    // the procedural sky.
    rg::Texture environment;
    // When ReflectionFrameSettings::countRays: kReflectionCountWords uints,
    // glint/reflection_frame_shared.h.
    rg::Buffer counts;
    uint32_t width = 0;
    uint32_t height = 0;
};

// The debug views ReflectionFrameSettings::debugView names: one table
// (passes/reflection_frame_output.cpp) that addFrame, --list-debug-views
// and the viewer all read.
struct DebugViewModes {
    bool hybrid = true, ssr = true, rt = true;
    bool has(ReflectionMode mode) const;
};
struct DebugViewInfo {
    std::string_view name;
    std::string_view shows;  // the pass that produces it and what it shows
    DebugViewModes modes;    // where it is produced; elsewhere addFrame throws
};
std::span<const DebugViewInfo> debugViews();
// Null when no view has that name.
const DebugViewInfo* findDebugView(std::string_view name);

// The passes whose GPU time is the reflections' cost (ray generation
// through temporal accumulation: the stats' reflection_ms).
bool isReflectionPass(std::string_view passName);

class ReflectionRenderer {
public:
    // `scene` must outlive the renderer; see GBufferRenderer and BvhManager
    // for what may change in it between frames.
    ReflectionRenderer(gpu::Context& ctx, const scene::Scene& scene, const ReflectionRendererOptions& options = {});
    ~ReflectionRenderer();
    ReflectionRenderer(const ReflectionRenderer&) = delete;
    ReflectionRenderer& operator=(const ReflectionRenderer&) = delete;

    // Declares one frame seen through `camera` (its frameIndex drives all
    // noise). Frames are declared and run one at a time, once each. The
    // output is marked as the graph's output, so every frame compiles to
    // the same passes whether or not the caller reads it back: the graph
    // plans history images from this frame's own uses (graph.h).
    ReflectionFrame addFrame(rg::Graph& graph, const scene::Camera& camera, const ReflectionFrameSettings& settings);
    // Binds the frame's imports (the BVH's objects, the environment).
    void bind(rg::FrameResources& resources, const ReflectionFrame& frame) const;

    // The ray backend; Auto on a device without ray tracing.
    RtBackend backend() const;
    // False on a device without ray tracing (gpu::Capabilities::canTraceRays):
    // then every frame is declared in ssr mode, whatever the settings ask
    // (ReflectionFrame::mode says which), and no BVH memory is allocated.
    bool tracesRays() const { return rt_ != nullptr; }
    const GBufferStats& gbufferStats() const { return gbuffer_.stats(); }
    // Of the last frame that declared BVH work (none in ssr mode).
    const scene::BvhStats& bvhPlanStats() const { return lastPlanStats_; }
    const BvhGpuStats& bvhGpuStats() const;
    const EnvironmentStats& environmentStats() const { return environment_.stats(); }

private:
    // addFrame's last steps (passes/reflection_frame_output.cpp): the ray
    // counts for stats, and the composited image or a debug view.
    void addStatsPasses(rg::Graph& graph, ReflectionFrame& f, rg::Buffer rtArgs);
    void addOutput(rg::Graph& graph, ReflectionFrame& f, const scene::Camera& camera,
                   const ReflectionFrameSettings& settings);
    // The host's side of the SSLR gate (FeedbackSettings::hostGate): learns
    // from the newest report read back, then says whether this hybrid frame
    // may render as rt (not after a cut, nor on a probe frame).
    bool screenSpaceIdle(const ReflectionFrameSettings& settings, uint64_t frameIndex, uint32_t width, uint32_t height);

    gpu::Context& ctx_;
    const scene::Scene& scene_;
    // Prefiltered when the renderer is created and when addFrame sees a new
    // environment (EnvironmentMap::update).
    EnvironmentMap environment_;
    GBufferRenderer gbuffer_;
    scene::BvhPlanner planner_;
    std::unique_ptr<BvhManager> bvh_;  // null without ray tracing
    FeedbackPipelines feedback_;
    RayGenerationPipelines rays_;
    SslrPipelines sslr_;
    std::unique_ptr<RtTracePipelines> rt_;  // null without ray tracing
    IntegratePipelines integrate_;
    TemporalPipelines temporal_;
    CompositePipelines composite_;
    ParticlePipelines particles_;
    gpu::Pipeline tileView_;
    gpu::Pipeline classCount_;
    scene::BvhStats lastPlanStats_;
    // The SSLR gate's state: each hybrid frame's feedback pass copies last
    // frame's SSLR hits into gateReadback_ (null without ray tracing).
    std::unique_ptr<rg::FrameReadback> gateReadback_;
    uint64_t gatePending_ = 0;   // the newest report of a frame after one that tried SSLR, not yet read (0: none)
    bool sslrPays_ = true;       // what the newest report read said (true until one says otherwise)
    uint32_t probeStride_ = 1;   // hostProbeFrame's: 2, 4, ... after probes that found SSLR still not paying
    // What the last frame declared did with SSLR: its counters hold a
    // report worth reading (TriedSslr) or none (RenderedAsRt: the next
    // frame that decides starts without evidence).
    enum class LastFrame { Other, TriedSslr, RenderedAsRt };
    LastFrame lastFrame_ = LastFrame::Other;
};

} // namespace glint::passes
