// The ray-traced hits and lighting pass (passes/rt_trace.cpp,
// shaders/rt_trace/*): constants and the scene constants block, shared by
// GLSL and C++. Buffers use scalar layout.
//
// Inputs: the RT ray list (glint/ray_generation_shared.h, kRayList*): each
// entry's ray leaves the G-buffer surface at the pixel its pixelFlags name,
// along unpackRayDirection(direction).
// Outputs, per pixel (every pixel no listed ray names keeps the cleared 0):
//   radiance     rgb: radiance arriving along the ray (the hit lit by
//                glint/brdf.glsl's shadeSurface, or environmentRadiance on
//                a miss); a = 1 where a ray was traced
//   hitDistance  world distance from the ray's origin to the hit;
//                kMissHitDistance on a miss
#ifndef GLINT_RT_TRACE_SHARED_H
#define GLINT_RT_TRACE_SHARED_H

#include "glint/gbuffer_shared.h"
#include "glint/shared.h"

GLINT_BEGIN

// ---------------------------------------------------------------------------
// Robust ray origins
// ---------------------------------------------------------------------------
// Wächter and Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection" (Ray Tracing Gems, chapter 6): move the origin along
// the surface normal by a distance that grows with the magnitude of the
// position, because float error grows with it (a fixed epsilon is too
// large near the origin and too small far from it). Their offset is a
// number of ULPs of each coordinate, for a point computed from the
// triangle's own vertices. Here the origin is reconstructed from a depth
// buffer through the inverse view-projection, which mixes all coordinates
// with the camera's translation, so the offset is counted in ULPs of the
// largest coordinate of the point or the camera; and the depth itself errs
// along the view ray, by an amount relative to the distance:
//   offset = kRtOriginUlps * ulp(max |coordinate|)
//          + distance * (kRtDistanceRelativeError + rasterErrorPerDistance)
// rasterErrorPerDistance (RtTraceConstants) is the rasteriser's share:
// vertices snap to the device's sub-pixel grid (subPixelPrecisionBits),
// which moves a triangle's depth plane by up to half a grid step in screen
// space, i.e. a point at distance d by up to d * pixelAngle * 2^-(bits+1)
// across the view ray, which for a surface seen at a grazing angle is
// nearly along its normal. Measured on an H100 (8 bits): the floor of
// tests/gpu/rt_trace_test.cpp 1/1560 pixel off, 7e-5 units below itself
// at 3.8 units; the offset takes twice the bound. Shadow rays leave their
// hit point the same way, the distance being the hit's t and the raster
// share zero. Below kRtOriginMinimum (Wächter and Binder's 1/32 region
// near the origin, where ULPs vanish) the ULP term uses kRtOriginMinimum.

// Wächter and Binder move by 256 ULPs (their int_scale); at x, z = 1e4
// that is 0.25 units. Measured here (tests/gpu/rt_trace_test.cpp: grazing
// rays leaving a tilted plane at x, z = 1e4, where this term dominates), a
// 64th of 32 ULPs lets 2 of ~1200 rays hit their own plane on lavapipe and
// a 16th none: 32 ULPs keep a margin of 16 and cost 2 mm at 1000 units
// from the origin.
GLINT_CONST float kRtOriginUlps = 32.0f;
// The depth's storage (D32 float), its interpolation and the
// reconstruction each err by a few ULPs of the distance (2^-23 each).
GLINT_CONST float kRtDistanceRelativeError = 1.0f / 262144.0f;
GLINT_CONST float kRtOriginMinimum = 1.0f / 32.0f;

// Invocations per workgroup of the ray query backend: the RT list's group
// size, so the list's dispatch command (word 0) fits it.
GLINT_CONST uint kRtTraceGroupSize = 64u;

// Scene constants of one frame (360 bytes: more than push constants
// guarantee, so a small buffer the pass fills with vkCmdUpdateBuffer).
struct RtTraceConstants {
    mat4 inverseViewProjection;  // of the G-buffer's rasterisation (jittered): its depth -> world
    vec4 cameraPosition;         // xyz
    SceneLighting lighting;      // as the G-buffer lit its surfaces
    uvec2 size;                  // G-buffer pixels
    float maxDistance;           // ray length at roughness 0
    float shortRangeRoughness;   // roughness at which the length reaches shortRangeFraction
    float shortRangeFraction;    // of maxDistance
    float shadowDistance;        // length of shadow rays
    float originOffsetScale;     // multiplies the robust origin offset (1: as above)
    float rasterErrorPerDistance;  // pixel angle * 2^-subPixelPrecisionBits (robust origins, above)
    uint shadows;                // 1: trace a shadow ray towards the sun
    uint instanceMask;           // cull mask of every ray (glint/packing.h kInstanceMask*)
    uint alphaTest;              // 1: rays pass through alpha-tested cut-outs; 0: every triangle opaque
    // 1: a hit the shadow map covers (inside it, nearer the camera than
    // shadow.fadeStart) takes the sun's visibility from the map, filtered
    // as the G-buffer's (glint/sun_shadow.glsl); other hits trace their
    // shadow ray. 0: every hit traces one.
    uint shadowMapAtHits;
    GBufferShadow shadow;        // the G-buffer's shadow map fit this frame
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::RtTraceConstants) == 364 + 4 + 112);
#endif

#endif
