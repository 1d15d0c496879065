// Screen-space reflections (passes/sslr.cpp, shaders/sslr/trace.comp):
// constants and push constants shared by GLSL and C++. Buffers use scalar
// layout.
//
// Outputs, per pixel p = y * width + x (only ray leaders of SSLR and hybrid
// pixels are traced; every other pixel keeps the cleared zero):
//   radiance    lit colour at the hit, rgb; a = 1 where a hit was found
//   confidence  [0, 1]: 0 for misses (off screen, sky, too thick, back face)
//   hitDebug    xy = hit uv, z = confidence, w = 1 on a hit
// RT hand-off:
//   rtRays      PackedRay (glint/ray_generation_shared.h) of each hybrid
//               ray whose confidence is below the threshold
//   rtArgs      VkDispatchIndirectCommand (one kSslrRtGroupSize-wide
//               workgroup per kSslrRtGroupSize listed rays) followed by the
//               list's length in rays (word kSslrRtCountOffset)
#ifndef GLINT_SSLR_SHARED_H
#define GLINT_SSLR_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

GLINT_CONST uint kSslrRtGroupSize = 64u;
GLINT_CONST uint kSslrRtCountOffset = 3u;
GLINT_CONST uint kSslrRtArgsWords = 4u;

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
    uint pad0;
    uint pad1;
    uint pad2;
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::SslrConstants) == 128);
#endif

#endif
