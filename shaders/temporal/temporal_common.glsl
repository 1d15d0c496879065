// What both temporal shaders share: the frame constants (binding 0),
// position reconstruction and the finite checks. Needs
// glint/temporal_shared.h first.
#ifndef GLINT_TEMPORAL_COMMON_GLSL
#define GLINT_TEMPORAL_COMMON_GLSL

layout(set = 0, binding = 0, scalar) uniform Frame { TemporalFrame frame; };

// On the bits, not isnan/isinf: a compiler that assumes no NaN (fast-math
// style) may fold those away, and here NaN is the very case.
bool isFinite(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }
bool isFinite(vec2 v) { return isFinite(v.x) && isFinite(v.y); }
bool isFinite(vec3 v) { return isFinite(v.x) && isFinite(v.y) && isFinite(v.z); }

// World position of a pixel position (pixels, +y down) at a reversed-Z depth
// (> 0: the sky has no position).
vec3 worldPosition(mat4 inverseViewProjection, vec2 pixelPosition, vec2 size, float depth) {
    const vec2 ndc = pixelPosition / size * 2.0 - 1.0;
    const vec4 p = inverseViewProjection * vec4(ndc, depth, 1.0);
    return p.xyz / p.w;
}

// View depth (clip w: distance along the view axis) of a world point.
float viewDepth(mat4 viewProjection, vec3 p) {
    return (viewProjection * vec4(p, 1.0)).w;
}

#endif
