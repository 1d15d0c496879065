#include "glint/passes/environment.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"

#include "glint/environment_shared.h"

#include <glm/gtc/constants.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

namespace glint::passes {

namespace {

// The largest finite half float: the prefiltered image is RGBA16F.
constexpr float kMaxHalf = 65504.0f;
// The SH projection reads the first source mip at most this wide: a few
// thousand texels hold all nine coefficients' detail.
constexpr uint32_t kIrradianceMaxWidth = 64;
constexpr uint32_t kSourceMinWidth = 32;
constexpr uint32_t kMaxSamples = 1024;

uint32_t groups(uint32_t n) { return (n + 7) / 8; }

uint32_t mipCount(uint32_t width, uint32_t height) {
    return uint32_t(std::bit_width(std::max(width, height)));
}

} // namespace

gpu::Sampler createEnvironmentSampler(gpu::Context& ctx, const std::string& name) {
    gpu::SamplerDesc desc;
    desc.filter = VK_FILTER_LINEAR;
    desc.mipmap = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    desc.address = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    desc.addressV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    desc.name = name;
    return gpu::Sampler(ctx, desc);
}

EnvironmentMap::EnvironmentMap(gpu::Context& ctx, const scene::Scene& scene, const EnvironmentSettings& settings)
    : ctx_(ctx), scene_(scene), settings_(settings) {
    source_ = gpu::createComputePipeline(
        ctx, {"environment/source.comp", {},
              uint32_t(sizeof(shader::EnvironmentPrefilterConstants)), "environment.source"});
    downsample_ = gpu::createComputePipeline(
        ctx, {"environment/downsample.comp", {},
              uint32_t(sizeof(shader::EnvironmentPrefilterConstants)), "environment.downsample"});
    prefilter_ = gpu::createComputePipeline(
        ctx, {"environment/prefilter.comp", {},
              uint32_t(sizeof(shader::EnvironmentPrefilterConstants)), "environment.prefilter"});
    irradiance_ = gpu::createComputePipeline(
        ctx, {"environment/irradiance.comp", {},
              uint32_t(sizeof(shader::EnvironmentPrefilterConstants)), "environment.irradiance"});
    sampler_ = createEnvironmentSampler(ctx, "environment.trilinear");
    refresh();
}

EnvironmentMap::~EnvironmentMap() {
    // Frames in flight may still sample the image.
    ctx_.waitIdleForTeardown("environment map");
}

EnvironmentMap::Fingerprint EnvironmentMap::fingerprint() const {
    const scene::Environment& env = scene_.environment;
    Fingerprint f;
    f.kind = env.kind;
    if (env.kind == scene::EnvironmentKind::EquirectangularImage) {
        f.width = env.image.width;
        f.height = env.image.height;
        f.pixels = env.image.rgba32f.data();
    }
    return f;
}

bool EnvironmentMap::update() {
    if (fingerprint() == last_) return false;
    refresh();
    return true;
}

void EnvironmentMap::refresh() {
    const scene::Environment& env = scene_.environment;
    last_ = fingerprint();
    sky_ = environmentSkyColors(env);
    if (radiance_) {
        ctx_.waitIdle();  // frames in flight may sample the old image
    }
    radiance_ = {};
    irradianceSh_ = {};
    const EnvironmentStats previous = stats_;
    stats_ = {};
    stats_.prefilters = previous.prefilters;
    if (env.kind != scene::EnvironmentKind::EquirectangularImage) return;
    if (!env.image.valid() || env.image.format != scene::TextureFormat::Rgba32Float) {
        throw gpu::GpuError("environment '" + env.image.name +
                            "': an equirectangular environment needs a valid RGBA32F image "
                            "(scene::loadEquirectangularEnvironment makes one)");
    }
    prefilter(env.image);
}

void EnvironmentMap::prefilter(const scene::Texture& image) {
    const auto start = std::chrono::steady_clock::now();
    const std::string name = image.name.empty() ? std::string("environment") : image.name;

    // The source chain: the sanitised image and its box mips, which the
    // filtered importance sampling reads.
    const uint32_t sourceMips = mipCount(image.width, image.height);
    gpu::Image chain(ctx_, {.width = image.width,
                            .height = image.height,
                            .mips = sourceMips,
                            .format = kEnvironmentFormat,
                            .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                            .name = "environment.source_chain (" + name + ")"});
    // Level 0: the first source mip at most maxWidth wide; the last level
    // kEnvironmentMinWidth wide (or level 0 when the image is that small).
    uint32_t top = 0;
    while ((image.width >> top) > std::max(settings_.maxWidth, 1u) && top + 1 < sourceMips) ++top;
    const uint32_t width = std::max(image.width >> top, 1u);
    const uint32_t height = std::max(image.height >> top, 1u);
    uint32_t levels = 1;
    while ((width >> levels) >= shader::kEnvironmentMinWidth) ++levels;
    const float maxLod = float(levels - 1);
    radiance_ = gpu::Image(ctx_, {.width = width,
                                  .height = height,
                                  .mips = levels,
                                  .format = kEnvironmentFormat,
                                  .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                  .name = "environment.radiance (" + name + ")"});
    // Filtered importance sampling reads no mip narrower than this: at the
    // coarser mips one bilinear texel spans a quarter of the sphere and
    // would smear a horizon across the whole lobe.
    uint32_t sourceMaxLod = 0;
    while ((image.width >> (sourceMaxLod + 1)) >= kSourceMinWidth && sourceMaxLod + 1 < sourceMips) ++sourceMaxLod;
    uint32_t irradianceMip = 0;
    while ((image.width >> irradianceMip) > kIrradianceMaxWidth && irradianceMip + 1 < sourceMips) ++irradianceMip;

    const VkDeviceSize sourceBytes = VkDeviceSize(image.width) * image.height * 4 * sizeof(float);
    gpu::Buffer upload(ctx_, {sourceBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Upload,
                              "environment.upload (" + name + ")"});
    std::memcpy(upload.mapped(), image.rgba32f.data(), sourceBytes);
    gpu::Buffer coefficients(ctx_, {sizeof(glm::vec4) * shader::kEnvironmentShCount, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                    gpu::MemoryUsage::Readback, "environment.irradiance_sh (" + name + ")"});

    shader::EnvironmentPrefilterConstants base{};
    base.sourceSize = {image.width, image.height};
    base.sourceMaxLod = float(sourceMaxLod);
    base.maxValue = kMaxHalf;
    base.samples = std::max(settings_.samples, 1u);

    gpu::submitAndWait(ctx_, ctx_.graphicsQueue(), "environment prefilter of '" + name + "'", [&](VkCommandBuffer cmd) {
        gpu::ScopedLabel label(ctx_, cmd, "environment.prefilter");
        constexpr VkPipelineStageFlags2 kCs = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        gpu::imageBarrier(cmd, chain, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, 0,
                          kCs, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        gpu::imageBarrier(cmd, radiance_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                          VK_PIPELINE_STAGE_2_NONE, 0, kCs, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        const auto afterWrites = [&](VkAccessFlags2 dstAccess) {
            gpu::memoryBarrier(cmd, kCs, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, kCs, dstAccess);
        };

        // 1. Source -> chain mip 0, sanitised.
        shader::EnvironmentPrefilterConstants c = base;
        c.size = {image.width, image.height};
        source_.bind(cmd);
        gpu::PushDescriptors(source_)
            .storageBuffer("Source", upload)
            .storageImage("chainImage", chain.mipView(0))
            .push(ctx_, cmd);
        source_.pushConstants(cmd, c);
        vkCmdDispatch(cmd, groups(c.size.x), groups(c.size.y), 1);

        // 2. The chain's box mips.
        downsample_.bind(cmd);
        for (uint32_t mip = 1; mip < sourceMips; ++mip) {
            afterWrites(VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
            c.size = {std::max(image.width >> mip, 1u), std::max(image.height >> mip, 1u)};
            gpu::PushDescriptors(downsample_)
                .storageImage("aboveImage", chain.mipView(mip - 1))
                .storageImage("mipImage", chain.mipView(mip))
                .push(ctx_, cmd);
            downsample_.pushConstants(cmd, c);
            vkCmdDispatch(cmd, groups(c.size.x), groups(c.size.y), 1);
        }
        afterWrites(VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);

        // 3. Each level of the prefiltered image, from the chain.
        prefilter_.bind(cmd);
        for (uint32_t level = 0; level < levels; ++level) {
            c = base;
            c.size = {std::max(width >> level, 1u), std::max(height >> level, 1u)};
            c.roughness = shader::environmentRoughnessOfLevel(float(level), maxLod);
            // Each level has a quarter of the texels of the one above and a
            // wider lobe: twice the samples keep its cost falling and its
            // structured error (one Hammersley set for every texel) small.
            c.samples = std::min(base.samples << std::min(level > 0 ? level - 1 : 0u, 8u), kMaxSamples);
            c.sourceLevel = top;
            gpu::PushDescriptors(prefilter_)
                .sampledImage("sourceTexture", chain.view(), sampler_.handle(), VK_IMAGE_LAYOUT_GENERAL)
                .storageImage("levelImage", radiance_.mipView(level))
                .push(ctx_, cmd);
            prefilter_.pushConstants(cmd, c);
            vkCmdDispatch(cmd, groups(c.size.x), groups(c.size.y), 1);
        }

        // 4. The irradiance's SH coefficients.
        c = base;
        c.size = {std::max(image.width >> irradianceMip, 1u), std::max(image.height >> irradianceMip, 1u)};
        c.sourceLevel = irradianceMip;
        irradiance_.bind(cmd);
        gpu::PushDescriptors(irradiance_)
            .sampledImage("sourceTexture", chain.view(), sampler_.handle(), VK_IMAGE_LAYOUT_GENERAL)
            .storageBuffer("Coefficients", coefficients)
            .push(ctx_, cmd);
        irradiance_.pushConstants(cmd, c);
        vkCmdDispatch(cmd, 1, 1, 1);

        // Frames sample the image in READ_ONLY_OPTIMAL (the graph's
        // SampledRead); the next submission's wait orders them after this.
        gpu::imageBarrier(cmd, radiance_, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL, kCs,
                          VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        gpu::memoryBarrier(cmd, kCs, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                           VK_ACCESS_2_HOST_READ_BIT);
    });

    // Cosine convolution, and the midpoint rule's solid angle made exactly
    // 4 pi (the rows' sines sum to a little more than 2 / dtheta).
    const uint32_t shHeight = std::max(image.height >> irradianceMip, 1u);
    double rowSines = 0.0;
    for (uint32_t y = 0; y < shHeight; ++y) {
        rowSines += std::sin((double(y) + 0.5) / double(shHeight) * glm::pi<double>());
    }
    const double solidAngle = 2.0 * glm::pi<double>() * glm::pi<double>() / double(shHeight) * rowSines;
    const float normalise = float(4.0 * glm::pi<double>() / solidAngle);
    const auto projected = coefficients.mappedSpan<glm::vec4>();
    for (uint32_t j = 0; j < shader::kEnvironmentShCount; ++j) {
        irradianceSh_[j] = glm::vec4(glm::vec3(projected[j]) * (shader::environmentShCosineFactor(j) * normalise), 0.0f);
    }

    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    stats_.width = width;
    stats_.height = height;
    stats_.levels = levels;
    stats_.sourceWidth = image.width;
    stats_.sourceHeight = image.height;
    ++stats_.prefilters;
    stats_.prefilterMs = ms;
    uint64_t texels = 0;
    for (uint32_t level = 0; level < levels; ++level) {
        texels += uint64_t(std::max(width >> level, 1u)) * std::max(height >> level, 1u);
    }
    stats_.bytes = texels * 8;
    spdlog::info("environment '{}': {}x{} prefiltered to {}x{} in {} roughness levels ({} samples, doubled per level) in {:.1f} ms", name,
                 image.width, image.height, width, height, levels, base.samples, ms);
    spdlog::debug("environment '{}': source chain {} mips, SH from mip {}, irradiance up {:.3f} {:.3f} {:.3f}", name,
                  sourceMips, irradianceMip, irradianceSh_[0].x, irradianceSh_[0].y, irradianceSh_[0].z);
}

const gpu::Image& EnvironmentMap::radiance() const {
    if (!radiance_) {
        throw gpu::GpuError("environment: the scene's environment is the procedural sky; there is no prefiltered image");
    }
    return radiance_;
}

shader::SceneLighting EnvironmentMap::lighting(const LightingSettings& settings) const {
    shader::SceneLighting l = sceneLighting(scene_, sky_, settings);
    if (radiance_) {
        const scene::Environment& env = scene_.environment;
        l.environment = glm::vec4(1.0f, env.intensity * settings.ambientScale, float(stats_.levels - 1),
                                  env.rotationRadians);
        for (uint32_t j = 0; j < shader::kEnvironmentShCount; ++j) l.irradianceSh[j] = irradianceSh_[j];
    }
    return l;
}

void EnvironmentMap::bind(rg::FrameResources& resources, rg::Texture handle) const {
    if (handle.valid()) resources.bind(handle, radiance());
}

rg::Texture importEnvironment(rg::Graph& graph, const EnvironmentMap& map) {
    if (!map.hasImage()) return {};
    const gpu::ImageDesc& desc = map.radiance().desc();
    const rg::BoundaryState sampled = rg::BoundaryState::of(rg::Access::SampledRead);
    return graph.importTexture("environment.radiance",
                               {{.width = desc.width, .height = desc.height, .mips = desc.mips, .format = desc.format},
                                sampled,
                                sampled});
}

} // namespace glint::passes
