// glint-viewer: the reflection frame (passes/reflection_frame.h) in a window,
// with a fly camera and an ImGui panel over the same settings structs
// glint-render and the benchmark use.
//
// One frame:
//   1. acquire a swapchain image (its semaphore per frame slot);
//   2. the render graph: the reflection frame, then "viewer.blit" copies its
//      output into the acquired image and "viewer.imgui" draws the panel
//      over it (present_passes.h). The image is imported through a
//      non-owning gpu::Image; the executor makes the batch of its first use
//      wait on the acquire semaphore, ends it in PRESENT_SRC and signals
//      the image's render-finished semaphore from the batch that does;
//   3. vkQueuePresentKHR waits on that semaphore.
// A slot is reused once the executor says its frame is done
// (rg::SubmittedFrame): its acquire semaphore and count readback are free.
//
// Colour: the output's bytes are sRGB-encoded; they travel unchanged
// (UNORM to UNORM blit, or a raw copy into an SRGB-only swapchain), see
// swapchain.h.

#include "common/app.h"
#include "common/reflection_run.h"
#include "glint/gpu/commands.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan_cache.h"
#include "glint/graph/verify.h"
#include "imgui_layer.h"
#include "plan_view.h"
#include "present_passes.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "swapchain.h"
#include "viewer_model.h"

#include "glint/occlusion_shared.h"
#include "glint/reflection_frame_shared.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <spdlog/spdlog.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cstdio>
#include <array>
#include <cstring>
#include <memory>
#include <optional>

using namespace glint;

namespace {

constexpr uint32_t kFramesInFlight = 2;

// ---- GLFW: the library and one window

std::string& glfwLastError() {
    static std::string text;
    return text;
}

void onGlfwError(int code, const char* text) {
    glfwLastError() = text ? std::string(text) : "GLFW error " + std::to_string(code);
}

class Window {
public:
    Window(const char* title, uint32_t width, uint32_t height) {
        glfwSetErrorCallback(onGlfwError);
        // No display (CI, ssh): glfwInit fails and says why; that becomes
        // the executable's one-line error.
        if (!glfwInit()) {
            throw std::runtime_error("cannot open a window: " + glfwLastError() +
                                     " (glint-viewer needs a display; glint-render renders without one)");
        }
        if (!glfwVulkanSupported()) {
            glfwTerminate();
            throw std::runtime_error("cannot open a window: GLFW finds no Vulkan loader or no window-system "
                                     "support in it (scripts/setup installs the loader)");
        }
        glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
        window_ = glfwCreateWindow(int(width), int(height), title, nullptr, nullptr);
        if (!window_) {
            glfwTerminate();
            throw std::runtime_error("cannot open a window: " + glfwLastError());
        }
        // Keys are polled once a frame; sticky keys keep a tap shorter than
        // a frame (a CPU device renders a few a second) from being lost.
        glfwSetInputMode(window_, GLFW_STICKY_KEYS, GLFW_TRUE);
    }
    ~Window() {
        glfwDestroyWindow(window_);
        glfwTerminate();
    }
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    GLFWwindow* handle() const { return window_; }

