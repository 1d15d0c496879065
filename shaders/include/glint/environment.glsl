// The environment as every pass that looks it up sees it: the sky pixels,
// the diffuse ambient light of the G-buffer and of ray-traced hits, the
// misses of the ray-traced reflections and integrate's environment
// fallback. One definition, so a direction and roughness give the same
// radiance wherever they are looked up.
//
// SceneLighting::environment.x says which environment the frame has:
//   0  the procedural gradient sky (skyRadiance / skyIrradiance below,
//      analytic; environmentTexture is a stand-in the shaders never read)
//   1  an equirectangular image, prefiltered by roughness into
//      environmentTexture's mips plus nine SH coefficients of irradiance
//      (passes/environment.h, glint/environment_shared.h).
//
// The includer defines GLINT_ENVIRONMENT_BINDING (the binding of the
// prefiltered texture, a trilinear sampler repeating in u and clamping in
// v) and includes glint/gbuffer_shared.h (SceneLighting) first;
// glint/brdf.glsl includes this file when the binding is defined.
#ifndef GLINT_ENVIRONMENT_GLSL
#define GLINT_ENVIRONMENT_GLSL

#include "glint/environment_shared.h"

#ifndef GLINT_ENVIRONMENT_BINDING
#error "define GLINT_ENVIRONMENT_BINDING (the prefiltered environment's binding) before including glint/environment.glsl"
#endif

layout(set = 0, binding = GLINT_ENVIRONMENT_BINDING) uniform sampler2D environmentTexture;

const float kEnvironmentPi = 3.14159265358979;

// Radiance of the gradient sky in direction `dir` (unit): ground below the
// horizon, horizon to zenith above it.
vec3 skyRadiance(SceneLighting l, vec3 dir) {
    const float y = clamp(dir.y, -1.0, 1.0);
    if (y < 0.0) {
        // A short blend below the horizon keeps the seam from aliasing.
        return mix(l.skyHorizon.rgb, l.skyGround.rgb, clamp(-y * 10.0, 0.0, 1.0));
    }
    return mix(l.skyHorizon.rgb, l.skyZenith.rgb, sqrt(y));
}

// Irradiance from the gradient sky on a surface facing `n`, cosine-weighted:
// the classic hemisphere-light approximation, blending the irradiance of a
// surface facing straight up (sky only) and straight down (ground only).
vec3 skyIrradiance(SceneLighting l, vec3 n) {
    const vec3 up = kEnvironmentPi * mix(l.skyHorizon.rgb, l.skyZenith.rgb, 0.5);
    const vec3 down = kEnvironmentPi * l.skyGround.rgb;
    return mix(down, up, 0.5 + 0.5 * clamp(n.y, -1.0, 1.0));
}

bool environmentHasImage(SceneLighting l) { return l.environment.x != 0.0; }

// A world direction in the image's frame: the image is turned by
// environment.w radians about +Y (scene::Environment::rotationRadians).
vec3 environmentImageDirection(SceneLighting l, vec3 dir) {
    const float c = cos(l.environment.w);
    const float s = sin(l.environment.w);
    return vec3(c * dir.x - s * dir.z, dir.y, s * dir.x + c * dir.z);
}

// Radiance the environment reflects towards a surface of perceptual
// `roughness` around the mirror direction `dir` (unit); roughness 0 is the
// environment itself (the sky pixels). The image: its level for the
// roughness, trilinear. The gradient sky is smooth, so there the mirror
// radiance blends towards the cosine-weighted irradiance over pi as the
// GGX lobe widens (alpha = roughness^2 reaches a hemisphere near 1).
vec3 environmentRadiance(SceneLighting l, vec3 dir, float roughness) {
    if (!environmentHasImage(l)) {
        const float alpha = clamp(roughness * roughness, 0.0, 1.0);
        return mix(skyRadiance(l, dir), skyIrradiance(l, dir) / kEnvironmentPi, alpha);
    }
    const vec2 uv = environmentEquirectUv(environmentImageDirection(l, dir));
    const float lod = environmentLevelOfRoughness(clamp(roughness, 0.0, 1.0), l.environment.z);
    return textureLod(environmentTexture, uv, lod).rgb * l.environment.y;
}

// Irradiance from the environment on a surface facing `n` (unit): pi times
// the radiance for a constant environment.
vec3 environmentIrradiance(SceneLighting l, vec3 n) {
    if (!environmentHasImage(l)) {
        return skyIrradiance(l, n);
    }
    const vec3 d = environmentImageDirection(l, n);
    vec3 e = vec3(0.0);
    for (uint j = 0u; j < kEnvironmentShCount; ++j) {
        e += l.irradianceSh[j].rgb * environmentShBasis(j, d);
    }
    // Nine bands ring below zero behind a bright sun; light is never negative.
    return max(e, vec3(0.0)) * l.environment.y;
}

#endif
