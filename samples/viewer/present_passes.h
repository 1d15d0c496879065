#pragma once
// The viewer's own graph passes, after the reflection frame: the frame's
// output blitted into the viewer's target image, the UI drawn over it, and
// the ray counts copied to the host. Declared here, apart from the window
// code, so a test can compile and verify them without a GPU.
//
// The target is imported entering and leaving in TransferSrc: the viewer's
// own submission copies it into the swapchain image after the graph ran
// (main.cpp says why), and the next frame's blit must wait for that copy.

#include "graph/graph.h"

#include <vulkan/vulkan.h>

#include <functional>

namespace glint::viewer {

struct ViewerPassesInputs {
    rg::Texture output;  // the reflection frame's RGBA8 output, sRGB-encoded
    VkExtent2D extent{};  // of the output and the target alike
    VkFormat targetFormat = VK_FORMAT_B8G8R8A8_UNORM;  // a UNORM format: bytes copied, not converted
    // Records the UI inside the pass (the target is a colour attachment
    // in the layout the pass's context reports).
    std::function<void(rg::PassContext&, rg::Texture target)> drawUi;
};

// Returns the imported target, for FrameResources::bind.
rg::Texture addViewerPasses(rg::Graph& graph, const ViewerPassesInputs& in);

// Copies `counts` (ReflectionFrame::counts) into an imported host-visible
// buffer of `bytes`, readable on the host once the frame is complete.
// Returns the import, for FrameResources::bind.
rg::Buffer addCountsReadback(rg::Graph& graph, rg::Buffer counts, uint64_t bytes);

} // namespace glint::viewer
