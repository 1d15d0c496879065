#include "glint/scene/scene_builder.h"

#include "glint/scene/mesh_tools.h"

#include "glint/packing.h"

#include <algorithm>
#include <cmath>

namespace glint::scene {

// Deterministic hash -> [0, 1) (a 32-bit integer finaliser, as in
// MurmurHash3's fmix32), so generated textures are identical on every run.
float hash01(int32_t x, int32_t y, uint32_t seed) {
    uint32_t h = uint32_t(x) * 0x8da6b343u ^ uint32_t(y) * 0xd8163841u ^ seed * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return float(h >> 8) / float(1u << 24);
}

// Value noise on a lattice of `period` cells that wraps, so textures tile.
float valueNoise(float x, float y, int32_t period, uint32_t seed) {
    const float fx = std::floor(x), fy = std::floor(y);
    const float tx = x - fx, ty = y - fy;
    const float sx = tx * tx * (3.0f - 2.0f * tx);
    const float sy = ty * ty * (3.0f - 2.0f * ty);
    const auto at = [&](int32_t i, int32_t j) {
        return hash01(((i % period) + period) % period, ((j % period) + period) % period, seed);
    };
    const int32_t i = int32_t(fx), j = int32_t(fy);
    const float top = glm::mix(at(i, j), at(i + 1, j), sx);
    const float bottom = glm::mix(at(i, j + 1), at(i + 1, j + 1), sx);
    return glm::mix(top, bottom, sy);
}

float fbm(float u, float v, uint32_t seed) {
    float sum = 0.0f, amplitude = 0.5f, norm = 0.0f;
    int32_t period = 4;
    for (int octave = 0; octave < 4; ++octave) {
        sum += amplitude * valueNoise(u * float(period), v * float(period), period, seed + uint32_t(octave));
        norm += amplitude;
        amplitude *= 0.5f;
        period *= 2;
    }
    return sum / norm;
}

uint8_t toByte(float v) {
    return uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}

uint8_t toSrgbByte(float linear) {
    return toByte(shader::linearToSrgb(linear));
}

Material makeMaterial(const std::string& name, const glm::vec3& baseColor, float metallic, float roughness) {
    Material m;
    m.name = name;
    m.baseColorFactor = glm::vec4(baseColor, 1.0f);
    m.metallicFactor = metallic;
    m.roughnessFactor = roughness;
    return m;
}

Material makeEmissive(const std::string& name, const glm::vec3& color, float strength) {
    Material m = makeMaterial(name, glm::vec3(0.05f), 0.0f, 0.4f);
    m.emissiveFactor = color;
    m.emissiveStrength = strength;
    return m;
}

glm::quat axisAngle(const glm::vec3& axis, float radians) {
    return glm::angleAxis(radians, glm::normalize(axis));
}

Geometry transformed(Geometry g, const glm::mat4& m) {
    transformGeometry(g, m);
    return g;
}

glm::mat4 translation(const glm::vec3& t) {
    return glm::translate(glm::mat4(1.0f), t);
}

} // namespace glint::scene
