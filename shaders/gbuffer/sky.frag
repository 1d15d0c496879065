#version 460
// Sky pixels of the G-buffer: the environment's radiance along the view ray
// in the lit colour; the normal, albedo and material targets get the
// clear values (a sky pixel has no surface); motion is the sky's own.
#extension GL_GOOGLE_include_directive : require

#include "gbuffer_common.glsl"
#include "glint/brdf.glsl"

layout(location = 0) out vec4 outNormal;
layout(location = 1) out vec4 outAlbedo;
layout(location = 2) out vec4 outRoughnessMetal;
layout(location = 3) out vec2 outMotion;
layout(location = 4) out vec4 outLit;

void main() {
    const vec2 ndc = gl_FragCoord.xy / frame.size * 2.0 - 1.0;
    // Reversed Z: depth 1 is the near plane, finite for infinite projections.
    const vec4 nearPoint = frame.inverseViewProjection * vec4(ndc, 1.0, 1.0);
    const vec3 dir = normalize(nearPoint.xyz / nearPoint.w - frame.cameraPosition.xyz);
    outNormal = vec4(0.0);
    outAlbedo = vec4(0.0);
    outRoughnessMetal = vec4(0.0);
    // The sky is at infinity: only the camera's rotation moves it.
    const vec4 clip = frame.viewProjection * vec4(dir, 0.0);
    const vec4 previousClip = frame.previousViewProjection * vec4(dir, 0.0);
    outMotion = clip.w > 0.0 && previousClip.w > 0.0
                    ? (previousClip.xy / previousClip.w - clip.xy / clip.w) * 0.5 * frame.size
                    : vec2(0.0);
    outLit = vec4(environmentRadiance(frame.lighting, dir, 0.0), 0.0);
}
