// G-buffer surface: writes the attributes and lights the surface with the
// unified lighting (glint/brdf.glsl), the sun shadowed by the shadow map
// (shadow.glsl) as the ray-traced hits are (by the same map where it
// covers them, else by shadow rays). Compiled
// three times: gbuffer.frag (opaque materials) and gbuffer_masked.frag
// (alpha-tested ones, GLINT_ALPHA_TEST 1), so that only the draws that
// discard lose early depth testing, and transparent.frag (blended ones,
// GLINT_BLEND 1: no attributes, one premultiplied colour the transparent
// pass blends over what lies behind; passes/transparent.h).
#if !defined(GLINT_ALPHA_TEST) || !defined(GLINT_BLEND)
#error "define GLINT_ALPHA_TEST and GLINT_BLEND (0 or 1) before including gbuffer_surface.glsl"
#endif

#include "gbuffer_common.glsl"
#include "glint/brdf.glsl"
#include "shadow.glsl"

layout(location = 0) in vec3 inWorldPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inAlbedo;  // rgb, a = coverage
layout(location = 3) in vec3 inMaterial;
layout(location = 4) in vec4 inClip;
layout(location = 5) in vec4 inPreviousClip;
layout(location = 6) in vec4 inTangent;
layout(location = 7) in vec4 inUv;
layout(location = 8) in vec3 inEmissive;

// The draw's material textures; 1x1 fallbacks (flat normal, white) where the
// material has none and the draw's flag is 0 (glint/gbuffer_shared.h's
// GBufferDraw: a flag is the texture coordinate set plus one).
layout(set = 0, binding = 7) uniform sampler2D normalMap;     // linear, tangent space
layout(set = 0, binding = 8) uniform sampler2D baseColorMap;  // sRGB image: texels decode to linear
layout(set = 0, binding = 9) uniform sampler2D metalRoughMap; // linear; G = roughness, B = metallic
layout(set = 0, binding = 10) uniform sampler2D emissiveMap;  // sRGB image: texels decode to linear

#if GLINT_BLEND
// Premultiplied: rgb = radiance x coverage, a = coverage.
layout(location = 0) out vec4 outColor;
#else
layout(location = 0) out vec4 outNormal;
layout(location = 1) out vec4 outAlbedo;
layout(location = 2) out vec4 outRoughnessMetal;
layout(location = 3) out vec2 outMotion;
layout(location = 4) out vec4 outLit;
#endif

// A texture reference's coordinates: its set (the draw's flag: glTF
// texCoord plus one), then its KHR_texture_transform.
vec2 textureUv(uint flag, UvTransform transform) {
    return applyUvTransform(transform, flag == 2u ? inUv.zw : inUv.xy);
}

vec2 pixelOf(vec4 clip) {
    return (clip.xy / clip.w * 0.5 + 0.5) * frame.size;
}

// glTF tangent-space normal mapping: n' = normalize(T m.x + B m.y + N m.z)
// with m = (2 texel - 1) * (scale, scale, 1) and B = cross(N, T) * w. `n` is
// the unit geometric normal of the front face; back faces of double-sided
// materials flip the whole frame (as the Khronos glTF sample viewer does).
// A degenerate tangent keeps the unperturbed normal.
vec3 normalMapped(vec3 n, bool backFace) {
    vec3 t = inTangent.xyz - n * dot(n, inTangent.xyz);
    const float tangentLengthSq = dot(t, t);
    if (!(tangentLengthSq > 1e-20)) {
        return backFace ? -n : n;
    }
    t *= inversesqrt(tangentLengthSq);
    vec3 b = cross(n, t) * (inTangent.w < 0.0 ? -1.0 : 1.0);
    vec3 frameNormal = n;
    if (backFace) {
        t = -t;
        b = -b;
        frameNormal = -n;
    }
    vec3 m = texture(normalMap, textureUv(draw.normalMap, draw.normalUvTransform)).xyz * 2.0 - 1.0;
    m.xy *= draw.normalScale;
    const vec3 perturbed = t * m.x + b * m.y + frameNormal * m.z;
    const float lengthSq = dot(perturbed, perturbed);
    return lengthSq > 1e-20 ? perturbed * inversesqrt(lengthSq) : frameNormal;
}

