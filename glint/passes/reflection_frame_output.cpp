// The end of the reflection frame: the composited image, or a debug view in
// its place, and the stats pass. The debug views are one table (name, what
// it shows, the modes that produce it, how it is drawn, where its texture
// comes from) that the wiring below, --list-debug-views and the viewer all
// read.
#include "glint/passes/reflection_frame.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"

#include "glint/reflection_frame_shared.h"

#include <array>
#include <functional>
#include <string>

namespace glint::passes {

namespace {

uint32_t groups(uint32_t n) { return (n + shader::kTileSize - 1) / shader::kTileSize; }

// What a debug view's producer may use besides the frame's outputs.
struct ViewSources {
    const ReflectionFrame& f;
    // A per-tile buffer drawn as a picture (kTileViewModes, kTileViewCounters).
    std::function<rg::Texture(rg::Buffer, uint32_t)> tiles;
    // The blended surfaces' layer, declared (empty) even with none in view.
    std::function<rg::Texture()> transparent;
};

// A range end of kReach stands for the frame's reach (distance views).
// Producers return an invalid texture for what the frame did not declare,
// so a row whose modes are wrong fails with a message, never a crash
// (tests/gpu/reflection_frame_plan_test.cpp walks the table in every mode).
constexpr float kReach = -1.0f;

struct ViewRow {
    DebugViewInfo info;
    DebugViewKind kind;
    float minValue;
    float maxValue;
    rg::Texture (*produce)(const ViewSources&);
};

constexpr DebugViewModes kAll{true, true, true};
constexpr DebugViewModes kScreenSpace{true, true, false};
constexpr DebugViewModes kTraced{true, false, true};
constexpr DebugViewModes kHybridOnly{true, false, false};

using K = DebugViewKind;
const std::array<ViewRow, 24> kViews = {{
    {{"final", "the composited, tonemapped image", kAll}, K::Color, 0, 1, nullptr},
    {{"lit", "G-buffer: lit colour of the opaque scene", kAll}, K::Color, 0, 1,
     [](const ViewSources& s) { return s.f.gbuffer.lit; }},
    {{"ray_classes", "ray generation: sky black, env grey, SSLR blue, hybrid purple, RT red", kAll}, K::Raw, 0, 1,
     [](const ViewSources& s) { return s.f.rays.classDebug; }},
    {{"tile_modes",
      "feedback: the tile decisions ray generation used (blue SSLR, purple hybrid, red RT, dark red RT-only)",
      kHybridOnly},
     K::Raw, 0, 1,
     [](const ViewSources& s) {
         return s.f.feedback ? s.tiles(s.f.feedback->tileModes, shader::kTileViewModes) : rg::Texture{};
     }},
    {{"feedback_counters", "integrate: SSLR hits green, misses red, per 8x8 tile", kHybridOnly}, K::Raw, 0, 1,
     [](const ViewSources& s) {
         return s.f.feedback ? s.tiles(s.f.integrate.counters, shader::kTileViewCounters) : rg::Texture{};
     }},
    {{"sslr_radiance", "SSLR: lit colour at the hit", kScreenSpace}, K::Color, 0, 1,
     [](const ViewSources& s) { return s.f.sslr ? s.f.sslr->radiance : rg::Texture{}; }},
    {{"sslr_confidence", "SSLR: confidence, 0..1", kScreenSpace}, K::Scalar, 0, 1,
     [](const ViewSources& s) { return s.f.sslr ? s.f.sslr->confidence : rg::Texture{}; }},
    {{"sslr_hits", "SSLR: hit uv (red, green)", kScreenSpace}, K::Raw, 0, 1,
     [](const ViewSources& s) { return s.f.sslr ? s.f.sslr->hit : rg::Texture{}; }},
    {{"rt_radiance", "RT: radiance along the traced rays", kTraced}, K::Color, 0, 1,
     [](const ViewSources& s) { return s.f.rt ? s.f.rt->radiance : rg::Texture{}; }},
    {{"rt_hit_distance", "RT: world distance, 0..reach", kTraced}, K::Scalar, 0, kReach,
     [](const ViewSources& s) { return s.f.rt ? s.f.rt->hitDistance : rg::Texture{}; }},
    {{"particles", "particles trace: particles seen in the reflections (scenes with particles)", kTraced}, K::Color, 0,
     1, [](const ViewSources& s) { return s.f.particles ? s.f.particles->radiance : rg::Texture{}; }},
    {{"transparent", "transparent pass: blended surfaces, premultiplied (scenes with alphaMode BLEND)", kAll},
     K::Color, 0, 1, [](const ViewSources& s) { return s.transparent(); }},
    {{"shadow_map", "G-buffer: the sun's shadow map (reversed depth)", kAll}, K::Scalar, 0, 1,
     [](const ViewSources& s) { return s.f.gbuffer.shadowMap; }},
    {{"lit_pyramid", "SSLR: the cone trace's colour pyramid, level 1 at half size (when a rough pixel cone-traces)",
      kScreenSpace},
     K::Color, 0, 1, [](const ViewSources& s) { return s.f.sslr ? s.f.sslr->litPyramid : rg::Texture{}; }},
    {{"reflection_source", "integrate: which trace each pixel's reflection came from", kAll}, K::Raw, 0, 1,
     [](const ViewSources& s) { return s.f.integrate.sourceDebug; }},
    {{"reflections", "integrate: reflection radiance", kAll}, K::Color, 0, 1,
     [](const ViewSources& s) { return s.f.integrate.radiance; }},
    {{"hit_distance", "integrate: world distance to the reflected point, 0..reach", kAll}, K::Scalar, 0, kReach,
     [](const ViewSources& s) { return s.f.integrate.hitDistance; }},
    {{"resolved", "temporal: accumulated reflections", kAll}, K::Color, 0, 1,
     [](const ViewSources& s) { return s.f.temporal.resolved; }},
    {{"reflection_motion", "temporal: the reprojection's motion, -8..8 pixels", kAll}, K::Scalar, -8, 8,
     [](const ViewSources& s) { return s.f.temporal.reflectionMotion; }},
    {{"history_length", "temporal: frames accumulated, 0..32", kAll}, K::Scalar, 0, 32,
     [](const ViewSources& s) { return s.f.temporal.historyLength; }},
    {{"motion", "G-buffer: surface motion, -8..8 pixels", kAll}, K::Scalar, -8, 8,
     [](const ViewSources& s) { return s.f.gbuffer.motion; }},
    {{"normal", "G-buffer: world normal", kAll}, K::Raw, 0, 1, [](const ViewSources& s) { return s.f.gbuffer.normal; }},
    {{"albedo", "G-buffer: base colour", kAll}, K::Raw, 0, 1, [](const ViewSources& s) { return s.f.gbuffer.albedo; }},
    {{"roughness", "G-buffer: perceptual roughness", kAll}, K::Scalar, 0, 1,
     [](const ViewSources& s) { return s.f.gbuffer.roughnessMetal; }},
}};

const std::array<DebugViewInfo, kViews.size()> kViewInfos = [] {
    std::array<DebugViewInfo, kViews.size()> infos{};
    for (size_t i = 0; i < kViews.size(); ++i) infos[i] = kViews[i].info;
    return infos;
}();

} // namespace

bool DebugViewModes::has(ReflectionMode mode) const {
    switch (mode) {
    case ReflectionMode::Hybrid: return hybrid;
    case ReflectionMode::Ssr: return ssr;
    case ReflectionMode::Rt: return rt;
    }
    return false;
}

std::span<const DebugViewInfo> debugViews() { return kViewInfos; }

const DebugViewInfo* findDebugView(std::string_view name) {
    for (const DebugViewInfo& info : kViewInfos) {
        if (info.name == name) return &info;
    }
    return nullptr;
}

void ReflectionRenderer::addStatsPasses(rg::Graph& graph, ReflectionFrame& f, rg::Buffer rtArgs) {
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
    constants.rtListCounted = f.mode != ReflectionMode::Ssr ? 1u : 0u;
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
                .storageBuffer("Classes", pc.buffer(d.classes))
                .storageBuffer("Rays", pc.buffer(d.rays))
                .storageBuffer("RtArgs", pc.buffer(d.rtArgs))
                .storageBuffer("Counts", pc.buffer(d.counts))
                .push(ctx_, pc.cmd());
            classCount_.pushConstants(pc.cmd(), constants);
            pc.dispatch(classCount_, groups(constants.size.x), groups(constants.size.y));
        });
    f.counts = count.counts;
}