    std::vector<std::string> instanceExtensions() const {
        uint32_t count = 0;
        const char** names = glfwGetRequiredInstanceExtensions(&count);
        return std::vector<std::string>(names, names + count);
    }
    VkExtent2D framebufferSize() const {
        int w = 0, h = 0;
        glfwGetFramebufferSize(window_, &w, &h);
        return {uint32_t(std::max(w, 0)), uint32_t(std::max(h, 0))};
    }

private:
    GLFWwindow* window_ = nullptr;
};

// The window's Vulkan surface; destroyed before the instance (declare after the Context).
class Surface {
public:
    Surface(const gpu::Context& ctx, const Window& window) : instance_(ctx.instance()) {
        gpu::check(glfwCreateWindowSurface(instance_, window.handle(), nullptr, &surface_), "glfwCreateWindowSurface");
    }
    ~Surface() { vkDestroySurfaceKHR(instance_, surface_, nullptr); }
    Surface(const Surface&) = delete;
    Surface& operator=(const Surface&) = delete;
    VkSurfaceKHR handle() const { return surface_; }

private:
    VkInstance instance_;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
};

// ---- what the panel shows

struct RayCounts {
    std::array<uint32_t, shader::kPixelClassCount> pixelClasses{};
    uint32_t sslrRays = 0;
    uint32_t rtRays = 0;
    bool valid = false;
    // The G-buffer's occlusion cull (shader::kOcclusionStat*), where it ran.
    std::optional<std::array<uint32_t, shader::kOcclusionStatWords>> occlusion;
};

// Per frame in flight: the acquire semaphore and the count readback.
struct FrameSlot {
    gpu::Unique<VkSemaphore> acquired;
    // The frame that used the slot last, until the slot is reused; none
    // after the executor was replaced (the device was idle then).
    std::optional<rg::SubmittedFrame> submitted;
    gpu::Buffer counts;
    gpu::Buffer occlusion;
    bool countsPending = false;
    bool occlusionPending = false;
};

class Viewer {
public:
    Viewer(gpu::Context& ctx, Window& window, VkSurfaceKHR surface, scene::Scene& scene,
           const viewer::ViewerOptions& options, float startSeconds)
        : ctx_(ctx), window_(window), scene_(scene), sliders_(viewer::parameterSliders()),
          swapchain_(ctx, surface, window.framebufferSize()), sizedFor_(window.framebufferSize()),
          sceneTime_(startSeconds) {
        options_.renderer.framesInFlight = kFramesInFlight;
        options_.renderer.backend = options.backend;
        options_.frame.mode = options.mode;
        options_.frame.debugView = options.debugView;
        showGraph_ = options.graphPanel;
        builtWith_ = options_.renderer;
        renderer_ = std::make_unique<passes::ReflectionRenderer>(ctx_, scene_, options_.renderer);
        executor_ = std::make_unique<rg::Executor>(ctx_, kFramesInFlight);
        for (uint32_t i = 0; i < kFramesInFlight; ++i) {
            auto slot = std::make_unique<FrameSlot>();
            VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
            VkSemaphore semaphore = VK_NULL_HANDLE;
            gpu::check(vkCreateSemaphore(ctx_.device(), &semaphoreInfo, nullptr, &semaphore), "vkCreateSemaphore");
            slot->acquired = gpu::Unique<VkSemaphore>(ctx_.device(), semaphore, vkDestroySemaphore);
            ctx_.setName(semaphore, VK_OBJECT_TYPE_SEMAPHORE, "viewer.acquired" + std::to_string(i));
            slot->counts = gpu::Buffer(ctx_, {shader::kReflectionCountWords * 4u, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                              gpu::MemoryUsage::Readback, "viewer.counts" + std::to_string(i)});
            slot->occlusion = gpu::Buffer(ctx_, {shader::kOcclusionStatWords * 4u, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                 gpu::MemoryUsage::Readback, "viewer.occlusion" + std::to_string(i)});
            slots_.push_back(std::move(slot));
        }
        imgui_ = std::make_unique<viewer::ImGuiLayer>(ctx_, window_.handle(), swapchain_.copyFormat(),
                                                      swapchain_.minImageCount(),
                                                      std::max(swapchain_.imageCount(), kFramesInFlight));
        createUiTargets();
        const scene::CameraPose start = pathPose(sceneTime_);
        fly_ = viewer::FlyCamera::lookingAlong(start);
        // Half the distance to what the path looks at per second: a helmet
        // and a plaza both cross the view in a few seconds.
        speed_ = std::clamp(0.5f * glm::length(start.target - start.position), 0.1f, 50.0f);
        camera_.lens = scene_.lens;
        lastTime_ = glfwGetTime();
    }

    ~Viewer() { ctx_.waitIdleForTeardown("viewer"); }

    // Until the window closes, or after `frames` frames presented or skipped (0: no limit).
    void run(uint32_t frames) {
        while (!glfwWindowShouldClose(window_.handle()) && (frames == 0 || frameIndex_ < frames)) {
            frame();
        }
        ctx_.waitIdle();
    }

private:
    // ---- the camera path: the scene's, or a slow orbit for a file's single view
    scene::CameraPose pathPose(double seconds) const {
        const auto& keys = scene_.cameraPath.keys;
        if (keys.size() != 1) return scene_.cameraPath.evaluate(float(seconds));
        // glint-render's orbit: a quarter degree per frame at 30 frames a second.
        const float angle = glm::radians(7.5f) * float(seconds);
        const glm::mat4 orbit = glm::rotate(glm::mat4(1.0f), angle, glm::vec3(0.0f, 1.0f, 0.0f));
        scene::CameraPose pose;
        const scene::CameraPathKey& key = keys.front();
        pose.position = key.target + glm::vec3(orbit * glm::vec4(key.position - key.target, 0.0f));
        pose.target = key.target;
        return pose;
    }

    bool composeFirst() const { return swapchain_.copyFormat() != swapchain_.format(); }

