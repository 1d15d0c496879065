#pragma once
// The camera: this and last frame's view and projection (motion vectors and
// reprojection need both), reversed-Z projection, sub-pixel jitter for
// temporal accumulation, and camera paths for scripted runs.
//
// Conventions: view space is right-handed, looking down -Z with +Y up.
// Projections map it to Vulkan clip space: +Y down, depth in [0, 1] and
// reversed (the near plane at depth 1, the far plane - or infinity - at 0),
// which spreads float precision evenly over distance.

#include <glm/glm.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace glint::scene {

inline constexpr float kInfiniteFar = std::numeric_limits<float>::infinity();

// FidelityFX FSR 2 uses 8 * (display / render width)^2 Halton phases; at
// native resolution that is 8.
inline constexpr uint32_t kDefaultJitterPhases = 8;

struct CameraPose {
    glm::vec3 position{0.0f};
    glm::vec3 target{0.0f, 0.0f, -1.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
};

struct Lens {
    float verticalFovRadians = 1.0471976f;  // 60 degrees
    float nearPlane = 0.1f;
    float farPlane = kInfiniteFar;  // finite or kInfiniteFar
};

// World -> view.
glm::mat4 viewMatrix(const CameraPose& pose);

// Reversed-Z perspective into Vulkan clip space (see the file comment).
// `farPlane` may be kInfiniteFar; then depth = near / distance.
glm::mat4 perspectiveReversedZ(float verticalFovRadians, float aspect, float nearPlane, float farPlane);

// Element `index` (>= 1) of the radical-inverse (Halton) sequence in `base`.
float halton(uint32_t index, uint32_t base);

// Sub-pixel jitter of frame `frameIndex`, in pixels, each component in
// [-0.5, 0.5): Halton(2, 3) over `phaseCount` frames, starting at index 1 as
// FidelityFX FSR 2 (ffxFsr2GetJitterOffset) does, since index 0 is (0, 0).
// +x is right and +y down, as in Vulkan framebuffer coordinates.
glm::vec2 jitterOffset(uint64_t frameIndex, uint32_t phaseCount = kDefaultJitterPhases);

// `projection` shifted by `jitterPixels` on an image of `resolution`.
glm::mat4 jitterProjection(const glm::mat4& projection, glm::vec2 jitterPixels, glm::uvec2 resolution);

struct Camera {
    glm::uvec2 resolution{1920, 1080};
    Lens lens;
    bool jitter = true;
    uint32_t jitterPhases = kDefaultJitterPhases;

    uint64_t frameIndex = 0;

    // This frame. `projection` is unjittered (motion vectors use it);
    // `jitteredProjection` is what rasterisation uses.
    glm::vec3 position{0.0f};
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    glm::mat4 jitteredProjection{1.0f};
    glm::vec2 jitterPixels{0.0f};

    // Last frame.
    glm::vec3 previousPosition{0.0f};
    glm::mat4 previousView{1.0f};
    glm::mat4 previousProjection{1.0f};
    glm::mat4 previousJitteredProjection{1.0f};
    glm::vec2 previousJitterPixels{0.0f};

    float aspect() const { return float(resolution.x) / float(resolution.y); }
    glm::mat4 viewProjection() const { return projection * view; }
    glm::mat4 previousViewProjection() const { return previousProjection * previousView; }

    // Moves this frame's matrices to last frame's and computes new ones.
    void advance(const CameraPose& pose, uint64_t frame);
    // Sets this and last frame to the same pose: the first frame, or a cut.
    void reset(const CameraPose& pose, uint64_t frame);

private:
    void computeCurrent(const CameraPose& pose, uint64_t frame);
};

struct CameraPathKey {
    float time = 0.0f;  // seconds
    glm::vec3 position{0.0f};
    glm::vec3 target{0.0f, 0.0f, -1.0f};
};

// Keys in increasing time, interpolated with uniform Catmull-Rom splines so
// the motion has no kinks at keys; times outside the keys clamp.
struct CameraPath {
    std::vector<CameraPathKey> keys;

    float duration() const;
    CameraPose evaluate(float seconds) const;
    // Frame `frame` of `frameCount` frames spread evenly over the path.
    CameraPose atFrame(uint32_t frame, uint32_t frameCount) const;
};

} // namespace glint::scene