void ReflectionRenderer::addOutput(rg::Graph& graph, ReflectionFrame& f, const scene::Camera& camera,
                                   const ReflectionFrameSettings& settings) {
    // Without SSLR particles the particles are drawn into the lit colour
    // only now: SSLR (and its cone pyramid) must not see them, or the trace
    // and SSLR would both reflect them. The blended surfaces' layer, when
    // the scene has any, goes over everything.
    const auto transparentLayer = [&](bool declareEmpty) {
        f.transparent = addTransparentPass(graph, gbuffer_, {f.gbuffer, f.environment, declareEmpty}).layer;
        return f.transparent;
    };
    const std::string_view view = settings.debugView.empty() ? std::string_view("final") : settings.debugView;
    const ViewRow* row = nullptr;
    for (const ViewRow& r : kViews) {
        if (r.info.name == view) row = &r;
    }
    if (row == nullptr) {
        std::string names;
        for (const ViewRow& r : kViews) names += (names.empty() ? "" : ", ") + std::string(r.info.name);
        throw gpu::GpuError("unknown debug view '" + std::string(view) + "' (available: " + names + ")");
    }
    if (!row->info.modes.has(f.mode)) {
        throw gpu::GpuError("debug view '" + std::string(view) + "' is not produced in mode " +
                            std::string(modeName(f.mode)));
    }
    if (row->produce == nullptr) {
        GBufferOutputs composited = f.gbuffer;
        if (!settings.sslrParticles) {
            composited.lit = addParticleForwardPass(graph, particles_, {f.gbuffer, scene_.particles, camera}).lit;
        }
        f.output = addCompositePass(graph, composite_,
                                    {composited, f.temporal.resolved, camera, transparentLayer(false)},
                                    settings.composite);
        graph.markOutput(f.output.color);
        return;
    }

    const auto tiles = [&](rg::Buffer perTile, uint32_t what) {
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
                d.tiles = b.read(perTile, rg::Access::StorageRead);
                d.image = b.write(b.createTexture("debug_view.tiles", {.width = f.width,
                                                                      .height = f.height,
                                                                      .format = VK_FORMAT_R8G8B8A8_UNORM}),
                                  rg::Access::StorageWrite);
            },
            [this, constants](const TileData& d, rg::PassContext& pc) {
                tileView_.bind(pc.cmd());
                gpu::PushDescriptors(tileView_)
                    .storageBuffer("Tiles", pc.buffer(d.tiles))
                    .storageImage("outImage", pc.view(d.image))
                    .push(ctx_, pc.cmd());
                tileView_.pushConstants(pc.cmd(), constants);
                pc.dispatch(tileView_, groups(constants.size.x), groups(constants.size.y));
            });
        return data.image;
    };
    const rg::Texture texture = row->produce({f, tiles, [&] { return transparentLayer(true); }});
    if (!texture.valid()) {
        throw gpu::GpuError("debug view '" + std::string(view) + "' is not produced by this frame (" +
                            std::string(row->info.shows) + ")");
    }
    DebugViewSettings s;
    s.kind = row->kind;
    s.minValue = row->minValue == kReach ? settings.reach : row->minValue;
    s.maxValue = row->maxValue == kReach ? settings.reach : row->maxValue;
    s.exposure = settings.composite.exposure;
    f.output = addDebugViewPass(graph, composite_, texture, f.width, f.height, s);
    graph.markOutput(f.output.color);
}

} // namespace glint::passes