    // What the UI draws into: the swapchain's images, or (SRGB-only
    // swapchains) the compose image the graph copies into them.
    void createUiTargets() {
        compose_.reset();
        std::vector<const gpu::Image*> targets;
        if (composeFirst()) {
            const VkExtent2D e = swapchain_.extent();
            compose_ = std::make_unique<gpu::Image>(
                ctx_, gpu::ImageDesc{e.width, e.height, 1, 1, 1, swapchain_.copyFormat(),
                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                         VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                                     "viewer.compose", false});
            // Into the state every frame's graph expects it in (TransferSrc).
            gpu::submitAndWait(ctx_, ctx_.graphicsQueue(), "viewer compose layout", [&](VkCommandBuffer cmd) {
                gpu::imageBarrier(cmd, *compose_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                  VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                  VK_ACCESS_2_TRANSFER_READ_BIT);
            });
            targets.push_back(compose_.get());
        } else {
            for (uint32_t i = 0; i < swapchain_.imageCount(); ++i) targets.push_back(&swapchain_.wrapped(i));
        }
        imgui_->setTargets(targets);
    }

    // Device idle: read every readback still pending.
    void readPendingCounts() {
        for (auto& slot : slots_) readCounts(*slot);
    }
    void readCounts(FrameSlot& slot) {
        if (!slot.countsPending) return;
        slot.countsPending = false;
        std::array<uint32_t, shader::kReflectionCountWords> words{};
        std::memcpy(words.data(), slot.counts.mapped(), sizeof words);
        std::copy_n(words.begin(), shader::kPixelClassCount, counts_.pixelClasses.begin());
        counts_.sslrRays = words[shader::kCountSslrRays];
        counts_.rtRays = words[shader::kCountRtRays];
        counts_.valid = true;
        counts_.occlusion.reset();
        if (slot.occlusionPending) {
            counts_.occlusion.emplace();
            std::memcpy(counts_.occlusion->data(), slot.occlusion.mapped(), sizeof *counts_.occlusion);
        }
    }

    void recreateSwapchain(VkExtent2D size) {
        ctx_.waitIdle();
        readPendingCounts();
        imgui_->setTargets({});  // their framebuffers go before the images' views
        swapchain_.recreate(size);
        sizedFor_ = size;
        createUiTargets();
        imgui_->setMinImageCount(swapchain_.minImageCount());
        // The executor keeps history images at the size it first made them;
        // a new one makes them at the new size (transients follow anyway).
        resetExecutor();
        needsRecreate_ = false;
    }

    // A new executor: new history images, cleared. Needed where the history
    // no longer fits the frame's plan: a new size, or a plan whose passes
    // use the history differently (mode, debug view, counting): the
    // executor leaves each history half in the layout the last plan left
    // it in, and a plan that uses it otherwise expects another.
    void resetExecutor() {
        ctx_.waitIdle();
        readPendingCounts();
        executor_.reset();
        executor_ = std::make_unique<rg::Executor>(ctx_, kFramesInFlight);
        for (auto& slot : slots_) slot->submitted.reset();  // the old executor's frames, all done
        resetHistory_ = true;
    }

    void rebuildRenderer() {
        rendererDirty_ = false;
        if (!viewer::rendererOptionsDiffer(options_.renderer, builtWith_)) return;
        ctx_.waitIdle();
        readPendingCounts();
        renderer_.reset();
        try {
            renderer_ = std::make_unique<passes::ReflectionRenderer>(ctx_, scene_, options_.renderer);
            builtWith_ = options_.renderer;
            message_.clear();
            spdlog::info("renderer rebuilt: backend {}, reflection LODs {}", passes::backendName(renderer_->backend()),
                         options_.renderer.bvh.reflectionLods ? "on" : "off");
        } catch (const std::exception& e) {
            message_ = std::string("renderer: ") + e.what();
            options_.renderer = builtWith_;
            renderer_ = std::make_unique<passes::ReflectionRenderer>(ctx_, scene_, options_.renderer);
        }
        resetHistory_ = true;
    }

