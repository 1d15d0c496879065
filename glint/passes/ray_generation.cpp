#include "glint/passes/ray_generation.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"

#include "glint/ray_generation_shared.h"
#include "glint/sampling.glsl"
#include "glint/sslr_shared.h"
#include "glint/sampling/blue_noise.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace glint::passes {

static_assert(kRayListDispatchArgsBytes == shader::kRayListDispatchOffset * sizeof(uint32_t));
static_assert(kRayListTraceArgsBytes == shader::kRayListCountOffset * sizeof(uint32_t));
static_assert(uint32_t(ReflectionMode::Hybrid) == shader::kModeHybrid && uint32_t(ReflectionMode::Ssr) == shader::kModeSsr &&
              uint32_t(ReflectionMode::Rt) == shader::kModeRt);

namespace {

// The blue noise in a device-local buffer: staged, copied and made
// visible to every later shader read on the graphics queue, once.
gpu::Buffer uploadBlueNoise(gpu::Context& ctx) {
    const std::vector<uint32_t> words = loadBlueNoiseWords();
    const VkDeviceSize bytes = words.size() * sizeof(uint32_t);
    gpu::Buffer buffer(ctx, {bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             gpu::MemoryUsage::DeviceLocal, "ray_generation.blue_noise"});
    gpu::Buffer staging(ctx, {bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                              "ray_generation.blue_noise.staging"});
    std::memcpy(staging.mapped(), words.data(), bytes);
    gpu::submitAndWait(ctx, ctx.graphicsQueue(), "upload 'ray_generation.blue_noise'", [&](VkCommandBuffer cmd) {
        const VkBufferCopy region{0, 0, bytes};
        vkCmdCopyBuffer(cmd, staging.handle(), buffer.handle(), 1, &region);
        gpu::bufferBarrier(cmd, buffer, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    });
    return buffer;
}

} // namespace

std::filesystem::path blueNoisePath() { return gpu::shaderDirectory() / "noise" / "blue_noise.bin"; }

std::vector<uint32_t> loadBlueNoiseWords() {
    const std::filesystem::path path = blueNoisePath();
    sampling::BlueNoiseTexture texture;
    try {
        texture = sampling::readBlueNoise(path);
    } catch (const std::exception& e) {
        throw gpu::GpuError(e.what());
    }
    if (texture.size.width != shader::kBlueNoiseWidth || texture.size.height != shader::kBlueNoiseHeight ||
        texture.size.depth != shader::kBlueNoiseDepth || texture.channels != shader::kBlueNoiseChannels) {
        throw gpu::GpuError(path.string() + ": blue noise of " + std::to_string(texture.size.width) + "x" +
                            std::to_string(texture.size.height) + "x" + std::to_string(texture.size.depth) + ", " +
                            std::to_string(texture.channels) + " channels; the shaders read " +
                            std::to_string(shader::kBlueNoiseWidth) + "x" + std::to_string(shader::kBlueNoiseHeight) +
                            "x" + std::to_string(shader::kBlueNoiseDepth) + ", " +
                            std::to_string(shader::kBlueNoiseChannels));
    }
    return sampling::blueNoiseWords(texture);
}

RayGenerationPipelines::RayGenerationPipelines(gpu::Context& ctx)
    : ctx_(ctx),
      classify_(gpu::createComputePipeline(ctx, {"ray_generation/classify.comp", {},
                                                 uint32_t(sizeof(shader::RayGenerationConstants)),
                                                 "ray_generation.classify"})),
      // The G-buffer is read texel by texel (texelFetch); the sampler only
      // completes the combined descriptor.
      nearest_(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f,
                     "ray_generation.nearest"}),
      blueNoise_(uploadBlueNoise(ctx)) {}

