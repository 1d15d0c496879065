// The smoke trace: one primary ray per pixel through a pinhole camera into a
// small procedural scene, traced by both ray backends (ray query in compute,
// ray tracing pipeline) that must agree. Buffers use scalar layout.
#ifndef GLINT_SMOKE_SHARED_H
#define GLINT_SMOKE_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

GLINT_CONST uint kSmokeGroupSize = 8;
GLINT_CONST float kSmokeTMin = 1.0e-3f;
GLINT_CONST float kSmokeTMax = 1.0e4f;

// Push constants of both backends (80 bytes).
struct SmokeCamera {
    vec4 origin;
    vec4 lowerLeft;   // world position of the image's lower-left corner
    vec4 horizontal;  // full image width, world units
    vec4 vertical;    // full image height, world units
    uvec4 size;       // width, height, unused, unused
};

// One record per pixel (32 bytes).
struct SmokeHit {
    uint hit;        // 1 when a triangle was hit
    uint instance;   // instance custom index
    uint geometry;   // geometry index inside the BLAS
    uint primitive;  // triangle index inside the geometry
    float t;
    float u;         // barycentrics of vertices 1 and 2
    float v;
    uint pad;
};

GLINT_END

#ifndef __cplusplus
vec3 smokeRayDirection(SmokeCamera camera, uvec2 pixel) {
    const vec2 uv = (vec2(pixel) + 0.5) / vec2(camera.size.xy);
    const vec3 target = camera.lowerLeft.xyz + uv.x * camera.horizontal.xyz + uv.y * camera.vertical.xyz;
    return normalize(target - camera.origin.xyz);
}

SmokeHit smokeMiss() { return SmokeHit(0u, 0u, 0u, 0u, 0.0, 0.0, 0.0, 0u); }
#endif

#endif