    void updateCamera(float dt) {
        const ImGuiIO& io = ImGui::GetIO();
        GLFWwindow* w = window_.handle();
        double x = 0.0, y = 0.0;
        glfwGetCursorPos(w, &x, &y);
        const glm::vec2 cursor{float(x), float(y)};
        const bool button = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
        // A drag belongs to the camera only if it started outside the panel.
        if (button && !dragging_ && !io.WantCaptureMouse) dragging_ = true;
        if (!button) dragging_ = false;
        if (dragging_ && !playPath_) fly_.turn(cursor - lastCursor_, 0.004f);
        lastCursor_ = cursor;

        const auto down = [&](int key) { return glfwGetKey(w, key) == GLFW_PRESS; };
        if (!io.WantCaptureKeyboard && down(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(w, GLFW_TRUE);
        if (playPath_) return;
        glm::vec3 local{0.0f};
        if (!io.WantCaptureKeyboard) {
            local.z += down(GLFW_KEY_W) ? 1.0f : 0.0f;
            local.z -= down(GLFW_KEY_S) ? 1.0f : 0.0f;
            local.x += down(GLFW_KEY_D) ? 1.0f : 0.0f;
            local.x -= down(GLFW_KEY_A) ? 1.0f : 0.0f;
            local.y += down(GLFW_KEY_E) ? 1.0f : 0.0f;
            local.y -= down(GLFW_KEY_Q) ? 1.0f : 0.0f;
            const bool fast = down(GLFW_KEY_LEFT_SHIFT) || down(GLFW_KEY_RIGHT_SHIFT);
            fly_.move(local, speed_ * (fast ? 4.0f : 1.0f) * dt);
        }
    }

    // The compiled plan of the frame on screen (viewer::planView): passes per
    // queue with their batches, waits, barriers and times; a pass's
    // resources on click; the transient heaps and what aliases what.
    void graphPanel() {
        ImGui::SetNextItemOpen(showGraph_, ImGuiCond_Once);
        showGraph_ = ImGui::CollapsingHeader("render graph");
        if (!showGraph_) return;
        const viewer::PlanView& v = planView_;
        const double mib = 1024.0 * 1024.0;
        ImGui::Text("%zu + %zu passes (%u culled); plans reused %llu, compiled %llu", v.lanes[0].size(),
                    v.lanes[1].size(), v.culled, static_cast<unsigned long long>(planCache_.hits()),
                    static_cast<unsigned long long>(planCache_.misses()));
        ImGui::Text("transients %.1f MiB, %.1f MiB with aliasing", double(v.transientBytes) / mib,
                    double(v.aliasedBytes) / mib);
        const ImGuiTableFlags flags = ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY | ImGuiTableFlags_RowBg;
        if (ImGui::BeginTable("queues", 2, flags, ImVec2(0.0f, 260.0f))) {
            ImGui::TableSetupColumn("graphics");
            ImGui::TableSetupColumn("async compute");
            ImGui::TableHeadersRow();
            ImGui::TableNextRow();
            for (int q = 0; q < 2; ++q) {
                ImGui::TableSetColumnIndex(q);
                for (const viewer::PlanViewPass& p : v.lanes[q]) {
                    for (const viewer::PlanViewWait& w : p.waits) {
                        const std::string what = std::string(rg::toString(w.queue));
                        ImGui::TextDisabled("waits for %s batch %u%s", what.c_str(), w.batch,
                                            w.previousFrame ? " (last frame)" : "");
                    }
                    char label[160];
                    std::snprintf(label, sizeof label, "%s%s  b%u, %u barriers%s", p.batchStart ? "" : "  ",
                                  p.name.c_str(), p.batch, p.barriers, p.milliseconds ? "," : "");
                    std::string text = label;
                    if (p.milliseconds) {
                        std::snprintf(label, sizeof label, " %.3f ms", *p.milliseconds);
                        text += label;
                    }
                    if (ImGui::Selectable((text + "##" + p.name).c_str(), selectedPass_ == p.name)) {
                        selectedPass_ = p.name;
                    }
                }
            }
            ImGui::EndTable();
        }
        for (const auto& lane : v.lanes) {
            for (const viewer::PlanViewPass& p : lane) {
                if (p.name != selectedPass_) continue;
                ImGui::Text("%s uses:", p.name.c_str());
                for (const viewer::PlanViewUse& u : p.uses) {
                    ImGui::BulletText("%s: %s%s", u.resource.c_str(), u.access.c_str(), u.writes ? " (writes)" : "");
                }
                if (!p.barrierList.empty()) ImGui::Text("barriers before it:");
                for (const viewer::PlanViewBarrier& b : p.barrierList) {
                    ImGui::BulletText("%s: stages 0x%llx -> 0x%llx, access 0x%llx -> 0x%llx, layout %d -> %d%s",
                                      b.resource.c_str(), static_cast<unsigned long long>(b.srcStages),
                                      static_cast<unsigned long long>(b.dstStages),
                                      static_cast<unsigned long long>(b.srcAccess),
                                      static_cast<unsigned long long>(b.dstAccess), int(b.oldLayout),
                                      int(b.newLayout), b.aliasing ? " (aliasing)" : "");
                }
            }
        }
        for (size_t h = 0; h < v.heaps.size(); ++h) {
            const viewer::PlanViewHeap& heap = v.heaps[h];
            const std::string queue(rg::toString(heap.queue));
            if (!ImGui::TreeNode(reinterpret_cast<void*>(h), "heap %zu (%s), %.1f MiB, %zu transients", h,
                                 queue.c_str(), double(heap.size) / mib, heap.placements.size())) {
                continue;
            }
            // Each placement as a bar over the heap's bytes; its tooltip
            // names the passes it lives through and what shares its bytes.
            ImDrawList* draw = ImGui::GetWindowDrawList();
            const float width = ImGui::GetContentRegionAvail().x;
            for (const viewer::PlanViewPlacement& p : heap.placements) {
                const ImVec2 at = ImGui::GetCursorScreenPos();
                const float x0 = width * float(double(p.offset) / double(std::max<uint64_t>(heap.size, 1)));
                const float x1 = width * float(double(p.offset + p.size) / double(std::max<uint64_t>(heap.size, 1)));
                const float h1 = ImGui::GetTextLineHeight();
                draw->AddRectFilled(ImVec2(at.x + x0, at.y), ImVec2(at.x + std::max(x1, x0 + 2.0f), at.y + h1),
                                    p.aliases.empty() ? IM_COL32(80, 140, 220, 160) : IM_COL32(220, 150, 60, 170));
                ImGui::Text("%s", p.resource.c_str());
                if (ImGui::IsItemHovered()) {
                    std::string aliases;
                    for (const std::string& a : p.aliases) aliases += (aliases.empty() ? "" : ", ") + a;
                    ImGui::SetTooltip("%.2f MiB at %.2f MiB, passes %u-%u\nshares bytes with: %s",
                                      double(p.size) / mib, double(p.offset) / mib, p.firstPass, p.lastPass,
                                      aliases.empty() ? "nothing" : aliases.c_str());
                }
            }
            ImGui::TreePop();
        }
    }

    void panel() {
        ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(380, std::max(200.0f, float(swapchain_.extent().height) - 20.0f)),
                                 ImGuiCond_FirstUseEver);
        ImGui::Begin("Glint");
        const ImGuiIO& io = ImGui::GetIO();
        ImGui::Text("%s, %ux%u, %.1f fps (%.2f ms)", ctx_.caps().deviceName.c_str(), swapchain_.extent().width,
                    swapchain_.extent().height, double(io.Framerate), 1000.0 / double(std::max(io.Framerate, 1e-3f)));
        if (!message_.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.3f, 1.0f), "%s", message_.c_str());

        // -- scene and camera
        ImGui::Text("scene %s, t = %.2f s", scene_.name.c_str(), sceneTime_);
        ImGui::Checkbox("pause", &paused_);
        ImGui::SameLine();
        if (ImGui::Checkbox("play path", &playPath_)) {
            // Leaving the path continues from where it was; entering it is a cut.
            if (!playPath_) fly_ = viewer::FlyCamera::lookingAlong(pathPose(sceneTime_));
            resetHistory_ = true;
        }
        ImGui::SliderFloat("speed", &speed_, 0.1f, 50.0f, "%.1f units/s", ImGuiSliderFlags_Logarithmic);

        // -- mode, backend, debug view
        int mode = int(options_.frame.mode);
        if (ImGui::Combo("mode", &mode, "hybrid\0ssr\0rt\0")) {
            options_.frame.mode = passes::ReflectionMode(mode);
            if (!viewer::debugViewAvailable(options_.frame.debugView, options_.frame.mode)) {
                options_.frame.debugView = "final";
            }
            resetHistory_ = true;
        }
        const std::string backendLabel =
            std::string(passes::backendName(options_.renderer.backend)) + " (" +
            std::string(passes::backendName(renderer_->backend())) + ")";
        if (ImGui::BeginCombo("backend", backendLabel.c_str())) {
            const bool has[3] = {true, ctx_.caps().rayQuery, ctx_.caps().rayTracingPipeline};
            for (int b = 0; b < 3; ++b) {
                ImGui::BeginDisabled(!has[b]);
                const auto backend = passes::RtBackend(b);
                if (ImGui::Selectable(std::string(passes::backendName(backend)).c_str(),
                                      options_.renderer.backend == backend)) {
                    options_.renderer.backend = backend;
                    rendererDirty_ = true;
                }
                ImGui::EndDisabled();
            }
            ImGui::EndCombo();
        }
        const std::string view = options_.frame.debugView.empty() ? "final" : options_.frame.debugView;
        if (ImGui::BeginCombo("debug view", view.c_str())) {
            for (const passes::DebugViewInfo& info : passes::debugViews()) {
                ImGui::BeginDisabled(!info.modes.has(options_.frame.mode));
                if (ImGui::Selectable(std::string(info.name).c_str(), info.name == view)) {
                    options_.frame.debugView = info.name;
                }
                if (ImGui::IsItemHovered()) ImGui::SetTooltip("%.*s", int(info.shows.size()), info.shows.data());
                ImGui::EndDisabled();
            }
            ImGui::EndCombo();
        }

        // -- the tunable parameters
        if (ImGui::CollapsingHeader("parameters", ImGuiTreeNodeFlags_DefaultOpen)) {
            for (const viewer::ParameterSlider& s : sliders_) {
                const std::string name(s.parameter.name);
                float value = float(app::getParameter(options_, s.parameter.name));
                bool changed = false;
                if (s.integer) {
                    int v = int(value);
                    changed = ImGui::SliderInt(name.c_str(), &v, int(s.min), int(s.max));
                    value = float(v);
                } else {
                    changed = ImGui::SliderFloat(name.c_str(), &value, s.min, s.max, "%.3f");
                }
                if (ImGui::IsItemHovered()) {
                    ImGui::SetTooltip("%.*s", int(s.parameter.field.size()), s.parameter.field.data());
                }
                if (changed) viewer::applySlider(options_, s, value);
                // The renderer's own options take a new renderer: only on release.
                if (s.rendererOption && ImGui::IsItemDeactivatedAfterEdit()) rendererDirty_ = true;
            }
            if (ImGui::Button("defaults")) {
                const passes::RtBackend backend = options_.renderer.backend;
                const std::string debugView = options_.frame.debugView;
                const passes::ReflectionMode frameMode = options_.frame.mode;
                options_ = app::ReflectionRunOptions{};
                options_.renderer.framesInFlight = kFramesInFlight;
                options_.renderer.backend = backend;
                options_.frame.debugView = debugView;
                options_.frame.mode = frameMode;
                rendererDirty_ = true;
            }
        }

        // -- GPU times of the newest completed frame
        if (ImGui::CollapsingHeader("GPU time per pass", ImGuiTreeNodeFlags_DefaultOpen)) {
            double total = 0.0, reflections = 0.0;
            if (ImGui::BeginTable("passes", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
                for (const rg::PassTiming& t : timings_) {
                    if (!t.milliseconds) continue;
                    total += *t.milliseconds;
                    if (passes::isReflectionPass(t.name)) reflections += *t.milliseconds;
                    ImGui::TableNextRow();
                    ImGui::TableNextColumn();
                    ImGui::Text("%s%s", t.name.c_str(), t.queue == rg::Queue::AsyncCompute ? " (async)" : "");
                    ImGui::TableNextColumn();
                    ImGui::Text("%.3f ms", *t.milliseconds);
                }
                ImGui::EndTable();
            }
            ImGui::Text("reflections %.3f ms, all passes %.3f ms", reflections, total);
        }

        // -- rays and pixel classes
        if (ImGui::CollapsingHeader("rays", ImGuiTreeNodeFlags_DefaultOpen)) {
            ImGui::Checkbox("count rays", &countRays_);
            if (options_.frame.mode == passes::ReflectionMode::Hybrid) {
                // FeedbackSettings::hostGate: the last frame's decision.
                if (sslrProbeSpacing_ == 0) {
                    ImGui::TextUnformatted("SSLR tried on hybrid pixels");
                } else {
                    ImGui::Text("SSLR does not pay: %s; a probe about every %u frames",
                                screenSpaceIdle_  ? "frame rendered as rt"
                                : sslrCountsOnly_ ? "probe frame (SSLR counted, rendered as rt)"
                                                  : "probe frame",
                                sslrProbeSpacing_);
                }
            }
            if (countRays_ && counts_.valid) {
                const double pixels = double(swapchain_.extent().width) * swapchain_.extent().height;
                ImGui::Text("SSLR rays %u, RT rays %u", counts_.sslrRays, counts_.rtRays);
                const char* names[shader::kPixelClassCount] = {"sky", "env", "sslr", "hybrid", "rt"};
                for (uint32_t c = 0; c < shader::kPixelClassCount; ++c) {
                    ImGui::Text("  %-7s %5.1f %%", names[c], 100.0 * counts_.pixelClasses[c] / pixels);
                }
                if (const auto& o = counts_.occlusion) {
                    ImGui::Text("G-buffer: %u instances drawn early, %u late, %u occluded; %u triangles",
                                (*o)[shader::kOcclusionStatEarly], (*o)[shader::kOcclusionStatLate],
                                (*o)[shader::kOcclusionStatOccluded], (*o)[shader::kOcclusionStatTriangles]);
                }
            }
        }

        graphPanel();

        // -- BVH
        if (ImGui::CollapsingHeader("BVH", ImGuiTreeNodeFlags_DefaultOpen)) {
            if (options_.frame.mode == passes::ReflectionMode::Ssr) {
                ImGui::TextUnformatted("none in ssr mode");
            } else {
                const scene::BvhStats& p = renderer_->bvhPlanStats();
                const passes::BvhGpuStats& g = renderer_->bvhGpuStats();
                ImGui::Text("TLAS instances %u (in range %u, culled %u)", p.tlasInstances, p.instancesInRange,
                            p.instancesCulled);
                ImGui::Text("BLAS this frame: built %u, rebuilt %u (skinned %u), static reused %u", p.built, p.rebuilt,
                            p.rebuiltSkinned, p.staticReused);
                ImGui::Text("deferred by budget %u (skinned %u)", p.deferredBudget, p.deferredSkinnedBudget);
                ImGui::Text("resident BLAS %u: %.1f MiB, TLAS %.1f MiB, pool %.1f MiB", g.residentBlases,
                            double(g.blasBytes) / 1048576.0, double(g.tlasBytes) / 1048576.0,
                            double(g.poolBytes) / 1048576.0);
            }
            const passes::GBufferStats& gb = renderer_->gbufferStats();
            ImGui::Text("G-buffer: %u draws in %u runs, %llu triangles (%llu facing away, skipped)", gb.draws,
                        gb.runs, static_cast<unsigned long long>(gb.triangles),
                        static_cast<unsigned long long>(gb.facetTrianglesSkipped));
        }
        ImGui::End();
    }

    void frame() {
        glfwPollEvents();
        const VkExtent2D size = window_.framebufferSize();
        if (size.width == 0 || size.height == 0) {
            glfwWaitEvents();  // minimised: nothing to draw into
            return;
        }
        // Compared with the size asked for, not the swapchain's extent: a
        // surface may settle on another extent, which must not mean a new
        // swapchain every frame.
        if (needsRecreate_ || size.width != sizedFor_.width || size.height != sizedFor_.height) {
            recreateSwapchain(size);
        }
        const double now = glfwGetTime();
        const float dt = float(std::min(now - lastTime_, 0.1));  // a stall is not a teleport
        lastTime_ = now;

        // The slot's previous frame (kFramesInFlight ago) is complete: its
        // acquire wait is done (the semaphore is free) and its counts written.
        FrameSlot& slot = *slots_[frameIndex_ % slots_.size()];
        if (slot.submitted) executor_->wait(*slot.submitted);
        slot.submitted.reset();
        readCounts(slot);
        if (const auto t = executor_->timings(); !t.empty()) timings_ = t;

        imgui_->begin();
        panel();
        imgui_->end();
        if (rendererDirty_) rebuildRenderer();

        // ---- camera and scene
        updateCamera(dt);
        if (!paused_) sceneTime_ += dt;
        const scene::CameraPose pose = playPath_ ? pathPose(sceneTime_) : fly_.pose();
        const VkExtent2D extent = swapchain_.extent();
        camera_.resolution = {extent.width, extent.height};
        if (frameIndex_ == 0 || resetHistory_) {
            camera_.reset(pose, frameIndex_);
        } else {
            camera_.advance(pose, frameIndex_);
        }
        scene::advanceScene(scene_, sceneTime_, &camera_);

        // ---- the image to draw into
        const std::optional<uint32_t> image = swapchain_.acquire(slot.acquired.get());
        if (!image) {
            // Out of date: nothing was acquired or submitted; a new
            // swapchain next frame.
            needsRecreate_ = true;
            ++frameIndex_;
            return;
        }

        // ---- the graph
        const std::string planShape = std::string(passes::modeName(options_.frame.mode)) + "/" +
                                      options_.frame.debugView + (countRays_ ? "/counted" : "");
        if (planShape != planShape_) {
            if (!planShape_.empty()) resetExecutor();
            planShape_ = planShape;
        }
        passes::ReflectionFrameSettings settings = options_.frame;
        settings.resetHistory = resetHistory_;
        settings.countRays = countRays_;
        resetHistory_ = false;
        // The panel's graph_carry_skipped_barriers.
        executor_->setCarrySkippedBarriers(options_.carrySkippedBarriers);
        rg::Graph graph(executor_->queueCaps());
        const passes::ReflectionFrame reflections = renderer_->addFrame(graph, camera_, settings);
        screenSpaceIdle_ = reflections.screenSpaceIdle;
        sslrProbeSpacing_ = reflections.sslrProbeSpacing;
        sslrCountsOnly_ = reflections.sslrCountsOnly;
        rg::FrameResources resources;
        renderer_->bind(resources, reflections);

        viewer::ViewerPassesInputs viewerInputs;
        viewerInputs.output = reflections.output.color;
        viewerInputs.extent = extent;
        viewerInputs.swapchainFormat = swapchain_.format();
        viewerInputs.composeFormat = swapchain_.copyFormat();
        viewerInputs.drawUi = [layer = imgui_.get()](rg::PassContext& pc, rg::Texture uiTarget) {
            if (pc.layout(uiTarget) != viewer::kUiTargetLayout) {
                throw gpu::GpuError("viewer.imgui: the graph gives the target a layout the UI render pass was "
                                    "not made for");
            }
            layer->record(pc.cmd(), pc.image(uiTarget));
        };
        const viewer::ViewerPasses viewerPasses = viewer::addViewerPasses(graph, viewerInputs);
        resources.bind(viewerPasses.swapchain, swapchain_.wrapped(*image));
        resources.waitSemaphore(viewerPasses.swapchain, slot.acquired.get());
        resources.signalSemaphore(viewerPasses.swapchain, swapchain_.presentReady(*image));
        if (viewerPasses.compose.valid()) resources.bind(viewerPasses.compose, *compose_);
        if (settings.countRays) {
            resources.bind(viewer::addCountsReadback(graph, reflections.counts, slot.counts.size()), slot.counts);
        }
        const rg::Buffer occlusion = reflections.gbuffer.occlusionStats;
        slot.occlusionPending = settings.countRays && occlusion.valid();
        if (slot.occlusionPending) {
            resources.bind(
                viewer::addCountsReadback(graph, occlusion, slot.occlusion.size(), "viewer.occlusion_counts"),
                slot.occlusion);
        }
        // A frame of an earlier frame's shape reuses that frame's plan.
        const rg::Plan& plan = planCache_.compile(graph, executor_->compileOptions());
        if (showGraph_) planView_ = viewer::planView(plan, timings_);
        if (ctx_.validationEnabled()) {
            // As glint-render: the plan's own checker covers what the layer cannot see.
            const rg::VerifyReport report = rg::verify(plan);
            if (!report.ok()) throw std::runtime_error("render graph plan: " + report.text());
        }
        slot.submitted = executor_->run(plan, resources);
        slot.countsPending = settings.countRays;

        // ---- present: waits on the semaphore the graph's last batch on the image signalled
        if (!swapchain_.present(*image)) needsRecreate_ = true;
        ++frameIndex_;
    }

    gpu::Context& ctx_;
    Window& window_;
    scene::Scene& scene_;
    const std::vector<viewer::ParameterSlider> sliders_;
    bool screenSpaceIdle_ = false;  // the last hybrid frame was rendered as rt (FeedbackSettings::hostGate)
    uint32_t sslrProbeSpacing_ = 0; // ReflectionFrame::sslrProbeSpacing of the last frame
    bool sslrCountsOnly_ = false;   // ReflectionFrame::sslrCountsOnly of the last frame (a probe rendered as rt)
    app::ReflectionRunOptions options_;            // what the panel edits
    passes::ReflectionRendererOptions builtWith_;  // what renderer_ was built with
    viewer::Swapchain swapchain_;
    VkExtent2D sizedFor_;  // the window size the swapchain was made for
    std::unique_ptr<gpu::Image> compose_;  // SRGB-only swapchains: the UNORM image the frame is composed in
    std::vector<std::unique_ptr<FrameSlot>> slots_;
    std::unique_ptr<passes::ReflectionRenderer> renderer_;
    std::unique_ptr<rg::Executor> executor_;
    rg::PlanCache planCache_;
    // The render graph panel: its rows (built each frame while it is open)
    // and the pass whose resources it lists.
    bool showGraph_ = false;
    viewer::PlanView planView_;
    std::string selectedPass_;
    std::unique_ptr<viewer::ImGuiLayer> imgui_;

    scene::Camera camera_;
    viewer::FlyCamera fly_;
    float speed_ = 5.0f;
    bool dragging_ = false;
    glm::vec2 lastCursor_{0.0f};
    double sceneTime_ = 0.0;
    double lastTime_ = 0.0;
    bool paused_ = false;
    bool playPath_ = false;

    uint64_t frameIndex_ = 0;
    bool resetHistory_ = true;
    bool needsRecreate_ = false;
    bool rendererDirty_ = false;
    bool countRays_ = true;
    std::string planShape_;  // mode, debug view and counting of the last frame
    std::vector<rg::PassTiming> timings_;
    RayCounts counts_;
    std::string message_;
};

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-viewer", [&] {
        const app::Args args(argc, argv, viewer::kUsage, viewer::viewerFlags(), viewer::viewerSwitches());
        const viewer::ViewerOptions options = viewer::viewerOptions(args);

        // The window first: without a display this fails at once, before
        // any Vulkan or scene work.
        Window window("glint-viewer", options.width, options.height);
        gpu::ContextOptions contextOptions = args.contextOptions();
        contextOptions.instanceExtensions = window.instanceExtensions();
        contextOptions.swapchain = true;
        gpu::Context ctx(contextOptions);
        const Surface surface(ctx, window);

        scene::Scene scene = scene::loadScene(options.scene, args.gltfOptions());
        // As glint-render: 3 s along the plaza's path looks down the plaza.
        const float startSeconds = options.scene == "plaza" ? 3.0f : 0.0f;
        spdlog::info("{}: {} on {}", scene.name, options.scene, ctx.caps().deviceName);
        {
            Viewer viewer(ctx, window, surface.handle(), scene, options, startSeconds);
            viewer.run(options.frames);
        }
        return app::validationClean(ctx) ? 0 : 2;
    });
}
