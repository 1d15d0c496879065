#include "passes/sslr.h"

#include "gpu/descriptors.h"
#include "gpu/error.h"
#include "graph/executor.h"

#include "glint/ray_generation_shared.h"
#include "glint/sslr_shared.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace glint::passes {

namespace {

constexpr uint32_t kBindingCount = 14;

std::vector<gpu::Binding> traceBindings() {
    std::vector<gpu::Binding> bindings;
    for (uint32_t i = 0; i < kBindingCount; ++i) {
        VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        if (i < 3 || i == 11 || i == 12) type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        if (i >= 6 && i <= 8) type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
        bindings.push_back({i, type, VK_SHADER_STAGE_COMPUTE_BIT});
    }
    return bindings;
}

uint32_t groupsOf(uint32_t n) { return (n + 7) / 8; }

// The trace inverts the projection from P00, P11, P22 and P32 alone
// (glint/sslr_shared.h); anything else (an off-centre or orthographic
// projection) would be reconstructed wrongly, so it is refused.
void checkProjection(const glm::mat4& p) {
    const bool perspective = p[2][0] == 0.0f && p[2][1] == 0.0f && p[2][3] == -1.0f && p[3][3] == 0.0f &&
                             p[0][1] == 0.0f && p[1][0] == 0.0f && p[3][0] == 0.0f && p[3][1] == 0.0f;
    if (!perspective) {
        throw gpu::GpuError("addSslrPass: the projection must be an unjittered, centred perspective");
    }
}

} // namespace

SslrPipelines::SslrPipelines(gpu::Context& ctx)
    : ctx_(ctx),
      trace_(gpu::createComputePipeline(
          ctx, {"sslr/trace.comp", traceBindings(), uint32_t(sizeof(shader::SslrConstants)), "sslr.trace"})),
      // Every read is a texelFetch; the sampler only completes the combined
      // descriptor.
      pyramidBase_(gpu::createComputePipeline(
          ctx, {"sslr/pyramid_base.comp",
                {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_SHADER_STAGE_COMPUTE_BIT},
                 {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_SHADER_STAGE_COMPUTE_BIT}},
                uint32_t(sizeof(glm::uvec2)),
                "sslr.pyramid_base"})),
      pyramidDown_(gpu::createComputePipeline(
          ctx, {"sslr/pyramid_down.comp",
                {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_SHADER_STAGE_COMPUTE_BIT},
                 {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_SHADER_STAGE_COMPUTE_BIT}},
                uint32_t(sizeof(shader::SslrPyramidConstants)),
                "sslr.pyramid_down"})),
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "sslr.nearest"}),
      trilinear_(ctx, {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                       VK_LOD_CLAMP_NONE, "sslr.trilinear"}),
      clearer_(ctx) {}

