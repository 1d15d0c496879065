#include "glint/passes/transparent.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/passes/gbuffer_internal.h"

#include <algorithm>
#include <string>
#include <vector>

namespace glint::passes {

using namespace gbuffer_detail;

gpu::Pipeline GBufferRenderer::createTransparentPipeline() const {
    gpu::GraphicsPipelineDesc desc;
    desc.vertexShader = "gbuffer/gbuffer.vert";
    desc.fragmentShader = "gbuffer/transparent.frag";
    desc.bindings = surfaceBindings();
    desc.pushConstantBytes = sizeof(shader::GBufferDraw);
    desc.dynamicCulling = true;  // per draw, as the G-buffer culls
    desc.colorFormats = {kTransparentFormat};
    desc.depthFormat = kGBufferDepthFormat;
    desc.depthWrite = false;
    // Premultiplied "over" for colour and coverage alike: the shader writes
    // (radiance x a, a).
    VkPipelineColorBlendAttachmentState over{};
    over.blendEnable = VK_TRUE;
    over.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    over.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    over.colorBlendOp = VK_BLEND_OP_ADD;
    over.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    over.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    over.alphaBlendOp = VK_BLEND_OP_ADD;
    over.colorWriteMask =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    desc.colorBlends = {over};
    desc.name = "gbuffer.transparent";
    return gpu::createGraphicsPipeline(ctx_, desc);
}

std::vector<GBufferRenderer::TransparentDraw> GBufferRenderer::transparentDraws(const FrameWork& work) const {
    std::vector<TransparentDraw> draws;
    if (!hasBlended_) return draws;
    const glm::vec3 camera(work.frame.cameraPosition);
    for (size_t i = 0; i < work.instances.size(); ++i) {
        if (!work.visible[i]) continue;
        for (const DrawRange& range : meshDraws_.at(work.meshes[i])) {
            if (range.coverage != Coverage::Blended || range.indexCount == 0) continue;
            const glm::vec3 centre(work.instances[i].transform * glm::vec4(range.bounds.center(), 1.0f));
            const glm::vec3 d = centre - camera;
            draws.push_back({glm::dot(d, d), uint32_t(i), &range});
        }
    }
    // Stable: equal distances keep scene order, so the image is the same
    // every frame and on every device.
    std::stable_sort(draws.begin(), draws.end(),
                     [](const TransparentDraw& a, const TransparentDraw& b) { return a.distanceSq > b.distanceSq; });
    return draws;
}

void GBufferRenderer::recordTransparent(const FrameWork& work, const std::vector<TransparentDraw>& draws,
                                        rg::PassContext& pc, rg::Texture layer, const GBufferOutputs& gbuf,
                                        rg::Texture environment) {
    const VkCommandBuffer cmd = pc.cmd();
    const FrameSlot& slot = *slots_[work.slot];

    // Over the layer the pass before cleared (a compute clear).
    gpu::beginRenderingOverDepth(cmd, pc.view(layer), pc.layout(layer), pc.view(gbuf.depth), pc.layout(gbuf.depth),
                                 {gbuf.width, gbuf.height});
    if (!draws.empty()) {
        vkCmdBindIndexBuffer(cmd, indices_.handle(), 0, VK_INDEX_TYPE_UINT32);
        const gpu::Pipeline& pipeline = transparentPipeline_;
        pipeline.bind(cmd);
        Facing facing;
        facing.bind(cmd);
        const gpu::Buffer* boundVertices = &vertices_;
        MaterialTextures boundTextures = fallbackTextures();
        pushSurfaceBindings(pipeline, pc, slot, *boundVertices, boundTextures, gbuf.shadowMap, environment);
        for (const TransparentDraw& d : draws) {
            const DrawRange& range = *d.range;
            const auto [vertices, vertexShift] = vertexSource(work, d.instance, slot);
            facing.set(cmd, work.mirrored[d.instance] != 0, range.doubleSided);
            MaterialTextures textures = boundTextures;
            rangeTextures(range, textures);
            if (vertices != boundVertices || textures != boundTextures) {
                boundVertices = vertices;
                boundTextures = textures;
                pushSurfaceBindings(pipeline, pc, slot, *boundVertices, boundTextures, gbuf.shadowMap, environment);
            }
            pipeline.pushConstants(cmd, range.material);
            vkCmdDrawIndexed(cmd, range.indexCount, 1, range.firstIndex, range.vertexOffset + vertexShift, d.instance);
        }
    }
    vkCmdEndRendering(cmd);
}

TransparentOutputs addTransparentPass(rg::Graph& graph, GBufferRenderer& renderer, const TransparentInputs& inputs) {
    const std::shared_ptr<GBufferRenderer::FrameWork> work = renderer.current_;
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (!work) {
        throw gpu::GpuError("transparent pass: the G-buffer renderer has declared no frame (call addGBufferPass first)");
    }
    if (glm::vec2(float(gbuf.width), float(gbuf.height)) != work->frame.size) {
        throw gpu::GpuError("transparent pass: the G-buffer given is " + std::to_string(gbuf.width) + "x" +
                            std::to_string(gbuf.height) + ", the renderer's last frame " +
                            std::to_string(uint32_t(work->frame.size.x)) + "x" +
                            std::to_string(uint32_t(work->frame.size.y)));
    }
    if (work->frame.lighting.environment.x != 0.0f && !inputs.environment.valid()) {
        throw gpu::GpuError("transparent pass: the lighting looks up an environment image but no environment texture "
                            "was given (the one addGBufferPass read)");
    }
    // The draws are known now: a frame with no blended surface in view
    // declares nothing (composite then reads no layer).
    auto draws = std::make_shared<const std::vector<GBufferRenderer::TransparentDraw>>(renderer.transparentDraws(*work));
    renderer.stats_.transparentDraws = uint32_t(draws->size());
    if (draws->empty() && !inputs.declareEmpty) return {};
    if (!renderer.transparentClearer_) renderer.transparentClearer_ = std::make_unique<ImageClearer>(renderer.ctx_);

    // A compute clear: a load-op clear of the 1080p layer took 0.30 ms on
    // an H200, whose graphics engine is small (passes/image_clear.h).
    rg::Texture layer = graph.createTexture("transparent.layer",
                                            {.width = gbuf.width, .height = gbuf.height, .format = kTransparentFormat});
    renderer.transparentClearer_->addClearPass(graph, "transparent.clear", std::span(&layer, 1));

    struct Data {
        TransparentOutputs out;
        GBufferOutputs gbuffer;
        rg::Texture environment;
    };
    const Data& data = graph.addPass<Data>(
        "transparent", rg::Queue::Graphics,
        [&](rg::Builder& b, Data& d) {
            b.setPipeline(rg::Pipeline::Raster);
            d.out.width = gbuf.width;
            d.out.height = gbuf.height;
            d.out.layer = b.write(layer, rg::Access::ColorAttachment);
            d.gbuffer = gbuf;
            d.gbuffer.depth = b.read(gbuf.depth, rg::Access::DepthRead);
            d.gbuffer.shadowMap = b.read(gbuf.shadowMap, rg::Access::SampledRead);
            if (inputs.environment.valid()) {
                d.environment = b.read(inputs.environment, rg::Access::SampledRead);
            }
        },
        [&renderer, work, draws](const Data& d, rg::PassContext& pc) {
            renderer.recordTransparent(*work, *draws, pc, d.out.layer, d.gbuffer, d.environment);
        });
    return data.out;
}

} // namespace glint::passes
