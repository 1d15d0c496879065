#pragma once
// The scene's sun and environment as every pass that lights a surface sees
// them (glint/gbuffer_shared.h's SceneLighting): the G-buffer's lit colour,
// the ray-traced hits and the environment fallback of the reflections all
// take it from here, so a surface seen directly and in a reflection gets
// the same light (glint/brdf.glsl).

#include "scene/scene.h"

#include "glint/gbuffer_shared.h"

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
};

// The procedural sky's three colours, or for an equirectangular image the
// solid-angle-weighted mean radiance of its upper cap, horizon band and
// lower hemisphere (O(texels): compute it once per scene, not per pixel).
shader::SceneLighting sceneLighting(const scene::Scene& scene, const LightingSettings& settings = {});

} // namespace glint::passes
