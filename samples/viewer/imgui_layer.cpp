#include "imgui_layer.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/error.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <spdlog/spdlog.h>

namespace glint::viewer {

namespace {

void checkImGuiVk(VkResult result) {
    // The backend reports VK_SUCCESS through here too.
    if (result != VK_SUCCESS) gpu::check(result, "ImGui Vulkan backend");
}

} // namespace

ImGuiLayer::ImGuiLayer(gpu::Context& ctx, GLFWwindow* window, VkFormat format, uint32_t minImageCount,
                       uint32_t imageCount)
    : ctx_(ctx) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini dropped in the working directory
    ImGui::StyleColorsDark();

    // The backend needs one combined image sampler (its font); a few spare.
    const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 8};
    VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    poolInfo.maxSets = 8;
    poolInfo.poolSizeCount = 1;
    poolInfo.pPoolSizes = &size;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    gpu::check(vkCreateDescriptorPool(ctx_.device(), &poolInfo, nullptr, &pool), "vkCreateDescriptorPool (ImGui)");
    pool_ = gpu::Unique<VkDescriptorPool>(ctx_.device(), pool, vkDestroyDescriptorPool);

    VkAttachmentDescription attachment{};
    attachment.format = format;
    attachment.samples = VK_SAMPLE_COUNT_1_BIT;
    attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // the frame was blitted in first
    attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachment.initialLayout = kUiTargetLayout;
    attachment.finalLayout = kUiTargetLayout;
    const VkAttachmentReference colour{0, kUiTargetLayout};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &colour;
    VkRenderPassCreateInfo rpInfo{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rpInfo.attachmentCount = 1;
    rpInfo.pAttachments = &attachment;
    rpInfo.subpassCount = 1;
    rpInfo.pSubpasses = &subpass;
    VkRenderPass renderPass = VK_NULL_HANDLE;
    gpu::check(vkCreateRenderPass(ctx_.device(), &rpInfo, nullptr, &renderPass), "vkCreateRenderPass (ImGui)");
    renderPass_ = gpu::Unique<VkRenderPass>(ctx_.device(), renderPass, vkDestroyRenderPass);
    ctx_.setName(renderPass, VK_OBJECT_TYPE_RENDER_PASS, "viewer.imgui");

    if (!ImGui_ImplGlfw_InitForVulkan(window, true)) throw gpu::GpuError("ImGui GLFW backend failed to start");
    glfwReady_ = true;

    ImGui_ImplVulkan_InitInfo info{};
    info.Instance = ctx_.instance();
    info.PhysicalDevice = ctx_.physicalDevice();
    info.Device = ctx_.device();
    info.QueueFamily = ctx_.graphicsQueue().family;
    info.Queue = ctx_.graphicsQueue().queue;
    info.DescriptorPool = pool;
    info.Subpass = 0;
    info.MinImageCount = std::max(minImageCount, 2u);
    info.ImageCount = std::max(imageCount, info.MinImageCount);
    info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    info.CheckVkResultFn = checkImGuiVk;
    if (!ImGui_ImplVulkan_Init(&info, renderPass)) throw gpu::GpuError("ImGui Vulkan backend failed to start");
    vulkanReady_ = true;

    // 1.86 uploads its font through a command buffer of ours.
    gpu::submitAndWait(ctx_, ctx_.graphicsQueue(), "ImGui font upload",
                       [](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
    ImGui_ImplVulkan_DestroyFontUploadObjects();
}

ImGuiLayer::~ImGuiLayer() {
    if (vulkanReady_) ImGui_ImplVulkan_Shutdown();
    if (glfwReady_) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

void ImGuiLayer::setTargets(std::span<const gpu::Image* const> targets) {
    framebuffers_.clear();
    extent_ = {};
    for (const gpu::Image* target : targets) {
        const VkImageView view = target->view();
        VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
        info.renderPass = renderPass_.get();
        info.attachmentCount = 1;
        info.pAttachments = &view;
        info.width = target->desc().width;
        info.height = target->desc().height;
        info.layers = 1;
        VkFramebuffer framebuffer = VK_NULL_HANDLE;
        gpu::check(vkCreateFramebuffer(ctx_.device(), &info, nullptr, &framebuffer), "vkCreateFramebuffer (ImGui)");
        framebuffers_.emplace_back(view, gpu::Unique<VkFramebuffer>(ctx_.device(), framebuffer, vkDestroyFramebuffer));
        // All targets share one size (the swapchain's).
        extent_ = {info.width, info.height};
    }
}

void ImGuiLayer::setMinImageCount(uint32_t count) { ImGui_ImplVulkan_SetMinImageCount(std::max(count, 2u)); }

void ImGuiLayer::begin() {
    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    // GLFW reports the window's size now, which a resize may already have
    // changed since the target was made; the draw lists must fit the target
    // (the backend's viewport and scissors come from this size, and on a
    // CPU device drawing past the framebuffer writes past the image).
    ImGuiIO& io = ImGui::GetIO();
    const float sx = io.DisplayFramebufferScale.x > 0.0f ? io.DisplayFramebufferScale.x : 1.0f;
    const float sy = io.DisplayFramebufferScale.y > 0.0f ? io.DisplayFramebufferScale.y : 1.0f;
    io.DisplaySize = ImVec2(float(extent_.width) / sx, float(extent_.height) / sy);
    ImGui::NewFrame();
}

void ImGuiLayer::end() { ImGui::Render(); }

void ImGuiLayer::record(VkCommandBuffer cmd, const gpu::Image& target) const {
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    for (const auto& [view, fb] : framebuffers_) {
        if (view == target.view()) framebuffer = fb.get();
    }
    if (framebuffer == VK_NULL_HANDLE) {
        throw gpu::GpuError("ImGui: '" + target.desc().name + "' is not one of the UI's targets (setTargets)");
    }
    VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    begin.renderPass = renderPass_.get();
    begin.framebuffer = framebuffer;
    begin.renderArea = {{0, 0}, extent_};
    vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
    ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
    vkCmdEndRenderPass(cmd);
}

} // namespace glint::viewer
