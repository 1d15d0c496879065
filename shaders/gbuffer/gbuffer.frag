#version 460
// G-buffer surface: writes the attributes and lights the surface with the
// unified lighting (glint/brdf.glsl), the sun shadowed by the shadow map
// (shadow.glsl) as the ray-traced hits are by their shadow rays.
#extension GL_GOOGLE_include_directive : require

#include "gbuffer_common.glsl"
#include "glint/brdf.glsl"
#include "shadow.glsl"

layout(location = 0) in vec3 inWorldPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec3 inAlbedo;
layout(location = 3) in vec3 inMaterial;
layout(location = 4) in vec4 inClip;
layout(location = 5) in vec4 inPreviousClip;
layout(location = 6) in vec4 inTangent;
layout(location = 7) in vec4 inUv;

// The draw's normal texture (linear, tangent space); a flat one when the
// material has none and draw.normalMap is 0.
layout(set = 0, binding = 7) uniform sampler2D normalMap;

layout(location = 0) out vec4 outNormal;
layout(location = 1) out vec4 outAlbedo;
layout(location = 2) out vec4 outRoughnessMetal;
layout(location = 3) out vec2 outMotion;
layout(location = 4) out vec4 outLit;

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
    const vec2 uv = applyUvTransform(draw.normalUvTransform, draw.normalTexCoord == 0u ? inUv.xy : inUv.zw);
    vec3 m = texture(normalMap, uv).xyz * 2.0 - 1.0;
    m.xy *= draw.normalScale;
    const vec3 perturbed = t * m.x + b * m.y + frameNormal * m.z;
    const float lengthSq = dot(perturbed, perturbed);
    return lengthSq > 1e-20 ? perturbed * inversesqrt(lengthSq) : frameNormal;
}

void main() {
    const float lengthSq = dot(inNormal, inNormal);
    // Degenerate normals (zero-area skinning, bad input) must not put NaN
    // into the buffer every later pass reads.
    vec3 n = lengthSq > 1e-20 ? inNormal * inversesqrt(lengthSq) : vec3(0.0, 1.0, 0.0);
    const bool backFace = draw.doubleSided != 0u && !gl_FrontFacing;
    // The shadow lookup's normal offset and slope bias follow the surface
    // the shadow map rasterised, not the normal map's detail.
    const vec3 geometricNormal = backFace ? -n : n;
    n = draw.normalMap != 0u ? normalMapped(n, backFace) : geometricNormal;
    Surface s;
    s.position = inWorldPosition;
    s.normal = n;
    s.albedo = clamp(inAlbedo, 0.0, 1.0);
    s.roughness = clamp(inMaterial.x, 0.0, 1.0);
    s.metallic = clamp(inMaterial.y, 0.0, 1.0);
    s.reflectance = clamp(inMaterial.z, 0.0, 1.0);

    const vec3 toViewer = normalize(frame.cameraPosition.xyz - inWorldPosition);
    // A normal map may turn a pixel towards the sun that the surface turns
    // away from it: the surface itself shadows it.
    const bool selfShadowed = draw.normalMap != 0u && dot(geometricNormal, frame.lighting.sunDirection.xyz) <= 0.0;
    const float sunVisibility = selfShadowed ? 0.0 : sunShadowVisibility(inWorldPosition, geometricNormal);
    outNormal = vec4(n, 1.0);
    outAlbedo = vec4(s.albedo, 1.0);
    outRoughnessMetal = vec4(s.roughness, s.metallic, s.reflectance, 1.0);
    // A vertex behind last frame's camera has w <= 0: no motion is better
    // than a wild one.
    outMotion = inPreviousClip.w > 0.0 ? pixelOf(inPreviousClip) - pixelOf(inClip) : vec2(0.0);
    outLit = vec4(shadeSurface(frame.lighting, s, toViewer, sunVisibility), 1.0);
}
