#include "glint/passes/composite.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"

#include "glint/composite_shared.h"

#include <cmath>
#include <string>
#include <vector>

namespace glint::passes {

namespace {

uint32_t groups(uint32_t pixels) { return (pixels + shader::kCompositeGroupSize - 1) / shader::kCompositeGroupSize; }

enum class SourceClass { Float, Uint, Unsupported };

// Which sampler type reads a format: float for float, normalised, sRGB and
// depth formats; usampler for unsigned integers. Signed integers and
// stencil (a view cannot sample depth and stencil together) are not shown.
SourceClass sourceClass(VkFormat format) {
    switch (format) {
    case VK_FORMAT_R8_UINT:
    case VK_FORMAT_R8G8_UINT:
    case VK_FORMAT_R8G8B8A8_UINT:
    case VK_FORMAT_R16_UINT:
    case VK_FORMAT_R16G16_UINT:
    case VK_FORMAT_R16G16B16A16_UINT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R32G32_UINT:
    case VK_FORMAT_R32G32B32A32_UINT:
    case VK_FORMAT_A2B10G10R10_UINT_PACK32:
        return SourceClass::Uint;
    case VK_FORMAT_UNDEFINED:
    case VK_FORMAT_R8_SINT:
    case VK_FORMAT_R8G8_SINT:
    case VK_FORMAT_R8G8B8A8_SINT:
    case VK_FORMAT_R16_SINT:
    case VK_FORMAT_R16G16_SINT:
    case VK_FORMAT_R16G16B16A16_SINT:
    case VK_FORMAT_R32_SINT:
    case VK_FORMAT_R32G32_SINT:
    case VK_FORMAT_R32G32B32A32_SINT:
    case VK_FORMAT_S8_UINT:
    case VK_FORMAT_D16_UNORM_S8_UINT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
        return SourceClass::Unsupported;
    default:
        return SourceClass::Float;
    }
}

CompositeOutputs outputOf(rg::Builder& b, const char* name, uint32_t width, uint32_t height) {
    CompositeOutputs out;
    out.width = width;
    out.height = height;
    out.color = b.write(b.createTexture(name, {.width = width, .height = height, .format = kCompositeFormat}),
                        rg::Access::StorageWrite);
    return out;
}

} // namespace

CompositePipelines::CompositePipelines(gpu::Context& ctx)
    : ctx_(ctx),
      composite_(gpu::createComputePipeline(ctx, {"composite/composite.comp", {},
                                                  uint32_t(sizeof(shader::CompositeConstants)), "composite"})),
      debugView_(gpu::createComputePipeline(ctx, {"composite/debug_view.comp", {},
                                                  uint32_t(sizeof(shader::DebugViewConstants)), "debug_view"})),
      debugViewUint_(gpu::createComputePipeline(ctx, {"composite/debug_view_uint.comp", {},
                                                      uint32_t(sizeof(shader::DebugViewConstants)),
                                                      "debug_view.uint"})),
      // Every read is a texelFetch; the sampler only completes the combined
      // descriptor (nearest: valid for every format, integers included).
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "composite.nearest"}) {}

