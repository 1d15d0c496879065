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

// A point's distance to a plane from its view depth alone. The point at
// view depth w on a camera's ray through pixel position q is
// camera + w E(q), where E(q), the step along the ray per unit of view
// depth, is affine in q (a pinhole camera, jittered or not: the rays meet
// the near plane, where w is the same everywhere, at points affine in q).
// So for a plane through `position` with unit `normal`, the point at view
// depth w on the ray through q = pixelPosition + (dx, dy) lies
//   dot(camera - position, normal) + w (s.x + dx s.y + dy s.z)
// off it, with s the vec3 returned here: e(q) = E(q) . normal at
// pixelPosition and its steps per pixel in x and y. `rays` is E's affine
// form for the camera (TemporalFrame::rays or previousRays).
vec3 planeDistanceSteps(vec4 rays[3], vec2 pixelPosition, vec3 normal) {
    const float perX = dot(rays[1].xyz, normal);
    const float perY = dot(rays[2].xyz, normal);
    return vec3(dot(rays[0].xyz, normal) + pixelPosition.x * perX + pixelPosition.y * perY, perX, perY);
}

#endif
