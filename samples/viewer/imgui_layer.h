#pragma once
// Dear ImGui on GLFW and Vulkan, drawn by a render-graph pass.
//
// libimgui-dev 1.86's Vulkan backend draws inside a VkRenderPass (dynamic
// rendering came to it later), so this owns a one-subpass render pass that
// loads and stores the target and keeps it in the layout the graph gives a
// colour attachment (ATTACHMENT_OPTIMAL): the graph's barriers around the
// pass do all synchronisation, the render pass none.

#include "glint/gpu/context.h"
#include "glint/gpu/handle.h"
#include "glint/gpu/resources.h"

#include <vulkan/vulkan.h>

#include <span>
#include <utility>
#include <vector>

struct GLFWwindow;

namespace glint::viewer {

// The layout the render graph puts a ColorAttachment use in (access table).
inline constexpr VkImageLayout kUiTargetLayout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL;

class ImGuiLayer {
public:
    // `format`: the target's; `imageCount`: how many frames the backend
    // keeps vertex buffers for (at least the frames in flight).
    ImGuiLayer(gpu::Context& ctx, GLFWwindow* window, VkFormat format, uint32_t minImageCount, uint32_t imageCount);
    ~ImGuiLayer();
    ImGuiLayer(const ImGuiLayer&) = delete;
    ImGuiLayer& operator=(const ImGuiLayer&) = delete;

    // The images it may draw into (one framebuffer each: the swapchain's
    // images, or the viewer's compose image); device idle.
    void setTargets(std::span<const gpu::Image* const> targets);
    // After a swapchain change; device idle.
    void setMinImageCount(uint32_t count);

    // Starts a UI frame (input from GLFW); build windows after it, then end().
    void begin();
    void end();
    // Records the last ended frame's draw lists into `target`, one of the targets.
    void record(VkCommandBuffer cmd, const gpu::Image& target) const;

private:
    gpu::Context& ctx_;
    gpu::Unique<VkDescriptorPool> pool_;
    gpu::Unique<VkRenderPass> renderPass_;
    std::vector<std::pair<VkImageView, gpu::Unique<VkFramebuffer>>> framebuffers_;
    VkExtent2D extent_{};
    bool glfwReady_ = false;
    bool vulkanReady_ = false;
};

} // namespace glint::viewer