CompositeOutputs addCompositePass(rg::Graph& graph, CompositePipelines& pipelines, const CompositeInputs& inputs,
                                  const CompositeSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (gbuf.width == 0 || gbuf.height == 0) {
        throw gpu::GpuError("addCompositePass: the G-buffer has no pixels");
    }
    for (const auto& [texture, what] : {std::pair{inputs.reflections, "reflections"},
                                        std::pair{inputs.transparency, "transparent layer"}}) {
        if (texture.valid() && texture.graph == graph.id() && texture.index < graph.declaration().resources.size()) {
            const rg::TextureDesc& desc = graph.declaration().resources[texture.index].texture;
            if (desc.width != gbuf.width || desc.height != gbuf.height) {
                throw gpu::GpuError(std::string("addCompositePass: the ") + what + " must have the G-buffer's size");
            }
        }
    }
    if (!std::isfinite(settings.exposure) || settings.exposure < 0.0f) {
        throw gpu::GpuError("addCompositePass: the exposure must be finite and not negative");
    }
    shader::CompositeConstants constants{};
    // The matrix the depth was rasterised with: exact positions.
    constants.inverseViewProjection = glm::inverse(inputs.camera.jitteredProjection * inputs.camera.view);
    constants.cameraPosition = glm::vec4(inputs.camera.position, 1.0f);
    constants.size = {gbuf.width, gbuf.height};
    constants.exposure = settings.exposure;
    constants.tonemap = uint32_t(settings.tonemap);
    constants.hasReflections = inputs.reflections.valid() ? 1u : 0u;
    constants.hasTransparency = inputs.transparency.valid() ? 1u : 0u;

    struct Data {
        rg::Texture lit, albedo, normal, roughnessMetal, depth, reflections, transparency;
        CompositeOutputs out;
    };
    const Data& data = graph.addPass<Data>(
        "composite", rg::Queue::Graphics,
        [&](rg::Builder& b, Data& d) {
            d.lit = b.read(gbuf.lit, rg::Access::SampledRead);
            d.albedo = b.read(gbuf.albedo, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            if (inputs.reflections.valid()) {
                d.reflections = b.read(inputs.reflections, rg::Access::SampledRead);
            }
            if (inputs.transparency.valid()) {
                d.transparency = b.read(inputs.transparency, rg::Access::SampledRead);
            }
            d.out = outputOf(b, "composite.color", gbuf.width, gbuf.height);
        },
        [&pipelines, constants](const Data& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.composite_;
            const VkSampler sampler = pipelines.nearest_.handle();
            // Without reflections or a transparent layer the binding still
            // needs an image: the lit colour, which the shader then never
            // reads there.
            const rg::Texture reflections = d.reflections.valid() ? d.reflections : d.lit;
            const rg::Texture transparency = d.transparency.valid() ? d.transparency : d.lit;
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                .sampledImage("litTexture", pc.view(d.lit), sampler, pc.layout(d.lit))
                .sampledImage("albedoTexture", pc.view(d.albedo), sampler, pc.layout(d.albedo))
                .sampledImage("normalTexture", pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage("roughnessMetalTexture", pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                .sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("reflectionTexture", pc.view(reflections), sampler, pc.layout(reflections))
                .sampledImage("transparencyTexture", pc.view(transparency), sampler, pc.layout(transparency))
                .storageImage("outputImage", pc.view(d.out.color))
                .push(pipelines.ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            pc.dispatch(pipeline, groups(constants.size.x), groups(constants.size.y));
        });
    return data.out;
}

CompositeOutputs addDebugViewPass(rg::Graph& graph, CompositePipelines& pipelines, rg::Texture source, uint32_t width,
                                  uint32_t height, const DebugViewSettings& settings) {
    if (!source.valid() || source.graph != graph.id() ||
        source.index >= graph.declaration().resources.size()) {
        throw gpu::GpuError("addDebugViewPass: the source is not a texture of this graph");
    }
    const rg::TextureDesc& desc = graph.declaration().resources[source.index].texture;
    const std::string name(graph.declaration().resources[source.index].name);
    if (desc.layers != 1 || desc.depth != 1) {
        throw gpu::GpuError("addDebugViewPass: '" + name + "' must be a 2D texture of one layer");
    }
    // Of a texture with mips (the SSLR pyramid), mip 0 is shown.
    const bool mipped = desc.mips > 1;
    // A source of half the output's size (its mip 1's) is shown at twice its size.
    const bool magnified = width > desc.width || height > desc.height;
    const bool half = width > 1 && height > 1 && desc.width == width / 2 && desc.height == height / 2;
    if (width == 0 || height == 0 || (magnified && !half)) {
        throw gpu::GpuError("addDebugViewPass: " + std::to_string(width) + "x" + std::to_string(height) +
                            " does not fit in '" + name + "' (" + std::to_string(desc.width) + "x" +
                            std::to_string(desc.height) + ", nor is it half of it)");
    }
    const SourceClass cls = sourceClass(desc.format);
    if (cls == SourceClass::Unsupported) {
        throw gpu::GpuError("addDebugViewPass: '" + name + "' has a format the debug view cannot sample (format " +
                            std::to_string(int(desc.format)) + ")");
    }
    shader::DebugViewConstants constants{};
    constants.size = {width, height};
    constants.kind = settings.kind == DebugViewKind::Scalar ? shader::kDebugViewScalar
                     : settings.kind == DebugViewKind::Raw  ? shader::kDebugViewRaw
                                                            : shader::kDebugViewColor;
    constants.tonemap = uint32_t(settings.tonemap);
    constants.minValue = settings.minValue;
    constants.maxValue = settings.maxValue;
    constants.exposure = settings.exposure;
    constants.sourceShift = magnified ? 1u : 0u;

    struct Data {
        rg::Texture source;
        CompositeOutputs out;
    };
    const gpu::Pipeline* pipeline = cls == SourceClass::Uint ? &pipelines.debugViewUint_ : &pipelines.debugView_;
    const Data& data = graph.addPass<Data>(
        "debug_view." + name, rg::Queue::Graphics,
        [&](rg::Builder& b, Data& d) {
            d.source = b.read(source, rg::Access::SampledRead, mipped ? rg::Subresource::mip(0) : rg::Subresource{});
            d.out = outputOf(b, "debug_view.color", width, height);
        },
        [&pipelines, pipeline, constants, mipped](const Data& d, rg::PassContext& pc) {
            pipeline->bind(pc.cmd());
            const VkImageView view = mipped ? pc.image(d.source).mipView(0) : pc.view(d.source);
            gpu::PushDescriptors(*pipeline)
                .sampledImage("sourceTexture", view, pipelines.nearest_.handle(), pc.layout(d.source))
                .storageImage("outputImage", pc.view(d.out.color))
                .push(pipelines.ctx_, pc.cmd());
            pipeline->pushConstants(pc.cmd(), constants);
            pc.dispatch(*pipeline, groups(constants.size.x), groups(constants.size.y));
        });
    return data.out;
}

} // namespace glint::passes
