#pragma once
// Reading a frame's texture back to the host from inside the render graph,
// for the GPU tests: a copy pass into a host-visible buffer the graph
// imports (its final state: host read), marked as an output so it is never
// culled. The caller waits for the frame, then reads buffer.mapped().

#include "gpu/context.h"
#include "gpu/resources.h"
#include "graph/executor.h"
#include "graph/graph.h"

#include <string>

namespace glint::test {

// A buffer large enough for a width x height texture of bytesPerTexel.
inline gpu::Buffer readbackBuffer(gpu::Context& ctx, uint32_t width, uint32_t height, uint32_t bytesPerTexel,
                                  const std::string& name) {
    return gpu::Buffer(ctx, {VkDeviceSize(width) * height * bytesPerTexel, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             gpu::MemoryUsage::Readback, name});
}

// Copies mip 0, layer 0 of `texture` (width x height) into `target`.
inline void addReadback(rg::Graph& graph, rg::Texture texture, uint32_t width, uint32_t height,
                        const gpu::Buffer& target, rg::FrameResources& resources, const std::string& name) {
    const rg::BoundaryState lastCopy = rg::BoundaryState::of(rg::Access::TransferDst);
    const rg::BoundaryState hostRead =
        rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
    const rg::Buffer imported = graph.importBuffer(name, {{target.size()}, lastCopy, hostRead});
    resources.bind(imported, target);
    struct Data {
        rg::Texture source;
        rg::Buffer target;
    };
    const Data& data = graph.addPass<Data>(
        name, rg::Queue::Graphics,
        [&](rg::Builder& b, Data& d) {
            d.source = b.read(texture, rg::Access::TransferSrc);
            d.target = b.write(imported, rg::Access::TransferDst);
        },
        [width, height](const Data& d, rg::PassContext& pc) {
            const gpu::Image& image = pc.image(d.source);
            VkBufferImageCopy region{};
            region.imageSubresource = {image.aspect(), 0, 0, 1};
            region.imageExtent = {width, height, 1};
            vkCmdCopyImageToBuffer(pc.cmd(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.buffer(d.target).handle(), 1, &region);
        });
    graph.markOutput(data.target);
}

} // namespace glint::test
