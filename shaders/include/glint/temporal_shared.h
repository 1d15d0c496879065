// Temporal accumulation of the reflections (passes/temporal.cpp,
// shaders/temporal/*): the per-frame constants, shared by GLSL and C++.
// One uniform buffer (scalar layout) serves both of the pass's shaders; it
// holds four matrices, more than the 128 bytes of push constants every
// device guarantees.
//
// History textures (ping-ponged by the graph across frames; their names
// end in the image size, ".<width>x<height>"):
//   temporal.radiance  RGBA16F; rgb: accumulated reflection radiance before
//                      the spatial filter, rounded stochastically to half
//                      floats (passes/temporal.h); a: history length in
//                      frames (0: none)
//   temporal.surface   RGBA16F; x: view depth (clip w) of the pixel's surface,
//                      y: perceptual roughness, zw: octahedral world normal
//                      (glint/packing.h's octEncode, unquantised); x = 0
//                      where nothing reflects. The accumulation writes it
//                      for the next frame's rejection tests; the spatial
//                      filter reads this frame's for its taps.
#ifndef GLINT_TEMPORAL_SHARED_H
#define GLINT_TEMPORAL_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

// Square workgroups over the image, of this side. The accumulation loads
// its clip box's tile (its pixels and a border) into shared memory once per
// workgroup: 16x16 loads 1.56 texels a pixel at the default radius where
// 8x8 loaded 2.25, and took the pass 0.1123 -> 0.1072 ms on the plaza at
// 1080p (H100; 0.1395 -> 0.1338 in the city;
// docs/results/log/06-2026-12-06-b.md, sixth session). The spatial filter
// reads its taps directly and was slower in 16x16 (0.0445 -> 0.0482 ms):
// 8x8.
GLINT_CONST uint kTemporalAccumulateGroupSize = 16u;
GLINT_CONST uint kTemporalSpatialGroupSize = 8u;

// The spatial filter's largest radius in pixels (its loop bound).
GLINT_CONST uint kTemporalMaxSpatialRadius = 4u;
GLINT_CONST uint kTemporalMaxClampRadius = 3u;

// Positions are reconstructed with the jittered matrices the depth was
// rasterised with (exact points); motion uses the unjittered ones, as the
// G-buffer's motion does (glint/gbuffer_shared.h).
struct TemporalFrame {
    mat4 inverseViewProjection;          // this frame, jittered
    mat4 viewProjection;                 // this frame, unjittered
    mat4 previousViewProjection;         // last frame, unjittered
    mat4 previousInverseViewProjection;  // last frame, jittered
    vec4 cameraPosition;                 // xyz, this frame
    vec4 previousCameraPosition;         // xyz, last frame
    uvec2 size;                          // pixels
    uint resetHistory;                   // 1: ignore the history
    uint neighbourhoodClamp;             // 1: variance clipping on
    float maxHistoryFrames;
    float clampGamma;
    float planeTolerance;
    float normalTolerance;               // smallest cosine between history and current normal
    float roughnessTolerance;
    float surfaceMotionRoughnessStart;
    float surfaceMotionRoughnessEnd;
    float maxRadiance;
    uint spatialRadius;                  // 0: the spatial filter is off
    float spatialRoughnessStart;
    float spatialRoughnessEnd;
    float spatialPlaneSigma;
    float spatialNormalPower;
    float spatialRoughnessSigma;
    float spatialRoughnessMax;
    uint hitMotionBound;                 // 1: the reflected points' own motion is bound
    uint clampRadius;                    // the clip box's neighbourhood where rays are shared: (2 r + 1)^2 pixels
    float sharedRayRoughness;            // from this roughness on, quads share rays (above 1: nowhere)
    float environmentRoughness;          // above this roughness the environment alone (above 1: nowhere)
    uint debugOutputs;                   // 1: write the motion and history length images
    uint frame;                          // the frame's index (the history's rounding noise)
    uint spatialNoiseFreeRadius;         // the spatial filter's radius where this frame's radiance is noise-free
    uint oneHistoryCandidate;            // 1: one history lookup at the blended motion (TemporalSettings)
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::TemporalFrame) == 4 * 64 + 2 * 16 + 108);
#endif

#endif
