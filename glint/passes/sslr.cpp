#include "glint/passes/sslr.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/transfer.h"

#include "glint/ray_generation_shared.h"
#include "glint/sslr_shared.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace glint::passes {

namespace {

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
          ctx, {"sslr/trace.comp", {}, uint32_t(sizeof(shader::SslrConstants)), "sslr.trace"})),
      pyramidBase_(gpu::createComputePipeline(
          ctx, {"sslr/pyramid_base.comp", {},
                uint32_t(sizeof(shader::SslrPyramidConstants)), "sslr.pyramid_base"})),
      pyramidDown_(gpu::createComputePipeline(
          ctx, {"sslr/pyramid_down.comp", {},
                uint32_t(sizeof(shader::SslrPyramidConstants)), "sslr.pyramid_down"})),
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "sslr.nearest"}),
      trilinear_(ctx, {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                       VK_LOD_CLAMP_NONE, "sslr.trilinear"}),
      clearer_(ctx) {}

float sslrStoredThreshold(float threshold) {
    // Round to the nearest half float, as the confidence image stores.
    return glm::unpackHalf1x16(glm::packHalf1x16(threshold));
}

SslrOutputs addSslrPass(rg::Graph& graph, SslrPipelines& pipelines, const SslrInputs& inputs,
                        const SslrSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    const RayGenerationOutputs& rays = inputs.rays;
    if (gbuf.width == 0 || gbuf.height == 0 || rays.width != gbuf.width || rays.height != gbuf.height) {
        throw gpu::GpuError("addSslrPass: the G-buffer and the rays must have the same, non-zero size");
    }
    if (settings.linearSteps == 0 || !(settings.minStepPixels >= 0.0f)) {
        throw gpu::GpuError("addSslrPass: linearSteps must be at least 1 and minStepPixels not negative");
    }
    checkProjection(inputs.projection);
    if (rays.blueNoiseBuffer == nullptr) {
        throw gpu::GpuError("addSslrPass: the rays carry no blue noise buffer (not from addRayGenerationPass)");
    }

    SslrOutputs out;
    out.width = gbuf.width;
    out.height = gbuf.height;

    // The trace writes its ray leaders' pixels only, and its readers read
    // nothing else (glint/sslr_shared.h): no clear, unless asked for.
    const auto texture = [&](const char* name, VkFormat format) {
        return graph.createTexture(name, {.width = gbuf.width, .height = gbuf.height, .format = format});
    };
    std::array<rg::Texture, 3> outputs{texture("sslr.radiance", kSslrRadianceFormat),
                                       texture("sslr.confidence", kSslrConfidenceFormat),
                                       texture("sslr.hit", kSslrHitFormat)};
    if (settings.clearUntraced) {
        pipelines.clearer_.addClearPass(graph, "sslr.clear", outputs);
    }
    const auto [radiance, confidence, hit] = outputs;

    // The cone trace's colour pyramid (glint/sslr_shared.h): the lit
    // colour's mip chain from level 1 on, its mip m - 1 the chain's level m;
    // two passes, each five levels, dispatched from the SSLR list's args,
    // which give them no groups unless ray generation listed a ray that
    // cone-traces.
    uint32_t pyramidMips = 0;  // the chain's levels, the lit colour (level 0) included
    rg::Texture pyramid;
    if (settings.coneTrace) {
        pyramidMips = std::min(shader::kSslrPyramidMaxMips, uint32_t(std::bit_width(std::max(gbuf.width, gbuf.height))));
    }
    if (pyramidMips > 1) {
        const glm::uvec2 size{gbuf.width, gbuf.height};
        const glm::uvec2 base = shader::sslrMipSize(size, 1);
        pyramid = graph.createTexture("sslr.lit_pyramid", {.width = base.x,
                                                            .height = base.y,
                                                            .mips = pyramidMips - 1,
                                                            .format = kSslrRadianceFormat});
        for (uint32_t pass = 0; pass < 2; ++pass) {
            // Pass 0 writes levels 1-5 from the lit colour, pass 1 the levels
            // from 6 on from level 5; `first` and `end` are the image's mips.
            const uint32_t first = pass * shader::kSslrPyramidLevelsPerPass;
            const uint32_t end = std::min(pyramidMips - 1, first + shader::kSslrPyramidLevelsPerPass);
            if (first >= end) break;
            shader::SslrPyramidConstants constants{};
            constants.sourceSize = shader::sslrMipSize(size, first);
            constants.outputs = end - first;
            for (uint32_t o = 0; o < constants.outputs; ++o) {
                constants.outputSize[o] = shader::sslrMipSize(size, first + 1 + o);
            }
            struct PyramidData {
                rg::Texture source, pyramid;
                rg::Buffer args;
                uint32_t first = 0, outputs = 0;
                bool fromLit = false;
            };
            const PyramidData& level = graph.addPass<PyramidData>(
                "sslr.pyramid", rg::Queue::Graphics,
                [&](rg::Builder& b, PyramidData& d) {
                    d.args = b.read(rays.sslrArgs, rg::Access::IndirectArgs);
                    d.fromLit = pass == 0;
                    // Level 5 (the image's mip 4) is read and the levels below
                    // it written through the handle the read returns (the
                    // graph orders both by subresource).
                    rg::Texture target = pyramid;
                    if (d.fromLit) {
                        d.source = b.read(gbuf.lit, rg::Access::SampledRead);
                    } else {
                        d.source = target = b.read(pyramid, rg::Access::StorageRead,
                                                   rg::Subresource::mip(shader::kSslrPyramidLevelsPerPass - 1));
                    }
                    d.pyramid = b.write(target, rg::Access::StorageWrite,
                                        rg::Subresource{first, end - first, 0, rg::Subresource::kAll});
                    d.first = first;
                    d.outputs = end - first;
                    // A frame rendered as rt traces no SSLR ray.
                    if (inputs.screenSpaceIdle) b.skip();
                },
                [&pipelines, constants, pass](const PyramidData& d, rg::PassContext& pc) {
                    const gpu::Pipeline& pipeline = d.fromLit ? pipelines.pyramidBase_ : pipelines.pyramidDown_;
                    const gpu::Image& image = pc.image(d.pyramid);
                    pipeline.bind(pc.cmd());
                    gpu::PushDescriptors push(pipeline);
                    if (d.fromLit) {
                        push.sampledImage("source", pc.view(d.source), pipelines.nearest_.handle(),
                                          pc.layout(d.source));
                    } else {
                        push.storageImage("source", image.mipView(shader::kSslrPyramidLevelsPerPass - 1));
                    }
                    // Outputs past the levels written repeat the last one (never stored to).
                    for (uint32_t o = 0; o < shader::kSslrPyramidLevelsPerPass; ++o) {
                        push.storageImage("output" + std::to_string(o),
                                          image.mipView(d.first + std::min(o, d.outputs - 1)));
                    }
                    push.push(pipelines.ctx_, pc.cmd());
                    pipeline.pushConstants(pc.cmd(), constants);
                    pc.dispatchIndirect(pipeline, d.args,
                                        (shader::kSslrArgsPyramidOffset + 3 * pass) * sizeof(uint32_t));
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
    constants.minStepPixels = settings.minStepPixels;
    constants.refineSteps = settings.refineSteps;
    constants.thickness = settings.thickness;
    constants.maxDistance = settings.maxDistance;
    constants.edgeFade = settings.edgeFade;
    // The shader hands a hybrid ray on below this confidence; above any
    // confidence (at most 1) it hands every one on.
    constants.confidenceThreshold = inputs.handEveryRay ? 2.0f : sslrStoredThreshold(inputs.confidenceThreshold);
    constants.pyramidMips = pyramidMips;
    constants.flags = (rays.blueNoise ? shader::kSslrFlagBlueNoise : 0u) |
                      (settings.relightHits ? shader::kSslrFlagRelight : 0u);
    // The lighting the re-lighting swaps the sun's specular term with: the
    // G-buffer's own (larger than push constants leave room for).
    const rg::Buffer lighting = rg::addUpload(graph, "sslr.lighting", gbuf.lighting);

    struct TraceData {
        rg::Texture depth, normal, albedo, lit, roughnessMetal, pyramid;
        rg::Buffer classes, sslrRays, sslrArgs, lighting;
        SslrOutputs out;
    };
    const TraceData& trace = graph.addPass<TraceData>(
        "sslr", rg::Queue::Graphics,
        [&](rg::Builder& b, TraceData& d) {
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.albedo = b.read(gbuf.albedo, rg::Access::SampledRead);
            d.lit = b.read(gbuf.lit, rg::Access::SampledRead);
            d.lighting = b.read(lighting, rg::Access::StorageRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            if (pyramid.valid()) d.pyramid = b.read(pyramid, rg::Access::SampledRead);
            d.classes = b.read(rays.classes, rg::Access::StorageRead);
            d.sslrRays = b.read(rays.sslrRays, rg::Access::StorageRead);
            // The dispatch's size, and the list's length for the shader.
            d.sslrArgs = b.read(rays.sslrArgs, rg::Access::IndirectArgs);
            b.read(rays.sslrArgs, rg::Access::StorageRead);
            d.out = out;
            d.out.radiance = b.write(radiance, rg::Access::StorageWrite);
            d.out.confidence = b.write(confidence, rg::Access::StorageWrite);
            d.out.hit = b.write(hit, rg::Access::StorageWrite);
            // Appends after ray generation's RT rays.
            d.out.rtRayList = b.write(rays.rtRays, rg::Access::StorageReadWrite);
            d.out.rtArgs = b.write(rays.rtArgs, rg::Access::StorageReadWrite);
            d.out.litPyramid = d.pyramid;
            // A frame rendered as rt traces no SSLR ray.
            if (inputs.screenSpaceIdle) b.skip();
        },
        [&pipelines, constants, blueNoise = rays.blueNoiseBuffer](const TraceData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.trace_;
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("normalTexture", pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage("litTexture", pc.view(d.lit), sampler, pc.layout(d.lit))
                .storageBuffer("Classes", pc.buffer(d.classes))
                .storageBuffer("SslrRays", pc.buffer(d.sslrRays))
                .storageImage("radianceImage", pc.view(d.out.radiance))
                .storageImage("confidenceImage", pc.view(d.out.confidence))
                .storageImage("hitImage", pc.view(d.out.hit))
                .storageBuffer("RtRays", pc.buffer(d.out.rtRayList))
                .storageBuffer("RtArgs", pc.buffer(d.out.rtArgs))
                .sampledImage("roughnessMetalTexture", pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                // Without the cone trace (pyramidMips 0) the pyramid is never
                // read; the lit colour completes the descriptor set.
                .sampledImage("pyramidTexture", pc.view(d.pyramid.valid() ? d.pyramid : d.lit),
                              pipelines.trilinear_.handle(), pc.layout(d.pyramid.valid() ? d.pyramid : d.lit))
                .storageBuffer("SslrArgs", pc.buffer(d.sslrArgs))
                .storageBuffer("BlueNoise", *blueNoise)
                .sampledImage("albedoTexture", pc.view(d.albedo), sampler, pc.layout(d.albedo))
                .storageBuffer("Lighting", pc.buffer(d.lighting))
                .push(pipelines.ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            pc.dispatchIndirect(pipeline, d.sslrArgs, kRayListDispatchArgsBytes);
        });
    return trace.out;
}

} // namespace glint::passes
