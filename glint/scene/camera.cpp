#include "glint/scene/camera.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace glint::scene {

glm::mat4 viewMatrix(const CameraPose& pose) {
    glm::vec3 forward = pose.target - pose.position;
    if (glm::dot(forward, forward) < 1e-20f) {
        forward = {0.0f, 0.0f, -1.0f};
    }
    forward = glm::normalize(forward);
    glm::vec3 up = pose.up;
    // lookAt is undefined when looking along `up`; any other up will do.
    if (glm::length(glm::cross(forward, up)) < 1e-6f) {
        up = std::abs(forward.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    }
    return glm::lookAtRH(pose.position, pose.position + forward, up);
}

glm::mat4 perspectiveReversedZ(float verticalFovRadians, float aspect, float nearPlane, float farPlane) {
    const float f = 1.0f / std::tan(verticalFovRadians * 0.5f);
    glm::mat4 p(0.0f);
    p[0][0] = f / aspect;
    p[1][1] = -f;     // Vulkan clip space: +Y down
    p[2][3] = -1.0f;  // w_clip = distance in front of the camera
    // depth = A + B / distance with depth(near) = 1 and depth(far) = 0:
    // B = near * far / (far - near), A = -near / (far - near); as far goes
    // to infinity, A -> 0 and B -> near.
    if (std::isinf(farPlane)) {
        p[2][2] = 0.0f;
        p[3][2] = nearPlane;
    } else {
        p[2][2] = nearPlane / (farPlane - nearPlane);
        p[3][2] = nearPlane * farPlane / (farPlane - nearPlane);
    }
    return p;
}

float halton(uint32_t index, uint32_t base) {
    float result = 0.0f;
    float f = 1.0f;
    const float invBase = 1.0f / float(base);
    while (index > 0) {
        f *= invBase;
        result += f * float(index % base);
        index /= base;
    }
    return result;
}

glm::vec2 jitterOffset(uint64_t frameIndex, uint32_t phaseCount) {
    const uint32_t index = uint32_t(frameIndex % std::max(phaseCount, 1u)) + 1;
    return {halton(index, 2) - 0.5f, halton(index, 3) - 0.5f};
}

glm::mat4 jitterProjection(const glm::mat4& projection, glm::vec2 jitterPixels, glm::uvec2 resolution) {
    // A translation in NDC, applied after projection so it scales with w and
    // shifts every depth by the same fraction of a pixel.
    const glm::vec3 ndcShift{2.0f * jitterPixels.x / float(resolution.x), 2.0f * jitterPixels.y / float(resolution.y),
                             0.0f};
    return glm::translate(glm::mat4(1.0f), ndcShift) * projection;
}

void Camera::computeCurrent(const CameraPose& pose, uint64_t frame) {
    frameIndex = frame;
    position = pose.position;
    view = viewMatrix(pose);
    projection = perspectiveReversedZ(lens.verticalFovRadians, aspect(), lens.nearPlane, lens.farPlane);
    jitterPixels = jitter ? jitterOffset(frame, jitterPhases) : glm::vec2(0.0f);
    jitteredProjection = jitterProjection(projection, jitterPixels, resolution);
}

void Camera::advance(const CameraPose& pose, uint64_t frame) {
    previousPosition = position;
    previousView = view;
    previousProjection = projection;
    previousJitteredProjection = jitteredProjection;
    previousJitterPixels = jitterPixels;
    computeCurrent(pose, frame);
}

void Camera::reset(const CameraPose& pose, uint64_t frame) {
    computeCurrent(pose, frame);
    previousPosition = position;
    previousView = view;
    previousProjection = projection;
    previousJitteredProjection = jitteredProjection;
    previousJitterPixels = jitterPixels;
}

float CameraPath::duration() const {
    return keys.empty() ? 0.0f : keys.back().time - keys.front().time;
}

namespace {
glm::vec3 catmullRom(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2, const glm::vec3& p3, float s) {
    const float s2 = s * s;
    const float s3 = s2 * s;
    return 0.5f * ((2.0f * p1) + (p2 - p0) * s + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * s2 +
                   (3.0f * p1 - p0 - 3.0f * p2 + p3) * s3);
}
} // namespace

CameraPose CameraPath::evaluate(float seconds) const {
    if (keys.empty()) {
        return {};
    }
    if (keys.size() == 1 || !(seconds > keys.front().time)) {
        return {keys.front().position, keys.front().target, {0, 1, 0}};
    }
    if (seconds >= keys.back().time) {
        return {keys.back().position, keys.back().target, {0, 1, 0}};
    }
    const auto next =
        std::upper_bound(keys.begin(), keys.end(), seconds, [](float t, const CameraPathKey& k) { return t < k.time; });
    const size_t i1 = size_t(next - keys.begin());
    const size_t i0 = i1 - 1;
    const size_t im = i0 == 0 ? 0 : i0 - 1;
    const size_t i2 = std::min(i1 + 1, keys.size() - 1);
    const float span = keys[i1].time - keys[i0].time;
    const float s = span > 0.0f ? (seconds - keys[i0].time) / span : 0.0f;
    CameraPose pose;
    pose.position = catmullRom(keys[im].position, keys[i0].position, keys[i1].position, keys[i2].position, s);
    pose.target = catmullRom(keys[im].target, keys[i0].target, keys[i1].target, keys[i2].target, s);
    return pose;
}

CameraPose CameraPath::atFrame(uint32_t frame, uint32_t frameCount) const {
    if (keys.empty()) {
        return {};
    }
    const float s = frameCount > 1 ? float(std::min(frame, frameCount - 1)) / float(frameCount - 1) : 0.0f;
    return evaluate(keys.front().time + s * duration());
}

} // namespace glint::scene
