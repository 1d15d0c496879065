#include "glint/passes/lighting.h"

#include <glm/gtc/constants.hpp>

#include <cmath>

namespace glint::passes {

// The mean radiance of the upper cap (y > 0.5), the band around the horizon
// (0 <= y <= 0.5) and the lower hemisphere: the procedural path only needs
// the low-frequency shape.
SkyColors environmentSkyColors(const scene::Environment& env) {
    if (env.kind != scene::EnvironmentKind::EquirectangularImage || !env.image.valid()) {
        return {env.sky.zenithColor, env.sky.horizonColor, env.sky.groundColor};
    }
    std::array<glm::dvec3, 3> sum{};
    std::array<double, 3> weight{};
    const scene::Texture& image = env.image;
    for (uint32_t y = 0; y < image.height; ++y) {
        const double theta = (double(y) + 0.5) / double(image.height) * glm::pi<double>();
        const double up = std::cos(theta);
        const double w = std::sin(theta);  // solid angle of a texel row
        const size_t band = up > 0.5 ? 0 : (up >= 0.0 ? 1 : 2);
        for (uint32_t x = 0; x < image.width; ++x) {
            const glm::dvec3 texel = glm::dvec3(glm::vec3(image.texel(x, y)));
            if (!std::isfinite(texel.x + texel.y + texel.z)) continue;
            sum[band] += w * texel;
            weight[band] += w;
        }
    }
    SkyColors out;
    for (size_t b = 0; b < 3; ++b) {
        out[b] = weight[b] > 0.0 ? glm::vec3(sum[b] / weight[b]) : glm::vec3(0.0f);
    }
    return out;
}

shader::SceneLighting sceneLighting(const scene::Scene& scene, const SkyColors& sky, const LightingSettings& settings) {
    const scene::DirectionalLight& sun = scene.sun;
    const float skyScale = scene.environment.intensity * settings.ambientScale;
    shader::SceneLighting l{};
    l.sunDirection = glm::vec4(glm::normalize(sun.directionToLight), settings.emissiveScale);
    l.sunIrradiance = glm::vec4(sun.color * (sun.illuminance * settings.sunIlluminanceScale), 0.0f);
    l.skyZenith = glm::vec4(sky[0] * skyScale, 0.0f);
    l.skyHorizon = glm::vec4(sky[1] * skyScale, 0.0f);
    l.skyGround = glm::vec4(sky[2] * skyScale, 0.0f);
    return l;
}

shader::SceneLighting sceneLighting(const scene::Scene& scene, const LightingSettings& settings) {
    return sceneLighting(scene, environmentSkyColors(scene.environment), settings);
}

} // namespace glint::passes
