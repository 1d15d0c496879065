// Screen-space reflections (passes/sslr.cpp, shaders/sslr/trace.comp):
// constants and push constants shared by GLSL and C++. Buffers use scalar
// layout.
//
// Outputs, per pixel p = y * width + x (only ray leaders of SSLR and hybrid
// pixels are traced; every other pixel keeps the cleared zero):
//   radiance    lit colour at the hit, rgb; a = 1 where a hit was found
//   confidence  [0, 1]: 0 for misses (off screen, sky, too thick, back face)
//   hitDebug    xy = hit uv, z = confidence, w = 1 on a hit
// RT hand-off: each hybrid ray whose confidence is below the threshold is
// appended to ray generation's RT ray list (glint/ray_generation_shared.h,
// kRayList*), after the RT pixels' rays.
#ifndef GLINT_SSLR_SHARED_H
#define GLINT_SSLR_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

// Push constants of trace.comp (128 bytes, Vulkan's guaranteed minimum).
// The projection travels as its four non-trivial entries: an unjittered
// perspective (scene::perspectiveReversedZ) has P[2][0] = P[2][1] = 0,
// P[2][3] = -1 and P[3][3] = 0 (passes/sslr.cpp checks this), so
//   clip = (P00 x, P11 y, P22 z + P32, -z)   for a view-space point (x, y, z).
struct SslrConstants {
    mat4 view;              // world -> view
    vec4 projection;        // P00, P11, P22, P32
    uvec2 size;
    uint frame;
    uint linearSteps;
    uint refineSteps;
    float thickness;
    float maxDistance;
    float edgeFade;
    float confidenceThreshold;
    float coneRoughness;  // perceptual roughness from which the cone trace runs
    uint pyramidMips;     // levels of the colour pyramid; 0: no cone trace
    uint pad0;
};

// Push constants of pyramid_down.comp.
struct SslrPyramidConstants {
    uvec2 sourceSize;
    uvec2 targetSize;
};

// The pyramid stops at 2^(kSslrPyramidMaxMips - 1) pixels per texel: wider
// footprints belong to pixels rougher than the cutoff, which trace nothing.
GLINT_CONST uint kSslrPyramidMaxMips = 8u;

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::SslrConstants) == 128);
#endif

#endif
