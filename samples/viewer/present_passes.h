#pragma once
// The viewer's own graph passes, after the reflection frame: the frame's
// output blitted into the acquired swapchain image, the UI drawn over it,
// the image handed to presentation, and the ray counts copied to the host.
// Declared here, apart from the window code, so a test can compile and
// verify them without a GPU.
//
// The swapchain image is imported acquired (its acquire semaphore waited at
// the blit's transfer stage, BoundaryState::acquired) and ends in Present
// (PRESENT_SRC_KHR, the render-finished semaphore signalled after the
// transition): main.cpp names the semaphores through FrameResources.
//
// Colour: the output's bytes are sRGB-encoded and must reach the screen
// unchanged (swapchain.h). A UNORM swapchain takes them straight: a UNORM
// to UNORM blit, the UI drawn over them in the same encoded space. An
// SRGB-only swapchain would re-encode a blit's or the UI's values, so there
// the frame is composed in a UNORM image of the viewer's and raw-copied
// (bytes unchanged) into the swapchain image, still inside the graph.

#include "glint/graph/graph.h"

#include <vulkan/vulkan.h>

#include <functional>
#include <string_view>

namespace glint::viewer {

// The stages the acquire semaphore is waited at: the first use of the
// swapchain image is a transfer (the blit, or the compose copy).
inline constexpr VkPipelineStageFlags2 kAcquireWaitStages = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;

struct ViewerPassesInputs {
    rg::Texture output;  // the reflection frame's RGBA8 output, sRGB-encoded
    VkExtent2D extent{};  // of the output and the swapchain image alike
    VkFormat swapchainFormat = VK_FORMAT_B8G8R8A8_UNORM;
    // The UNORM format of the same bytes: equal to swapchainFormat, the
    // frame is drawn straight into the swapchain image; else composed in an
    // image of this format first.
    VkFormat composeFormat = VK_FORMAT_B8G8R8A8_UNORM;
    // Records the UI inside the pass (the target is a colour attachment
    // in the layout the pass's context reports).
    std::function<void(rg::PassContext&, rg::Texture target)> drawUi;
};

struct ViewerPasses {
    rg::Texture swapchain;  // bind the acquired image; its semaphores go with it
    rg::Texture compose;    // valid only when composing first: bind the viewer's compose image
};

ViewerPasses addViewerPasses(rg::Graph& graph, const ViewerPassesInputs& in);

// Copies `counts` (ReflectionFrame::counts, or the G-buffer's occlusion
// counts) into an imported host-visible buffer of `bytes` named `name`,
// readable on the host once the frame is complete. Returns the import, for
// FrameResources::bind.
rg::Buffer addCountsReadback(rg::Graph& graph, rg::Buffer counts, uint64_t bytes,
                             std::string_view name = "viewer.counts");

} // namespace glint::viewer
