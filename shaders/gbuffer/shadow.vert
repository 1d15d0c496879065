#version 460
// The sun's shadow map: the G-buffer's vertices (same buffer, same skinning,
// same instance transforms) seen through the shadow map's orthographic
// view. Depth only; shadow.frag is empty, shadow_masked.frag discards what
// an alpha-tested material's coverage leaves out.
#extension GL_GOOGLE_include_directive : require

#include "gbuffer_common.glsl"

// For shadow_masked.frag's alpha test (the opaque fragment stage reads none).
layout(location = 0) out vec4 outUv;  // uv0, uv1
layout(location = 1) out float outAlpha;

void main() {
    const GBufferVertex v = vertices[gl_VertexIndex];
    const GBufferInstance inst = instances[gl_InstanceIndex];
    vec3 position = v.position;
    if (inst.jointCount > 0u) {
        position = (skinMatrix(v, inst, false) * vec4(v.position, 1.0)).xyz;
    }
    gl_Position = frame.shadow.viewProjection * (inst.transform * vec4(position, 1.0));
    outUv = vec4(v.uv0, v.uv1);
    outAlpha = v.alpha;
}