void main() {
#if GLINT_ALPHA_TEST || GLINT_BLEND
    // The coverage: vertex alpha (factor times COLOR_0) times the base
    // colour texel's.
    float alpha = inAlbedo.a;
    if (draw.baseColorMap != 0u) {
        alpha *= texture(baseColorMap, textureUv(draw.baseColorMap, draw.baseColorUvTransform)).a;
    }
#endif
#if GLINT_ALPHA_TEST
    // glTF alphaMode MASK: the coverage against the cutoff; what falls
    // below leaves no surface.
    if (alpha < draw.alphaCutoff) {
        discard;
    }
#endif
    const float lengthSq = dot(inNormal, inNormal);
    // Degenerate normals (zero-area skinning, bad input) must not put NaN
    // into the buffer every later pass reads.
    vec3 n = lengthSq > 1e-20 ? inNormal * inversesqrt(lengthSq) : vec3(0.0, 1.0, 0.0);
    const bool backFace = draw.doubleSided != 0u && !gl_FrontFacing;
    // The shadow lookup's normal offset and slope bias follow the surface
    // the shadow map rasterised, not the normal map's detail.
    const vec3 geometricNormal = backFace ? -n : n;
    n = draw.normalMap != 0u ? normalMapped(n, backFace) : geometricNormal;
    // glTF: factor (and COLOR_0, both in the vertex) times texel, per pixel.
    // The flags are push constants, so the branches are uniform per draw.
    vec3 albedo = inAlbedo.rgb;
    if (draw.baseColorMap != 0u) {
        albedo *= texture(baseColorMap, textureUv(draw.baseColorMap, draw.baseColorUvTransform)).rgb;
    }
    vec2 roughnessMetallic = inMaterial.xy;
    if (draw.metalRoughMap != 0u) {
        roughnessMetallic *= texture(metalRoughMap, textureUv(draw.metalRoughMap, draw.metalRoughUvTransform)).gb;
    }
    Surface s;
    s.position = inWorldPosition;
    s.normal = n;
    s.albedo = clamp(albedo, 0.0, 1.0);
    s.roughness = clamp(roughnessMetallic.x, 0.0, 1.0);
    s.metallic = clamp(roughnessMetallic.y, 0.0, 1.0);
    s.reflectance = clamp(inMaterial.z, 0.0, 1.0);

    const vec3 toViewer = normalize(frame.cameraPosition.xyz - inWorldPosition);
    // A normal map may turn a pixel towards the sun that the surface turns
    // away from it: the surface itself shadows it.
    const bool selfShadowed = draw.normalMap != 0u && dot(geometricNormal, frame.lighting.sunDirection.xyz) <= 0.0;
    const float sunVisibility = selfShadowed ? 0.0 : sunShadowVisibility(inWorldPosition, geometricNormal);
#if !GLINT_BLEND
    outNormal = vec4(n, 1.0);
    outAlbedo = vec4(s.albedo, 1.0);
    outRoughnessMetal = vec4(s.roughness, s.metallic, s.reflectance, 1.0);
    // A vertex behind last frame's camera has w <= 0: no motion is better
    // than a wild one.
    outMotion = inPreviousClip.w > 0.0 ? pixelOf(inPreviousClip) - pixelOf(inClip) : vec2(0.0);
#endif
    // Emission: glTF factor x strength (in the vertex) x the sRGB texel, in
    // lit units through the emissive scale; neither lit nor shadowed.
    vec3 emission = inEmissive;
    if (draw.emissiveMap != 0u) {
        emission *= texture(emissiveMap, textureUv(draw.emissiveMap, draw.emissiveUvTransform)).rgb;
    }
    emission *= frame.lighting.sunDirection.w;
#if GLINT_BLEND
    // glTF alphaMode BLEND, as the Khronos sample viewer blends it: the
    // whole radiance (sun, diffuse sky, emission and the specular sky light
    // an opaque surface gets from the reflection passes, here from the
    // environment alone) times the coverage, over what lies behind.
    const float NoV = clamp(dot(n, toViewer), 0.0, 1.0);
    const vec3 specularSky = environmentRadiance(frame.lighting, reflect(-toViewer, n), s.roughness) *
                             envBrdfApprox(surfaceF0(s), s.roughness, NoV);
    const vec3 radiance = shadeSurface(frame.lighting, s, toViewer, sunVisibility) + specularSky + emission;
    const float coverage = clamp(alpha, 0.0, 1.0);
    outColor = vec4(radiance * coverage, coverage);
#else
    // a: the sun's visibility, with which SSLR re-lights the surface for
    // the direction a reflection ray sees it from (shaders/sslr/trace.comp).
    outLit = vec4(shadeSurface(frame.lighting, s, toViewer, sunVisibility) + emission, sunVisibility);
#endif
}
