#version 460
// The shadow map of alpha-tested materials (glTF alphaMode MASK): the same
// coverage test as the G-buffer's (gbuffer_surface.glsl), so a leaf casts
// the shadow of its cut-out shape.
#extension GL_GOOGLE_include_directive : require

#include "gbuffer_common.glsl"

layout(location = 0) in vec4 inUv;  // uv0, uv1
layout(location = 1) in float inAlpha;

// The base colour texture (its alpha), at the G-buffer's binding.
layout(set = 0, binding = 8) uniform sampler2D baseColorMap;

void main() {
    float alpha = inAlpha;
    if (draw.baseColorMap != 0u) {
        const vec2 uv = applyUvTransform(draw.baseColorUvTransform, draw.baseColorMap == 2u ? inUv.zw : inUv.xy);
        alpha *= texture(baseColorMap, uv).a;
    }
    if (alpha < draw.alphaCutoff) {
        discard;
    }
}
