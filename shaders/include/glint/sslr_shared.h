// Screen-space reflections (passes/sslr.cpp, shaders/sslr/trace.comp):
// constants and push constants shared by GLSL and C++. Buffers use scalar
// layout.
//
// Outputs, per pixel p = y * width + x, written at the ray leaders of the
// SSLR and hybrid pixels only (the SSLR list's entries): other pixels hold
// whatever the memory held, unless SslrSettings::clearUntraced zeroes them
// first (for debug views). Readers look at a pixel's leader, and only for
// SSLR and hybrid pixels:
//   radiance    lit colour at the hit (re-lit for the ray's direction:
//               SslrSettings::relightHits), rgb; a: 0 no hit, kSslrHitRay (1) a
//               hit of the pixel's own (stochastic) ray, kSslrHitCone (2) a
//               cone trace's hit: the lobe's mean from the lit colour's mip
//               chain, without the ray's noise
//   confidence  [0, 1]: 0 for misses (off screen, sky, too thick, back face)
//   hit         xy = uv of the hit texel's centre (float32: exact at any size)
// RT hand-off: each hybrid ray whose confidence is not at least the
// threshold (NaN included) is appended to ray generation's RT ray list
// (glint/ray_generation_shared.h, kRayList*), after the RT pixels' rays.
// The threshold is one the confidence image holds exactly
// (passes::sslrStoredThreshold), so a reader that finds the stored
// confidence below it knows the ray was handed on and its RT result exists.
#ifndef GLINT_SSLR_SHARED_H
#define GLINT_SSLR_SHARED_H

#include "glint/packing.h"
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
    float confidenceThreshold;  // as stored (passes::sslrStoredThreshold); hybrid rays below it go on to RT
    uint pyramidMips;           // levels of the lit colour's mip chain (below); 0: no cone trace
    float minStepPixels;        // SslrSettings::minStepPixels
    uint flags;                 // kSslrFlag* below
};

// SslrConstants::flags.
GLINT_CONST uint kSslrFlagBlueNoise = 1u;  // start offsets from the blue noise (ray generation's choice)
GLINT_CONST uint kSslrFlagRelight = 2u;    // hits re-lit for the ray's direction (SslrSettings::relightHits)

// radiance.a of a hit (above): the pixel's ray, or the cone trace.
GLINT_CONST float kSslrHitRay = 1.0f;
GLINT_CONST float kSslrHitCone = 2.0f;

// Whether a stored radiance.a (a half float) is the cone trace's hit.
GLINT_FUNC bool sslrHitIsCone(float a) { return a > 0.5f * (kSslrHitRay + kSslrHitCone); }

// The pyramid stops at 2^(kSslrPyramidMaxMips - 1) pixels per texel: wider
// footprints belong to pixels rougher than the cutoff, which trace nothing.
GLINT_CONST uint kSslrPyramidMaxMips = 8u;

// The colour pyramid is the lit colour's mip chain without its level 0
// (the lit colour itself, which the cone trace reads from the G-buffer):
// an image of half the lit colour's size whose mip k is the chain's level
// k + 1, a 2^(k+1) box filter. SslrConstants::pyramidMips counts the
// chain's levels, level 0 included. It is built by two passes of
// pyramid.glsl, each a 16 x 16 workgroup per 32 x 32 texels of its source
// level that writes the five levels below it (2x2 means, reduced in shared
// memory): the first reads the lit colour (levels 1-5), the second level 5
// (levels 6 and 7). Both are dispatched indirectly from the SSLR list's
// args (glint/ray_generation_shared.h, kSslrArgsPyramidOffset), whose z is
// 0, so no group runs, unless ray generation listed a ray that
// cone-traces.
GLINT_CONST uint kSslrPyramidGroupTexels = 32u;
GLINT_CONST uint kSslrPyramidLevelsPerPass = 5u;

// Push constants of pyramid_base.comp and pyramid_down.comp.
struct SslrPyramidConstants {
    uvec2 sourceSize;     // texels of the level read
    uvec2 outputSize[5];  // texels of each written level (kSslrPyramidLevelsPerPass), in binding order
    uint outputs;         // levels written (the rest of the bindings are stand-ins)
    uint pad0;
};

// Texels of a level of a `size` image (Vulkan's mip chain).
GLINT_FUNC uvec2 sslrMipSize(uvec2 size, uint level) {
    return uvec2(max(size.x >> level, 1u), max(size.y >> level, 1u));
}

// The hit image's value for a hit texel: the uv of its centre (float32).
GLINT_FUNC vec2 sslrHitUv(uvec2 texel, uvec2 size) {
    return (vec2(texel) + 0.5f) / vec2(size);
}

// The texel a stored hit uv names: where integrate and the particle trace
// read the reflected point's depth and motion. Floored, clamped into the
// image.
GLINT_FUNC uvec2 sslrHitTexel(vec2 uv, uvec2 size) {
    return min(uvec2(max(floor(uv * vec2(size)), vec2(0.0f))), size - uvec2(1u));
}

// Workgroups of pyramid pass `pass` (0: from the lit colour, 1: from level 5).
GLINT_FUNC uvec2 sslrPyramidGroups(uvec2 size, uint pass) {
    const uvec2 source = sslrMipSize(size, pass * kSslrPyramidLevelsPerPass);
    return uvec2((source.x + kSslrPyramidGroupTexels - 1u) / kSslrPyramidGroupTexels,
                 (source.y + kSslrPyramidGroupTexels - 1u) / kSslrPyramidGroupTexels);
}

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::SslrConstants) == 128);
static_assert(sizeof(glint::shader::SslrPyramidConstants) == 56);
#endif

#endif
