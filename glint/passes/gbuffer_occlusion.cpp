// Occlusion culling of the G-buffer's draws (GBufferSettings::
// occlusionCulling; the scheme and the buffers: glint/occlusion_shared.h).
// The passes, in frame order:
//   gbuffer.cull_early  commands for the draws of last frame's visible
//                       instances (the visibility history)
//   gbuffer             draws them (passes/gbuffer.cpp, SurfacePhase::Early)
//   gbuffer.hiz         the min-depth pyramid of what it drew (two passes)
//   gbuffer.cull_late   every instance in the frustum against it: next
//                       frame's history, and commands for the newly visible
//   gbuffer.late        draws those over the early ones, then the sky
#include "glint/passes/gbuffer.h"
#include "glint/passes/gbuffer_internal.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"

#include "glint/occlusion_shared.h"

#include <algorithm>
#include <bit>
#include <string>

namespace glint::passes {

using namespace gbuffer_detail;

namespace {

constexpr const char* kVisibilityHistoryName = "gbuffer.visibility";

// The cull takes an instance as hidden only where its bounds lie wholly
// behind what was drawn. Bounds are grown a little first: by a thousandth
// of their diagonal and a millimetre, far more than the float rounding of
// projecting eight corners against the rasterizer's own vertices, so a
// surface lying on its box's face is never taken for hidden behind itself
// or a neighbour flush with it.
constexpr float kBoundsGrowth = 1e-3f;
constexpr float kBoundsGrowthMetres = 1e-3f;

uint32_t groupsFor(uint64_t invocations) {
    return uint32_t(std::max<uint64_t>((invocations + shader::kOcclusionGroupSize - 1) / shader::kOcclusionGroupSize, 1));
}

// The buffers both phases bind (occlusion_cull.glsl); the late phase adds
// its own.
struct CullBuffers {
    rg::Buffer previous, args, stats;
};
gpu::PushDescriptors cullBindings(const gpu::Pipeline& pipeline, const gpu::Buffer& draws, rg::PassContext& pc,
                                  const CullBuffers& buffers) {
    gpu::PushDescriptors push(pipeline);
    push.storageBuffer("Draws", draws)
        .storageBuffer("Previous", pc.buffer(buffers.previous))
        .storageBuffer("Args", pc.buffer(buffers.args))
        .storageBuffer("Stats", pc.buffer(buffers.stats));
    return push;
}

} // namespace

void GBufferRenderer::createOcclusionPipelines() {
    hizBasePipeline_ = gpu::createComputePipeline(
        ctx_, {"gbuffer/hiz_base.comp", {}, uint32_t(sizeof(shader::HizConstants)), "gbuffer.hiz_base"});
    hizDownPipeline_ = gpu::createComputePipeline(
        ctx_, {"gbuffer/hiz_down.comp", {}, uint32_t(sizeof(shader::HizConstants)), "gbuffer.hiz_down"});
    cullEarlyPipeline_ = gpu::createComputePipeline(
        ctx_, {"gbuffer/occlusion_early.comp", {}, uint32_t(sizeof(shader::OcclusionConstants)),
               "gbuffer.cull_early"});
    cullLatePipeline_ = gpu::createComputePipeline(
        ctx_, {"gbuffer/occlusion_late.comp", {}, uint32_t(sizeof(shader::OcclusionConstants)),
               "gbuffer.cull_late"});
}

void GBufferRenderer::prepareOcclusion(FrameWork& work) const {
    const size_t count = work.instances.size();
    work.occlusionInstances.assign(count, shader::OcclusionInstance{});
    std::vector<uint8_t> hasDraws(count, 0);
    work.occlusionDraws.clear();
    work.occlusionDraws.reserve(work.draws.size() + shader::kOcclusionGroupSize);
    work.runFirstSlot.clear();
    constexpr uint32_t chunk = shader::kOcclusionGroupSize;
    for (size_t d = 0; d < work.draws.size(); ++d) {
        const SurfaceDraw& draw = work.draws[d];
        if (d == 0 || draw.run != work.draws[d - 1].run) {
            // A run starts a chunk: pad the last one with empty slots.
            work.occlusionDraws.resize((work.occlusionDraws.size() + chunk - 1) / chunk * chunk);
            work.runFirstSlot.push_back(uint32_t(work.occlusionDraws.size()));
        }
        hasDraws[draw.instance] = 1;
        // A morphing instance draws from its own copy of the vertices: the
        // command carries the shift into it (the shift is the same whatever
        // the slot).
        const int32_t shift = vertexSource(work, draw.instance, *slots_[work.slot]).second;
        work.occlusionDraws.push_back(
            {draw.instance, draw.indexCount, draw.firstIndex, draw.range->vertexOffset + shift});
    }
    work.occlusionDraws.resize((work.occlusionDraws.size() + chunk - 1) / chunk * chunk);
    // A run wastes less than a chunk, and there are at most as many runs as
    // run keys (a state, morphed or not, mirrored or not) or draws.
    const uint64_t runs = std::min<uint64_t>(work.drawCapacity, uint64_t(rangeStates_) * 4);
    work.argsChunks = uint32_t((work.drawCapacity + chunk - 1) / chunk + runs);
    if (work.occlusionDraws.size() > uint64_t(work.argsChunks) * chunk) {
        throw gpu::GpuError("G-buffer: the occlusion cull's " + std::to_string(work.occlusionDraws.size()) +
                            " command slots exceed the " + std::to_string(uint64_t(work.argsChunks) * chunk) +
                            " it sized for this scene");
    }
    for (size_t i = 0; i < count; ++i) {
        if (!hasDraws[i]) continue;  // boundsMin.w = 0: no draws, never visible
        const scene::Aabb& bounds = work.bounds[i];
        shader::OcclusionInstance& out = work.occlusionInstances[i];
        if (bounds.empty()) {
            // Nothing to bound by: a box around everything, which the cull
            // takes as visible (it reaches behind the camera).
            out.boundsMin = glm::vec4(glm::vec3(-1e30f), 1.0f);
            out.boundsMax = glm::vec4(glm::vec3(1e30f), 0.0f);
            continue;
        }
        const float grow = kBoundsGrowth * glm::length(bounds.max - bounds.min) + kBoundsGrowthMetres;
        out.boundsMin = glm::vec4(bounds.min - grow, 1.0f);
        out.boundsMax = glm::vec4(bounds.max + grow, 0.0f);
    }
}

GBufferRenderer::OcclusionHandles GBufferRenderer::addEarlyCull(rg::Graph& graph,
                                                                const std::shared_ptr<FrameWork>& work) {
    OcclusionHandles h;
    const uint32_t instances = uint32_t(work->occlusionInstances.size());
    const uint32_t draws = uint32_t(work->occlusionDraws.size());
    // Sized for every draw the scene can have, so a moving camera keeps
    // one plan (the graph's buffers keep their sizes).
    const uint64_t argsBytes = occlusionArgsBytes(work->argsChunks);
    // A scene with another instance count starts a new (zeroed) pair:
    // nothing drawn early that frame.
    h.visibility = graph.createHistoryBuffer(kVisibilityHistoryName,
                                             {uint64_t(std::max(instances, 1u)) * sizeof(uint32_t)});

    shader::OcclusionConstants constants{};
    constants.drawCount = draws;
    constants.instanceCount = instances;
    constants.countsAt = uint32_t(occlusionCountsOffset(work->argsChunks) / sizeof(uint32_t));
    const CullBuffers& early = graph.addPass<CullBuffers>(
        "gbuffer.cull_early", rg::Queue::Graphics,
        [&](rg::Builder& b, CullBuffers& d) {
            d.previous = b.read(h.visibility.previous, rg::Access::StorageRead);
            d.args = b.write(b.createBuffer("gbuffer.early_args", {argsBytes}), rg::Access::StorageWrite);
            d.stats = b.write(b.createBuffer("gbuffer.occlusion_stats", {shader::kOcclusionStatWords * 4u}),
                              rg::Access::StorageWrite);
        },
        [this, work, constants](const CullBuffers& d, rg::PassContext& pc) {
            uploadOnce(*work);
            const gpu::Pipeline& pipeline = cullEarlyPipeline_;
            pipeline.bind(pc.cmd());
            cullBindings(pipeline, slots_[work->slot]->occlusionDraws, pc, d).push(ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            pc.dispatch(pipeline, groupsFor(constants.drawCount));
        });
    h.earlyArgs = early.args;
    h.stats = early.stats;
    return h;
}

rg::Buffer GBufferRenderer::addLateCull(rg::Graph& graph, const std::shared_ptr<FrameWork>& work,
                                        const GBufferOutputs& early, OcclusionHandles& h) {
    const glm::uvec2 screen{early.width, early.height};
    const glm::uvec2 base = shader::hizBaseSize(screen);
    const uint32_t mips = std::min(shader::kHizMaxMips, uint32_t(std::bit_width(std::max(base.x, base.y))));
    rg::Texture hiz = graph.createTexture(
        "gbuffer.hiz", {.width = base.x, .height = base.y, .mips = mips, .format = VK_FORMAT_R32_SFLOAT});

    // The pyramid: levels 0-4 from the depth, then 5-9 from level 4.
    for (uint32_t pass = 0; pass * shader::kHizLevelsPerPass < mips; ++pass) {
        const uint32_t first = pass * shader::kHizLevelsPerPass;
        const uint32_t end = std::min(mips, first + shader::kHizLevelsPerPass);
        shader::HizConstants constants{};
        const uint32_t sourceLevel = first - 1;  // pass > 0
        constants.sourceValid = pass == 0 ? screen : shader::hizValidSize(screen, sourceLevel);
        constants.outputs = end - first;
        for (uint32_t o = 0; o < constants.outputs; ++o) constants.outputSize[o] = shader::hizLevelSize(base, first + o);
        // Only the source texels the screen reaches: the rest of each level
        // is never read (the cull clamps to the screen).
        const uint32_t groupsX = (constants.sourceValid.x + shader::kHizGroupTexels - 1) / shader::kHizGroupTexels;
        const uint32_t groupsY = (constants.sourceValid.y + shader::kHizGroupTexels - 1) / shader::kHizGroupTexels;
        struct HizData {
            rg::Texture source, hiz;
            uint32_t first = 0, outputs = 0, sourceLevel = 0;
            bool fromDepth = false;
        };
        const HizData& level = graph.addPass<HizData>(
            "gbuffer.hiz", rg::Queue::Graphics,
            [&](rg::Builder& b, HizData& d) {
                d.fromDepth = pass == 0;
                rg::Texture target = hiz;
                if (d.fromDepth) {
                    d.source = b.read(early.depth, rg::Access::SampledRead);
                } else {
                    d.source = target = b.read(hiz, rg::Access::StorageRead, rg::Subresource::mip(sourceLevel));
                }
                d.hiz = b.write(target, rg::Access::StorageWrite,
                                rg::Subresource{first, end - first, 0, rg::Subresource::kAll});
                d.first = first;
                d.outputs = end - first;
                d.sourceLevel = sourceLevel;
            },
            [this, constants, groupsX, groupsY](const HizData& d, rg::PassContext& pc) {
                const gpu::Pipeline& pipeline = d.fromDepth ? hizBasePipeline_ : hizDownPipeline_;
                const gpu::Image& image = pc.image(d.hiz);
                pipeline.bind(pc.cmd());
                gpu::PushDescriptors push(pipeline);
                if (d.fromDepth) {
                    push.sampledImage("source", pc.view(d.source), nearest_.handle(), pc.layout(d.source));
                } else {
                    push.storageImage("source", image.mipView(d.sourceLevel));
                }
                // Outputs past the levels written repeat the last one (never stored to).
                for (uint32_t o = 0; o < shader::kHizLevelsPerPass; ++o) {
                    push.storageImage("output" + std::to_string(o), image.mipView(d.first + std::min(o, d.outputs - 1)));
                }
                push.push(ctx_, pc.cmd());
                pipeline.pushConstants(pc.cmd(), constants);
                pc.dispatch(pipeline, groupsX, groupsY);
            });
        hiz = level.hiz;
    }

    shader::OcclusionConstants constants{};
    constants.viewProjection = work->frame.jitteredViewProjection;
    constants.screenSize = screen;
    constants.hizMips = mips;
    constants.drawCount = uint32_t(work->occlusionDraws.size());
    constants.instanceCount = uint32_t(work->occlusionInstances.size());
    const uint64_t argsBytes = occlusionArgsBytes(work->argsChunks);
    constants.countsAt = uint32_t(occlusionCountsOffset(work->argsChunks) / sizeof(uint32_t));
    struct LateData : CullBuffers {
        rg::Texture hiz;
        rg::Buffer current;
    };
    const LateData& late = graph.addPass<LateData>(
        "gbuffer.cull_late", rg::Queue::Graphics,
        [&](rg::Builder& b, LateData& d) {
            d.hiz = b.read(hiz, rg::Access::SampledRead);
            d.previous = b.read(h.visibility.previous, rg::Access::StorageRead);
            d.current = b.write(h.visibility.current, rg::Access::StorageWrite);
            d.args = b.write(b.createBuffer("gbuffer.late_args", {argsBytes}), rg::Access::StorageWrite);
            d.stats = b.write(h.stats, rg::Access::StorageReadWrite);
        },
        [this, work, constants](const LateData& d, rg::PassContext& pc) {
            const FrameSlot& slot = *slots_[work->slot];
            const gpu::Pipeline& pipeline = cullLatePipeline_;
            pipeline.bind(pc.cmd());
            cullBindings(pipeline, slot.occlusionDraws, pc, d)
                .storageBuffer("Instances", slot.occlusionInstances)
                .storageBuffer("Current", pc.buffer(d.current))
                .sampledImage("hiz", pc.view(d.hiz), nearest_.handle(), pc.layout(d.hiz))
                .push(ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            pc.dispatch(pipeline, groupsFor(uint64_t(constants.drawCount) + constants.instanceCount));
        });
    h.visibility.current = late.current;
    h.stats = late.stats;
    return late.args;
}

} // namespace glint::passes
