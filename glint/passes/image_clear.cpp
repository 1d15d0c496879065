#include "glint/passes/image_clear.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"

#include <algorithm>
#include <vector>

namespace glint::passes {

namespace {

struct ClearConstants {
    glm::vec4 value;
    glm::uvec2 size;
};

gpu::Pipeline createClearPipeline(gpu::Context& ctx) {
    VkPhysicalDeviceFeatures features{};
    vkGetPhysicalDeviceFeatures(ctx.physicalDevice(), &features);
    if (!features.shaderStorageImageWriteWithoutFormat) {
        throw gpu::GpuError("ImageClearer: device '" + ctx.caps().deviceName +
                            "' lacks shaderStorageImageWriteWithoutFormat");
    }
    return gpu::createComputePipeline(
        ctx, {"common/clear_image.comp", {}, uint32_t(sizeof(ClearConstants)), "common.clear_image"});
}

} // namespace

ImageClearer::ImageClearer(gpu::Context& ctx) : ctx_(ctx), pipeline_(createClearPipeline(ctx)) {}

void ImageClearer::clear(rg::PassContext& pc, rg::Texture texture, glm::vec4 value) const {
    const gpu::Image& image = pc.image(texture);
    const ClearConstants constants{value, {image.extent().width, image.extent().height}};
    pipeline_.bind(pc.cmd());
    gpu::PushDescriptors(pipeline_).storageImage("target", pc.view(texture)).push(ctx_, pc.cmd());
    pipeline_.pushConstants(pc.cmd(), constants);
    pc.dispatch(pipeline_, (constants.size.x + 7) / 8, (constants.size.y + 7) / 8);
}

void ImageClearer::addClearPass(rg::Graph& graph, std::string_view name, std::span<rg::Texture> textures) const {
    using Cleared = std::vector<rg::Texture>;
    const Cleared& cleared = graph.addPass<Cleared>(
        name, rg::Queue::Graphics,
        [&](rg::Builder& b, Cleared& d) {
            for (const rg::Texture t : textures) {
                d.push_back(b.write(t, rg::Access::StorageWrite));
            }
        },
        [this](const Cleared& d, rg::PassContext& pc) {
            for (const rg::Texture t : d) {
                clear(pc, t);
            }
        });
    std::copy(cleared.begin(), cleared.end(), textures.begin());
}

} // namespace glint::passes
