#pragma once
// The scene's sun and environment as every pass that lights a surface sees
// them (glint/gbuffer_shared.h's SceneLighting): the G-buffer's lit colour,
// the ray-traced hits and the environment fallback of the reflections all
// take it from here, so a surface seen directly and in a reflection gets
// the same light (glint/brdf.glsl, glint/environment.glsl). An
// equirectangular image is looked up through passes/environment.h's
// EnvironmentMap, whose lighting() adds the image's fields.

#include "glint/scene/scene.h"

#include "glint/gbuffer_shared.h"

#include <array>

namespace glint::passes {

struct LightingSettings {
    // Scene lux -> lit-colour units, in which the procedural sky's colours
    // are radiance. A clear sky gives about a fifth of the direct sun's
    // illuminance (CIE clear sky: ~20 klx diffuse beside ~100 klx direct);
    // a sky of radiance ~0.5 gives an irradiance of ~1.6, so a 100 klx sun
    // becomes ~8 at this scale.
    float sunIlluminanceScale = 8.0f / 100000.0f;
    // Multiplies the sky's contribution (environment intensity still applies).
    float ambientScale = 1.0f;
    // glTF emissive radiance (emissiveFactor x KHR_materials_emissive_strength
    // x texel) -> lit-colour units. glTF gives emission no physical unit;
    // viewers (the Khronos sample viewer, Blender's glTF I/O) show emissive
    // 1.0 as the display's white at exposure 1, and so does 1.0 here: lit
    // 1.0 leaves the composite's default exposure and PBR Neutral tonemap
    // at about display white, near a sunlit white wall (~2.5 at the sun
    // scale above). Emission is added unlit and unshadowed, in the
    // G-buffer's lit colour and at ray-traced hits alike.
    float emissiveScale = 1.0f;
};

// Zenith, horizon and ground radiance, unscaled.
using SkyColors = std::array<glm::vec3, 3>;

// The procedural sky's three colours, or for an equirectangular image the
// solid-angle-weighted mean radiance of its upper cap, horizon band and
// lower hemisphere, non-finite texels skipped (O(texels): compute it once
// per environment, as EnvironmentMap does, not per frame).
SkyColors environmentSkyColors(const scene::Environment& environment);

// The sun and `sky` scaled by the environment's intensity; environment.x = 0
// (the shaders take the procedural sky's path with these colours).
shader::SceneLighting sceneLighting(const scene::Scene& scene, const SkyColors& sky,
                                    const LightingSettings& settings = {});
// The same with environmentSkyColors(scene.environment): walks an image's
// texels on every call.
shader::SceneLighting sceneLighting(const scene::Scene& scene, const LightingSettings& settings = {});

} // namespace glint::passes
