// The sun's visibility at a G-buffer surface from the shadow map
// (glint/gbuffer_shared.h's GBufferShadow; passes/gbuffer.cpp renders and
// fits the map; the filter: glint/sun_shadow.glsl). Needs
// gbuffer_common.glsl first.
#ifndef GLINT_GBUFFER_SHADOW_GLSL
#define GLINT_GBUFFER_SHADOW_GLSL

#include "glint/sun_shadow.glsl"

// The shadow map (reversed depth, see glint/gbuffer_shared.h).
layout(set = 0, binding = 5) uniform sampler2D shadowMap;

// Fraction of the sun reaching `position` (world) on a surface of unit
// normal `n`: 1 lit, 0 shadowed.
float sunShadowVisibility(vec3 position, vec3 n) {
    const GBufferShadow sh = frame.shadow;
    if (sh.enabled == 0u) {
        return 1.0;
    }
    const float NoL = dot(n, frame.lighting.sunDirection.xyz);
    // Facing away, the sun adds nothing whatever its visibility.
    if (NoL <= 0.0) {
        return 1.0;
    }
    float visibility = sunShadowMapVisibility(shadowMap, sh, NoL, position, n);
    // Outside the map (beyond its fit) nothing was rendered to cast.
    if (visibility < 0.0) {
        return 1.0;
    }
    // A map fitted to the view ends at a camera distance; fading out before
    // it hides where shadows stop.
    if (sh.fadeEnd > sh.fadeStart) {
        const float fade = smoothstep(sh.fadeStart, sh.fadeEnd, distance(position, frame.cameraPosition.xyz));
        visibility = mix(visibility, 1.0, fade);
    }
    return visibility;
}

#endif
