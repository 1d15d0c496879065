#pragma once
// What the viewer decides without a window: its command line, the panel's
// model (which debug views a mode produces, slider ranges for the tunable
// parameters, which of them need a new renderer) and the fly camera. Kept
// apart from the GLFW/Vulkan code so it can be tested on a machine with no
// display (tests: viewer_model_test.cpp).

#include "common/app.h"
#include "common/reflection_run.h"
#include "glint/passes/reflection_frame.h"
#include "glint/scene/camera.h"

#include <glm/glm.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace glint::viewer {

inline constexpr const char* kUsage =
    "glint-viewer: the interactive viewer (GLFW + Dear ImGui).\n"
    "  WASD move, Q/E down/up, Shift faster, left-drag to look, Esc quits;\n"
    "  the panel sets mode, backend, debug view and parameters";

struct ViewerOptions {
    std::string scene = "plaza";
    uint32_t width = 1280;  // the window's initial size; frames follow the window
    uint32_t height = 720;
    uint32_t frames = 0;  // 0: until the window is closed
    passes::ReflectionMode mode = passes::ReflectionMode::Hybrid;
    passes::RtBackend backend = passes::RtBackend::Auto;
    std::string debugView = "final";
    bool graphPanel = false;  // the render graph panel starts open
};

// "WxH" (or "N" for a square), 64..8192 each: smaller windows leave no room
// for the panel.
glm::uvec2 parseWindowSize(std::string_view text);
ViewerOptions viewerOptions(const app::Args& args);
// Throws std::runtime_error naming the flag for a bad value, and for a
// debug view the mode does not produce.
// The flags app::Args must accept for the viewer.
std::vector<app::Flag> viewerFlags();
// The switches (flags without a value).
std::vector<app::Flag> viewerSwitches();

// Whether ReflectionRenderer::addFrame produces debug view `view` in
// `mode`: the SSLR views need screen space (not rt), the ray-traced ones a
// trace (not ssr), the tile views the feedback pass (hybrid only). The
// panel greys out the others so a frame never asks for what it lacks.
bool debugViewAvailable(std::string_view view, passes::ReflectionMode mode);

// One slider of the panel over a tunable parameter (app::parameters()).
struct ParameterSlider {
    app::Parameter parameter;
    float min = 0.0f;
    float max = 1.0f;
    bool integer = false;
    // Lives in ReflectionRendererOptions (read when the renderer is built):
    // applied on release, by building a new renderer.
    bool rendererOption = false;
};

// Every parameter of app::parameters(), in that order, with its range.
std::vector<ParameterSlider> parameterSliders();
// Sets `value`, clamped to the slider's range (and rounded for integers),
// through app::setParameter.
void applySlider(app::ReflectionRunOptions& options, const ParameterSlider& slider, float value);
// The renderer options the viewer can change (backend, BVH radius) differ.
bool rendererOptionsDiffer(const passes::ReflectionRendererOptions& a, const passes::ReflectionRendererOptions& b);

// A free-flying camera: position, yaw about +Y (0 looks down -Z) and pitch.
struct FlyCamera {
    glm::vec3 position{0.0f};
    float yaw = 0.0f;
    float pitch = 0.0f;

    // Pitch stops short of straight up or down, where the view's up vector
    // and direction would coincide.
    static constexpr float kMaxPitch = 1.55f;

    static FlyCamera lookingAlong(const scene::CameraPose& pose);
    glm::vec3 forward() const;
    glm::vec3 right() const;
    scene::CameraPose pose() const;
    // Mouse motion in pixels: right turns right, down looks down.
    void turn(glm::vec2 pixels, float radiansPerPixel);
    // `local`: x right, y world up, z forward; moved `distance` along it.
    void move(glm::vec3 local, float distance);
};

} // namespace glint::viewer