RayGenerationOutputs addRayGenerationPass(rg::Graph& graph, RayGenerationPipelines& pipelines,
                                          const RayGenerationInputs& inputs, const RayGenerationSettings& settings) {
    const GBufferOutputs& gbuf = inputs.gbuffer;
    if (gbuf.width == 0 || gbuf.height == 0) {
        throw gpu::GpuError("addRayGenerationPass: the G-buffer has no size");
    }
    if (gbuf.width > shader::kRayPixelXMask + 1 || gbuf.height > shader::kRayPixelYMask + 1) {
        throw gpu::GpuError("addRayGenerationPass: the packed ray holds pixels up to 32768 x 16384");
    }
    RayGenerationOutputs out;
    out.blueNoise = settings.blueNoise;
    out.blueNoiseBuffer = &pipelines.blueNoise_;
    out.width = gbuf.width;
    out.height = gbuf.height;
    out.tilesX = (gbuf.width + shader::kTileSize - 1) / shader::kTileSize;
    out.tilesY = (gbuf.height + shader::kTileSize - 1) / shader::kTileSize;
    // A frame the gate renders as rt classifies as rt (the flags below).
    const ReflectionMode listedMode = inputs.screenSpaceIdle ? ReflectionMode::Rt : inputs.mode;
    out.sslrListed = listedMode != ReflectionMode::Rt;
    out.rtListed = listedMode != ReflectionMode::Ssr;
    const uint64_t pixels = uint64_t(gbuf.width) * gbuf.height;

    // The lists count up from zero every frame, and a dispatch's (or a
    // trace's) y and z are 1: the args are reset by a transfer before the
    // classification.
    struct ClearData {
        rg::Buffer sslrArgs, rtArgs;
    };
    const ClearData& clear = graph.addPass<ClearData>(
        "ray_generation.clear_args", rg::Queue::Graphics,
        [&](rg::Builder& b, ClearData& d) {
            d.sslrArgs = b.write(b.createBuffer("ray_generation.sslr_args", {shader::kSslrArgsWords * 4u}),
                                 rg::Access::TransferDst);
            d.rtArgs = b.write(b.createBuffer("ray_generation.rt_args", {shader::kRayListArgsWords * 4u}),
                               rg::Access::TransferDst);
        },
        [size = glm::uvec2(gbuf.width, gbuf.height)](const ClearData& d, rg::PassContext& pc) {
            const std::array<uint32_t, shader::kRayListArgsWords> initial = {0, 1, 1, 0, 1, 1};
            // SSLR's pyramid passes: their groups, closed (z = 0) until a
            // ray that cone-traces is listed.
            const glm::uvec2 base = shader::sslrPyramidGroups(size, 0), down = shader::sslrPyramidGroups(size, 1);
            std::array<uint32_t, shader::kSslrArgsWords> sslr{0, 1, 1, 0, 1, 1};
            const std::array<uint32_t, 6> pyramid = {base.x, base.y, 0, down.x, down.y, 0};
            std::copy(pyramid.begin(), pyramid.end(), sslr.begin() + shader::kSslrArgsPyramidOffset);
            vkCmdUpdateBuffer(pc.cmd(), pc.buffer(d.sslrArgs).handle(), 0, sizeof(sslr), sslr.data());
            vkCmdUpdateBuffer(pc.cmd(), pc.buffer(d.rtArgs).handle(), 0, sizeof(initial), initial.data());
        });

    shader::RayGenerationConstants constants{};
    constants.inverseViewProjection = glm::inverse(inputs.camera.viewProjection());
    constants.cameraPosition = glm::vec4(inputs.camera.position, 1.0f);
    constants.size = {gbuf.width, gbuf.height};
    // The noise's sequences are 32-bit (glint/sampling.glsl); wrapping after
    // 2^32 frames only restarts them.
    constants.frame = uint32_t(inputs.frameIndex);
    constants.roughnessCutoff = settings.roughnessCutoff;
    constants.reuseRoughness = settings.reuseRoughness;
    constants.rtMaxDistance = settings.rtMaxDistance;
    constants.sslrMinDistance = inputs.sslrMinDistance;
    const bool idle = inputs.screenSpaceIdle;
    constants.flags = uint32_t(listedMode) | (settings.reuse ? shader::kRayGenReuse : 0u) |
                      (inputs.tileModes.valid() && !idle ? shader::kRayGenTileModes : 0u) |
                      (settings.checkerboard ? shader::kRayGenCheckerboard : 0u) |
                      (settings.blueNoise ? shader::kRayGenBlueNoise : 0u) |
                      (settings.sslrFirst ? shader::kRayGenSslrFirst : 0u) |
                      (inputs.debugOutputs ? shader::kRayGenClassDebug : 0u);
    constants.coneRoughness = settings.coneRoughness;
    constants.rtToHybridShare = settings.rtToHybridShare;
    constants.tilesX = out.tilesX;

    struct ClassifyData {
        rg::Texture depth, normal, roughnessMetal;
        rg::Buffer tileModes;
        RayGenerationOutputs out;
    };
    const ClassifyData& classify = graph.addPass<ClassifyData>(
        "ray_generation", rg::Queue::Graphics,
        [&](rg::Builder& b, ClassifyData& d) {
            d.depth = b.read(gbuf.depth, rg::Access::SampledRead);
            d.normal = b.read(gbuf.normal, rg::Access::SampledRead);
            d.roughnessMetal = b.read(gbuf.roughnessMetal, rg::Access::SampledRead);
            if (inputs.tileModes.valid()) {
                d.tileModes = b.read(inputs.tileModes, rg::Access::StorageRead);
            }
            d.out = out;
            const auto buffer = [&](const char* name, uint64_t bytes) {
                return b.write(b.createBuffer(name, {bytes}), rg::Access::StorageWrite);
            };
            d.out.rays = buffer("ray_generation.rays", pixels * sizeof(shader::PackedRay));
            d.out.classes = buffer("ray_generation.classes", pixels * sizeof(uint32_t));
            d.out.sslrRays = buffer("ray_generation.sslr_rays", pixels * sizeof(shader::PackedRay));
            d.out.rtRays = buffer("ray_generation.rt_rays", pixels * sizeof(shader::PackedRay));
            d.out.sslrArgs = b.write(clear.sslrArgs, rg::Access::StorageReadWrite);
            d.out.rtArgs = b.write(clear.rtArgs, rg::Access::StorageReadWrite);
            d.out.classDebug = b.write(b.createTexture("ray_generation.class_debug",
                                                       {.width = gbuf.width, .height = gbuf.height,
                                                        .format = kRayClassDebugFormat}),
                                       rg::Access::StorageWrite);
        },
        [&pipelines, constants, idle](const ClassifyData& d, rg::PassContext& pc) {
            const gpu::Pipeline& pipeline = pipelines.classify_;
            const VkSampler sampler = pipelines.nearest_.handle();
            pipeline.bind(pc.cmd());
            gpu::PushDescriptors(pipeline)
                // Layouts as the plan chose them (a sampled depth image stays depth read-only).
                .sampledImage("depthTexture", pc.view(d.depth), sampler, pc.layout(d.depth))
                .sampledImage("normalTexture", pc.view(d.normal), sampler, pc.layout(d.normal))
                .sampledImage("roughnessMetalTexture", pc.view(d.roughnessMetal), sampler, pc.layout(d.roughnessMetal))
                .storageBuffer("Rays", pc.buffer(d.out.rays))
                .storageBuffer("Classes", pc.buffer(d.out.classes))
                .storageBuffer("SslrRays", pc.buffer(d.out.sslrRays))
                .storageBuffer("SslrArgs", pc.buffer(d.out.sslrArgs))
                .storageBuffer("RtRays", pc.buffer(d.out.rtRays))
                .storageImage("classDebug", pc.view(d.out.classDebug))
                .storageBuffer("RtArgs", pc.buffer(d.out.rtArgs))
                // Without tile modes the shader never reads them; the blue
                // noise, which no pass writes, only completes the descriptor
                // set. (A buffer of the graph would be a read it does not
                // know of: sync validation takes a bound readonly buffer as
                // read, and the class buffer may alias memory a pass wrote.)
                .storageBuffer("TileModes", d.tileModes.valid() && !idle ? pc.buffer(d.tileModes) : pipelines.blueNoise_)
                .storageBuffer("BlueNoise", pipelines.blueNoise_)
                .push(pipelines.ctx_, pc.cmd());
            pipeline.pushConstants(pc.cmd(), constants);
            pc.dispatch(pipeline, d.out.tilesX, d.out.tilesY);
        });
    RayGenerationOutputs result = classify.out;
    if (!inputs.debugOutputs) {
        // Declared (the binding needs an image) but never stored to.
        result.classDebug = {};
    }
    return result;
}

} // namespace glint::passes
