#include "present_passes.h"

#include "glint/graph/executor.h"

namespace glint::viewer {

namespace {

// The host reads the counts after the frame's fence: the final state makes
// the copy's writes visible there.
constexpr rg::BoundaryState kHostRead =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

} // namespace

ViewerPasses addViewerPasses(rg::Graph& graph, const ViewerPassesInputs& in) {
    ViewerPasses out;
    const rg::TextureDesc size{.width = in.extent.width, .height = in.extent.height};
    rg::TextureDesc swapchainDesc = size;
    swapchainDesc.format = in.swapchainFormat;
    out.swapchain = graph.importTexture("viewer.swapchain",
                                        {swapchainDesc, rg::BoundaryState::acquired(kAcquireWaitStages),
                                         rg::BoundaryState::of(rg::Access::Present)});
    const bool composeFirst = in.composeFormat != in.swapchainFormat;
    rg::Texture target = out.swapchain;
    if (composeFirst) {
        // The viewer's own image, from frame to frame: it ends each frame
        // read by the copy, and the next frame's blit waits for that read.
        rg::TextureDesc composeDesc = size;
        composeDesc.format = in.composeFormat;
        const rg::BoundaryState copied = rg::BoundaryState::of(rg::Access::TransferSrc);
        out.compose = graph.importTexture("viewer.compose", {composeDesc, copied, copied});
        target = out.compose;
    }

    struct BlitData {
        rg::Texture source, target;
    };
    const VkExtent2D extent = in.extent;
    const BlitData& blit = graph.addPass<BlitData>(
        "viewer.blit", rg::Queue::Graphics,
        [&](rg::Builder& b, BlitData& d) {
            d.source = b.read(in.output, rg::Access::TransferSrc);
            d.target = b.write(target, rg::Access::TransferDst);
        },
        [extent](const BlitData& d, rg::PassContext& pc) {
            // Same size, UNORM to UNORM: every byte arrives unchanged, only
            // the channel order may change (a BGRA target).
            VkImageBlit region{};
            region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.dstSubresource = region.srcSubresource;
            region.srcOffsets[1] = {int32_t(extent.width), int32_t(extent.height), 1};
            region.dstOffsets[1] = region.srcOffsets[1];
            vkCmdBlitImage(pc.cmd(), pc.image(d.source).handle(), pc.layout(d.source), pc.image(d.target).handle(),
                           pc.layout(d.target), 1, &region, VK_FILTER_NEAREST);
        });

    struct UiData {
        rg::Texture target;
    };
    const UiData& ui = graph.addPass<UiData>(
        "viewer.imgui", rg::Queue::Graphics,
        [&](rg::Builder& b, UiData& d) {
            b.setPipeline(rg::Pipeline::Raster);
            d.target = b.write(blit.target, rg::Access::ColorAttachment);
        },
        [drawUi = in.drawUi](const UiData& d, rg::PassContext& pc) {
            if (drawUi) drawUi(pc, d.target);
        });

    if (composeFirst) {
        struct CopyData {
            rg::Texture source, target;
        };
        graph.addPass<CopyData>(
            "viewer.present_copy", rg::Queue::Graphics,
            [&](rg::Builder& b, CopyData& d) {
                d.source = b.read(ui.target, rg::Access::TransferSrc);
                d.target = b.write(out.swapchain, rg::Access::TransferDst);
            },
            [extent](const CopyData& d, rg::PassContext& pc) {
                // UNORM into SRGB of the same texel size: a copy moves bytes, never converts.
                VkImageCopy region{};
                region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                region.dstSubresource = region.srcSubresource;
                region.extent = {extent.width, extent.height, 1};
                vkCmdCopyImage(pc.cmd(), pc.image(d.source).handle(), pc.layout(d.source),
                               pc.image(d.target).handle(), pc.layout(d.target), 1, &region);
            });
    }
    return out;
}

rg::Buffer addCountsReadback(rg::Graph& graph, rg::Buffer counts, uint64_t bytes, std::string_view name) {
    const rg::Buffer imported =
        graph.importBuffer(name, {{bytes}, rg::BoundaryState::of(rg::Access::TransferDst), kHostRead});
    struct CopyData {
        rg::Buffer source, target;
    };
    graph.addPass<CopyData>(
        "viewer.read_counts", rg::Queue::Graphics,
        [&](rg::Builder& b, CopyData& d) {
            d.source = b.read(counts, rg::Access::TransferSrc);
            d.target = b.write(imported, rg::Access::TransferDst);
        },
        [bytes](const CopyData& d, rg::PassContext& pc) {
            const VkBufferCopy region{0, 0, bytes};
            vkCmdCopyBuffer(pc.cmd(), pc.buffer(d.source).handle(), pc.buffer(d.target).handle(), 1, &region);
        });
    return imported;
}

} // namespace glint::viewer
