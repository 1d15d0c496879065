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
// depth, is affine in q (a pinhole camera, jittered or not). So for a plane
// through `position` with unit `normal`, the point at view depth w on the
// ray through q = pixelPosition + (dx, dy) lies
//   dot(camera - position, normal) + w (s.x + dx s.y + dy s.z)
// off it, with s the vec3 returned here: e(q) = E(q) . normal at
// pixelPosition and its steps per pixel in x and y. The matrices are the
// camera's (jittered) inverse view-projection, which gives the rays, and
// its view-projection, whose w row gives view depth.
vec3 planeDistanceSteps(mat4 inverseViewProjection, mat4 viewProjection, vec3 camera, vec2 pixelPosition,
                        vec3 normal) {
    // w is linear along a ray from the camera, where it is 0.
    const vec3 wRow = vec3(viewProjection[0][3], viewProjection[1][3], viewProjection[2][3]);
    vec3 e[3];
    for (int i = 0; i < 3; ++i) {
        const vec2 q = pixelPosition + vec2(i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0);
        const vec3 ray = worldPosition(inverseViewProjection, q, vec2(frame.size), 1.0) - camera;
        e[i] = ray / dot(wRow, ray);
    }
    const float e0 = dot(e[0], normal);
    return vec3(e0, dot(e[1], normal) - e0, dot(e[2], normal) - e0);
}

#endif
