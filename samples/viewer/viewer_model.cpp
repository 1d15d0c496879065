#include "viewer_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace glint::viewer {

namespace {

bool startsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

} // namespace

glm::uvec2 parseWindowSize(std::string_view text) {
    const auto number = [&](std::string_view part) {
        uint32_t v = 0;
        bool ok = !part.empty() && part.size() <= 5;
        for (const char c : part) {
            ok = ok && c >= '0' && c <= '9';
            if (ok) v = v * 10 + uint32_t(c - '0');
        }
        if (!ok || v < 64 || v > 8192) {
            throw std::runtime_error("--size " + std::string(text) + ": expected WxH with 64..8192 pixels each");
        }
        return v;
    };
    const size_t x = text.find('x');
    if (x == std::string_view::npos) {
        const uint32_t n = number(text);
        return {n, n};
    }
    return {number(text.substr(0, x)), number(text.substr(x + 1))};
}

std::vector<app::Flag> viewerFlags() {
    return {{"scene", "plaza (default), hard-cases, city[:OPTIONS], mirror-motion[:lamp=rigid|skinned|morphed], FILE.gltf or FILE.glb"},
            {"size", "WxH: the window's size"},
            {"frames", "close after N frames (smoke tests on a virtual display)"},
            {"mode", "hybrid, ssr or rt: what the panel starts with"},
            {"backend", "auto, query or pipeline: the ray backend the panel starts with"},
            {"debug-view", "the debug view the panel starts with (glint-render --list-debug-views)"}};
}

std::vector<app::Flag> viewerSwitches() {
    return {{"graph-panel", "start with the render graph panel open (the compiled plan: passes per queue, waits, "
                            "barriers, times, transient memory)"}};
}

ViewerOptions viewerOptions(const app::Args& args) {
    ViewerOptions o;
    o.scene = args.get("scene", o.scene);
    if (args.has("size")) {
        const glm::uvec2 size = parseWindowSize(args.get("size", ""));
        o.width = size.x;
        o.height = size.y;
    }
    o.frames = args.getUint("frames", 0);
    o.graphPanel = args.has("graph-panel");
    try {
        o.mode = passes::parseMode(args.get("mode", "hybrid"));
        o.backend = passes::parseBackend(args.get("backend", "auto"));
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("--mode/--backend: ") + e.what());
    }
    o.debugView = args.get("debug-view", o.debugView);
    if (passes::findDebugView(o.debugView) == nullptr) {
        throw std::runtime_error("--debug-view " + o.debugView + ": unknown (glint-render --list-debug-views)");
    }
    if (!debugViewAvailable(o.debugView, o.mode)) {
        throw std::runtime_error("--debug-view " + o.debugView + ": not produced in mode " +
                                 std::string(passes::modeName(o.mode)));
    }
    return o;
}

bool debugViewAvailable(std::string_view view, passes::ReflectionMode mode) {
    const passes::DebugViewInfo* info = passes::findDebugView(view);
    return info != nullptr && info->modes.has(mode);
}

std::vector<ParameterSlider> parameterSliders() {
    std::vector<ParameterSlider> sliders;
    for (const app::Parameter& p : app::parameters()) {
        ParameterSlider s;
        s.parameter = p;
        // The range lives with the parameter (app::Parameter).
        s.min = p.min;
        s.max = p.max;
        s.integer = p.integer;
        // The renderer's own options (ReflectionRendererOptions::bvh and
        // ::bvhUpdate) are read once, when it is built.
        s.rendererOption = startsWith(p.field, "BvhSettings::") || startsWith(p.field, "BvhUpdateOptions::");
        sliders.push_back(s);
    }
    return sliders;
}

void applySlider(app::ReflectionRunOptions& options, const ParameterSlider& slider, float value) {
    float v = std::clamp(std::isfinite(value) ? value : slider.min, slider.min, slider.max);
    char text[32];
    if (slider.integer) {
        std::snprintf(text, sizeof text, "%u", unsigned(std::lround(v)));
    } else {
        std::snprintf(text, sizeof text, "%.9g", double(v));
    }
    app::setParameter(options, slider.parameter.name, text);
}

bool rendererOptionsDiffer(const passes::ReflectionRendererOptions& a, const passes::ReflectionRendererOptions& b) {
    return a.backend != b.backend || a.bvh.reflectionLods != b.bvh.reflectionLods;
}

// ---- fly camera

FlyCamera FlyCamera::lookingAlong(const scene::CameraPose& pose) {
    FlyCamera c;
    c.position = pose.position;
    const glm::vec3 d = pose.target - pose.position;
    const float length = glm::length(d);
    if (length > 0.0f && std::isfinite(length)) {
        const glm::vec3 n = d / length;
        c.yaw = std::atan2(n.x, -n.z);
        c.pitch = std::clamp(std::asin(std::clamp(n.y, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
    }
    return c;
}

glm::vec3 FlyCamera::forward() const {
    return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
}

glm::vec3 FlyCamera::right() const { return {std::cos(yaw), 0.0f, std::sin(yaw)}; }

scene::CameraPose FlyCamera::pose() const {
    scene::CameraPose p;
    p.position = position;
    p.target = position + forward();
    return p;
}

void FlyCamera::turn(glm::vec2 pixels, float radiansPerPixel) {
    yaw = std::remainder(yaw + pixels.x * radiansPerPixel, 2.0f * 3.14159265f);
    pitch = std::clamp(pitch - pixels.y * radiansPerPixel, -kMaxPitch, kMaxPitch);
}

void FlyCamera::move(glm::vec3 local, float distance) {
    const float length = glm::length(local);
    if (!(length > 0.0f)) return;
    const glm::vec3 l = local / length;
    // Forward follows the view (pitch included), as a fly camera does; up
    // is the world's, so Q/E change height whatever the view.
    position += (right() * l.x + glm::vec3(0.0f, 1.0f, 0.0f) * l.y + forward() * l.z) * distance;
}

} // namespace glint::viewer
