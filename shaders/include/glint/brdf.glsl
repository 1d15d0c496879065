// The unified lighting of Glint: the G-buffer's lit colour and the
// reflection hit shaders light surfaces with these functions, so a surface
// seen directly and in a reflection gets the same radiance.
//
// Specular: GGX / Trowbridge-Reitz distribution, height-correlated Smith
// visibility and Schlick Fresnel, as Filament writes them ("Physically Based
// Rendering in Filament", sections 4.4-4.6), alpha = roughness^2. Diffuse:
// Lambert. Needs glint/gbuffer_shared.h (SceneLighting) first; with
// GLINT_ENVIRONMENT_BINDING defined also the environment's lookups
// (glint/environment.glsl) and shadeSurface.
#ifndef GLINT_BRDF_GLSL
#define GLINT_BRDF_GLSL

const float kPi = 3.14159265358979;

// Filament clamps roughness so alpha^2 stays representable in half and
// float; at alpha -> 0 the sun's highlight would be an infinite spike.
const float kMinRoughness = 0.045;

float ggxDistribution(float NoH, float alpha) {
    const float a2 = alpha * alpha;
    const float d = (NoH * a2 - NoH) * NoH + 1.0;
    return a2 / (kPi * d * d);
}

float smithVisibility(float NoV, float NoL, float alpha) {
    const float a2 = alpha * alpha;
    const float ggxV = NoL * sqrt(NoV * NoV * (1.0 - a2) + a2);
    const float ggxL = NoV * sqrt(NoL * NoL * (1.0 - a2) + a2);
    return 0.5 / max(ggxV + ggxL, 1e-7);
}

vec3 fresnelSchlick(vec3 f0, float VoH) {
    const float f = pow(1.0 - VoH, 5.0);
    return f0 + (vec3(1.0) - f0) * f;
}

struct Surface {
    vec3 position;  // world
    vec3 normal;    // world, unit
    vec3 albedo;    // linear base colour
    float roughness;
    float metallic;
    float reflectance;
};

vec3 surfaceF0(Surface s) {
    return mix(vec3(0.16 * s.reflectance * s.reflectance), s.albedo, s.metallic);
}

vec3 diffuseColor(Surface s) {
    return s.albedo * (1.0 - s.metallic);
}

// The specular sky light the reflection passes add (composite) and the
// transparent surfaces add themselves (gbuffer_surface.glsl) is weighted
// by this. Karis, "Physically Based Shading on Mobile" (Unreal Engine blog, 2014):
// an analytic fit of the split-sum environment BRDF of GGX (the scale and
// bias that multiply F0 after integrating the BRDF over the lobe), by
// perceptual roughness and N.V.
vec3 envBrdfApprox(vec3 f0, float roughness, float NoV) {
    const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
    const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    const vec4 r = roughness * c0 + c1;
    const float a004 = min(r.x * r.x, exp2(-9.28 * NoV)) * r.x + r.y;
    const vec2 ab = vec2(-1.04, 1.04) * a004 + r.zw;
    return f0 * ab.x + ab.y;
}

// The sun's specular reflection leaving `s` towards `toViewer` (unit),
// unshadowed: the one term of shadeSurface that depends on the direction
// the light leaves in. SSLR swaps the camera's direction for the ray's
// with it at its hits (shaders/sslr/trace.comp), as the ray-traced hits are
// lit from the ray's side.
vec3 sunSpecular(SceneLighting l, Surface s, vec3 toViewer) {
    const vec3 n = s.normal;
    const vec3 L = l.sunDirection.xyz;
    const float NoL = clamp(dot(n, L), 0.0, 1.0);
    const float NoV = max(dot(n, toViewer), 1e-4);
    const vec3 H = normalize(L + toViewer);
    const float NoH = clamp(dot(n, H), 0.0, 1.0);
    const float VoH = clamp(dot(toViewer, H), 0.0, 1.0);
    const float roughness = max(s.roughness, kMinRoughness);
    const float alpha = roughness * roughness;
    const vec3 F = fresnelSchlick(surfaceF0(s), VoH);
    return F * (ggxDistribution(NoH, alpha) * smithVisibility(NoV, NoL, alpha)) * l.sunIrradiance.rgb * NoL;
}

#ifdef GLINT_ENVIRONMENT_BINDING
// The environment's lookups (the sky, its irradiance, the prefiltered
// image): shaders that light surfaces bind it.
#include "glint/environment.glsl"

// Sun (diffuse + specular) and diffuse sky light leaving `s` towards `toViewer`
// (unit). `sunVisibility` is 1 unshadowed, 0 in shadow. Specular sky light
// is left to the reflection passes.
vec3 shadeSurface(SceneLighting l, Surface s, vec3 toViewer, float sunVisibility) {
    const vec3 n = s.normal;
    const float NoL = clamp(dot(n, l.sunDirection.xyz), 0.0, 1.0);
    const vec3 diffuse = diffuseColor(s) / kPi;
    const vec3 sun = (diffuse * l.sunIrradiance.rgb * NoL + sunSpecular(l, s, toViewer)) * sunVisibility;
    const vec3 ambient = diffuseColor(s) / kPi * environmentIrradiance(l, n);
    return sun + ambient;
}
#endif

#endif
