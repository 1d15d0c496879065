#pragma once
// A texture filled by the host, inside a graph: the host writes a buffer,
// and a copy pass of the graph moves it into a transient texture under the
// graph's own barriers.
#include "glint/gpu/resources.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"

#include <string>

namespace glint::test {

// A width x height texture of `format` holding `source`'s tightly packed
// texels (a host-written transfer source the caller keeps alive until the
// frame has run).
inline rg::Texture uploadTexture(rg::Graph& graph, rg::FrameResources& resources, const gpu::Buffer& source,
                                 const std::string& name, VkFormat format, uint32_t width, uint32_t height) {
    constexpr rg::BoundaryState kHostWritten =
        rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
    const rg::Buffer staging = graph.importBuffer(
        name + ".staging", {{source.size()}, kHostWritten, rg::BoundaryState::of(rg::Access::TransferSrc)});
    resources.bind(staging, source);
    struct Data {
        rg::Buffer source;
        rg::Texture texture;
        uint32_t width = 0, height = 0;
    };
    const Data& d = graph.addPass<Data>(
        "upload." + name, rg::Queue::Graphics,
        [&](rg::Builder& b, Data& data) {
            data.source = b.read(staging, rg::Access::TransferSrc);
            data.texture = b.write(b.createTexture(name, {.width = width, .height = height, .format = format}),
                                   rg::Access::TransferDst);
            data.width = width;
            data.height = height;
        },
        [](const Data& data, rg::PassContext& pc) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {data.width, data.height, 1};
            vkCmdCopyBufferToImage(pc.cmd(), pc.buffer(data.source).handle(), pc.image(data.texture).handle(),
                                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        });
    return d.texture;
}

} // namespace glint::test
