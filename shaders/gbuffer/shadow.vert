#version 460
// The sun's shadow map: the G-buffer's vertices (same buffer, same skinning,
// same instance transforms) seen through the shadow map's orthographic
// view. Depth only; shadow.frag is empty.
#extension GL_GOOGLE_include_directive : require

#include "gbuffer_common.glsl"

void main() {
    const GBufferVertex v = vertices[gl_VertexIndex];
    const GBufferInstance inst = instances[draw.instance];
    vec3 position = v.position;
    if (inst.jointCount > 0u) {
        position = (skinMatrix(v, inst, false) * vec4(v.position, 1.0)).xyz;
    }
    gl_Position = frame.shadow.viewProjection * (inst.transform * vec4(position, 1.0));
}
