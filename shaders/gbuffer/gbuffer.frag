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

layout(location = 0) out vec4 outNormal;
layout(location = 1) out vec4 outAlbedo;
layout(location = 2) out vec4 outRoughnessMetal;
layout(location = 3) out vec2 outMotion;
layout(location = 4) out vec4 outLit;

vec2 pixelOf(vec4 clip) {
    return (clip.xy / clip.w * 0.5 + 0.5) * frame.size;
}

void main() {
    const float lengthSq = dot(inNormal, inNormal);
    // Degenerate normals (zero-area skinning, bad input) must not put NaN
    // into the buffer every later pass reads.
    vec3 n = lengthSq > 1e-20 ? inNormal * inversesqrt(lengthSq) : vec3(0.0, 1.0, 0.0);
    if (draw.doubleSided != 0u && !gl_FrontFacing) {
        n = -n;
    }
    Surface s;
    s.position = inWorldPosition;
    s.normal = n;
    s.albedo = clamp(inAlbedo, 0.0, 1.0);
    s.roughness = clamp(inMaterial.x, 0.0, 1.0);
    s.metallic = clamp(inMaterial.y, 0.0, 1.0);
    s.reflectance = clamp(inMaterial.z, 0.0, 1.0);

    const vec3 toViewer = normalize(frame.cameraPosition.xyz - inWorldPosition);
    outNormal = vec4(n, 1.0);
    outAlbedo = vec4(s.albedo, 1.0);
    outRoughnessMetal = vec4(s.roughness, s.metallic, s.reflectance, 1.0);
    // A vertex behind last frame's camera has w <= 0: no motion is better
    // than a wild one.
    outMotion = inPreviousClip.w > 0.0 ? pixelOf(inPreviousClip) - pixelOf(inClip) : vec2(0.0);
    outLit = vec4(shadeSurface(frame.lighting, s, toViewer, sunShadowVisibility(inWorldPosition, n)), 1.0);
}