SslrOutputs addSslrPass(rg::Graph& graph, SslrPipelines& pipelines, const SslrInputs& inputs,
                        const SslrSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    const RayGenerationOutputs& rays = inputs.rays;
    if (gbuf.width == 0 || gbuf.height == 0 || rays.width != gbuf.width || rays.height != gbuf.height) {
        throw gpu::GpuError("addSslrPass: the G-buffer and the rays must have the same, non-zero size");
    }
    if (settings.linearSteps == 0) {
        throw gpu::GpuError("addSslrPass: linearSteps must be at least 1");
    }
    checkProjection(inputs.projection);

    SslrOutputs out;
    out.width = gbuf.width;
    out.height = gbuf.height;

    // Every frame starts from zero radiance and confidence: only listed
    // tiles' leaders are written, and later passes read the rest as "no
    // reflection yet".
    struct ClearData {
        rg::Texture radiance, confidence, hitDebug;
    };
    const ClearData& clear = graph.addPass<ClearData>(
        "sslr.clear", rg::Queue::Graphics,
        [&](rg::Builder& b, ClearData& d) {
            const auto texture = [&](const char* name, VkFormat format) {
                return b.write(b.createTexture(name, {.width = gbuf.width, .height = gbuf.height, .format = format}),
                               rg::Access::StorageWrite);
            };
            d.radiance = texture("sslr.radiance", kSslrRadianceFormat);
            d.confidence = texture("sslr.confidence", kSslrConfidenceFormat);
            d.hitDebug = texture("sslr.hit_debug", kSslrHitDebugFormat);
        },
        [&pipelines](const ClearData& d, rg::PassContext& pc) {
            for (const rg::Texture t : {d.radiance, d.confidence, d.hitDebug}) {
                pipelines.clearer_.clear(pc, t);
            }
        });

    // The cone trace's colour pyramid: level 0 is the lit colour, each
    // further level the 2x2 mean of the one above, one graph pass per level
    // (each reads the level above and writes its own: the graph orders
    // them by subresource).
    uint32_t pyramidMips = 0;
    rg::Texture pyramid;
    if (settings.coneTrace) {
        pyramidMips = std::min(shader::kSslrPyramidMaxMips, uint32_t(std::bit_width(std::max(gbuf.width, gbuf.height))));
        struct BaseData {
            rg::Texture lit, pyramid;
        };
        const glm::uvec2 size{gbuf.width, gbuf.height};
        const BaseData& base = graph.addPass<BaseData>(
            "sslr.pyramid", rg::Queue::Graphics,
            [&](rg::Builder& b, BaseData& d) {
                d.lit = b.read(gbuf.lit, rg::Access::SampledRead);
                d.pyramid = b.write(b.createTexture("sslr.lit_pyramid", {.width = gbuf.width,
                                                                        .height = gbuf.height,
                                                                        .mips = pyramidMips,
                                                                        .format = kSslrRadianceFormat}),
                                    rg::Access::StorageWrite, rg::Subresource::mip(0));
            },
            [&pipelines, size](const BaseData& d, rg::PassContext& pc) {
                const gpu::Pipeline& pipeline = pipelines.pyramidBase_;
                pipeline.bind(pc.cmd());
                gpu::PushDescriptors(pipeline)
                    .sampledImage(0, pc.view(d.lit), pipelines.nearest_.handle(), pc.layout(d.lit))
                    .storageImage(1, pc.image(d.pyramid).mipView(0))
                    .push(pipelines.ctx_, pc.cmd());
                pipeline.pushConstants(pc.cmd(), size);
                pc.dispatch(pipeline, groupsOf(size.x), groupsOf(size.y));
            });
        pyramid = base.pyramid;
        for (uint32_t m = 1; m < pyramidMips; ++m) {
            struct DownData {
                rg::Texture pyramid;
                uint32_t mip = 0;
            };
            shader::SslrPyramidConstants down{};
            down.sourceSize = {std::max(1u, gbuf.width >> (m - 1)), std::max(1u, gbuf.height >> (m - 1))};
            down.targetSize = {std::max(1u, gbuf.width >> m), std::max(1u, gbuf.height >> m)};
            const DownData& level = graph.addPass<DownData>(
                "sslr.pyramid", rg::Queue::Graphics,
                [&](rg::Builder& b, DownData& d) {
                    const rg::Texture above = b.read(pyramid, rg::Access::StorageRead, rg::Subresource::mip(m - 1));
                    d.pyramid = b.write(above, rg::Access::StorageWrite, rg::Subresource::mip(m));
                    d.mip = m;
                },
                [&pipelines, down](const DownData& d, rg::PassContext& pc) {
                    const gpu::Pipeline& pipeline = pipelines.pyramidDown_;
                    const gpu::Image& image = pc.image(d.pyramid);
                    pipeline.bind(pc.cmd());
                    gpu::PushDescriptors(pipeline)
                        .storageImage(0, image.mipView(d.mip - 1))
                        .storageImage(1, image.mipView(d.mip))
                        .push(pipelines.ctx_, pc.cmd());
                    pipeline.pushConstants(pc.cmd(), down);
                    pc.dispatch(pipeline, groupsOf(down.targetSize.x), groupsOf(down.targetSize.y));
                });
            pyramid = level.pyramid;
        }
    }

    shader::SslrConstants constants{};
    constants.view = inputs.view;
    const glm::mat4& p = inputs.projection;
    constants.projection = {p[0][0], p[1][1], p[2][2], p[3][2]};
    constants.size = {gbuf.width, gbuf.height};
    // The same 32-bit frame as ray generation's noise (glint/sampling.glsl).
    constants.frame = uint32_t(inputs.frameIndex);
    constants.linearSteps = settings.linearSteps;
    constants.refineSteps = settings.refineSteps;
    constants.thickness = settings.thickness;
    constants.maxDistance = settings.maxDistance;
    constants.edgeFade = settings.edgeFade;
    constants.confidenceThreshold = settings.confidenceThreshold;
    constants.coneRoughness = settings.coneRoughness;
    constants.pyramidMips = pyramidMips;

    struct TraceData {
        rg::Texture depth, normal, lit, roughnessMetal, pyramid;
        rg::Buffer rays, classes, sslrRays, sslrArgs;
        SslrOutputs out;
    };
    const TraceData& trace = graph.addPass<TraceData>(
        "sslr", rg::Queue::Graphics,
        [&](rg::Builder& b, TraceData& d) {
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.lit = b.read(gbuf.lit, rg::Access::SampledRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            if (pyramid.valid()) d.pyramid = b.read(pyramid, rg::Access::SampledRead);
            d.rays = b.read(rays.rays, rg::Access::StorageRead);
            d.classes = b.read(rays.classes, rg::Access::StorageRead);
            d.sslrRays = b.read(rays.sslrRays, rg::Access::StorageRead);
            // The dispatch's size, and the list's length for the shader.
            d.sslrArgs = b.read(rays.sslrArgs, rg::Access::IndirectArgs);
            b.read(rays.sslrArgs, rg::Access::StorageRead);
            d.out = out;
            d.out.radiance = b.write(clear.radiance, rg::Access::StorageWrite);
            d.out.confidence = b.write(clear.confidence, rg::Access::StorageWrite);
            d.out.hitDebug = b.write(clear.hitDebug, rg::Access::StorageWrite);
            // Appends after ray generation's RT rays.
            d.out.rtRayList = b.write(rays.rtRays, rg::Access::StorageReadWrite);
            d.out.rtArgs = b.write(rays.rtArgs, rg::Access::StorageReadWrite);
            d.out.litPyramid = d.pyramid;
        },
        [&pipelines, constants](const TraceData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.trace_;
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .sampledImage(0, pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage(1, pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage(2, pc.view(d.lit), sampler, pc.layout(d.lit))
                .storageBuffer(3, pc.buffer(d.rays))
                .storageBuffer(4, pc.buffer(d.classes))
                .storageBuffer(5, pc.buffer(d.sslrRays))
                .storageImage(6, pc.view(d.out.radiance))
                .storageImage(7, pc.view(d.out.confidence))
                .storageImage(8, pc.view(d.out.hitDebug))
                .storageBuffer(9, pc.buffer(d.out.rtRayList))
                .storageBuffer(10, pc.buffer(d.out.rtArgs))
                .sampledImage(11, pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                // Without the cone trace (pyramidMips 0) binding 12 is never
                // read; the lit colour completes the descriptor set.
                .sampledImage(12, pc.view(d.pyramid.valid() ? d.pyramid : d.lit), pipelines.trilinear_.handle(),
                              pc.layout(d.pyramid.valid() ? d.pyramid : d.lit))
                .storageBuffer(13, pc.buffer(d.sslrArgs))
                .push(pipelines.ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            pc.dispatchIndirect(pipeline, d.sslrArgs, kRayListDispatchArgsBytes);
        });
    return trace.out;
}

} // namespace glint::passes
