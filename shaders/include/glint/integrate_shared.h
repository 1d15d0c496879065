// Integrate (passes/integrate.cpp, shaders/integrate/*): the per-frame
// constants and the sources a pixel's reflection can come from, shared by
// GLSL and C++. Buffers use scalar layout.
//
// Outputs, per pixel:
//   radiance     rgb: the radiance arriving along the pixel's reflection;
//                a: 0 for the sky, kReflectsNoiseFree (2) where the
//                reflection is the SSLR cone trace's hit alone (no ray's
//                noise: the colour pyramid holds the lobe's blur, and the
//                spatial filter leaves it as it is,
//                TemporalSettings::spatialNoiseFreeRadius), kReflects (1)
//                elsewhere a surface reflects
//   hitDistance  world distance from the surface to the reflected point;
//                kMissHitDistance (glint/ray_generation_shared.h) for the
//                environment, misses and the sky
//   hitMotion    xyz: where the reflected point was last frame minus where
//                it is (world units; zero where it is at infinity)
//   sourceDebug  integrateSourceColour(source) (debug view "reflection_source")
//   counters     one u32 per 8x8 tile (glint/feedback_shared.h)
#ifndef GLINT_INTEGRATE_SHARED_H
#define GLINT_INTEGRATE_SHARED_H

#include "glint/shared.h"
#include "glint/gbuffer_shared.h"  // SceneLighting
#include "glint/packing.h"         // GLINT_FUNC

GLINT_BEGIN

// radiance.a where a surface reflects (above).
GLINT_CONST float kReflects = 1.0f;
GLINT_CONST float kReflectsNoiseFree = 2.0f;

// Whether a stored radiance.a (any float format) marks a noise-free reflection.
GLINT_FUNC bool reflectsNoiseFree(float a) { return a > 0.5f * (kReflects + kReflectsNoiseFree); }

// Where a pixel's reflection came from.
//   Sky          nothing reflects: no surface
//   Environment  an env-class pixel (rougher than the tracing cutoff)
//   Sslr         the screen-space hit
//   Rt           the ray-traced hit (or its miss: the true environment)
//   Fallback     a traced pixel whose traces found nothing usable: the
//                environment map
GLINT_CONST uint kSourceSky = 0u;
GLINT_CONST uint kSourceEnvironment = 1u;
GLINT_CONST uint kSourceSslr = 2u;
GLINT_CONST uint kSourceRt = 3u;
GLINT_CONST uint kSourceFallback = 4u;
GLINT_CONST uint kSourceCount = 5u;

// Debug colours: grey environment, blue SSLR, red RT, yellow fallback,
// black sky. Every channel is a multiple of 0.2, so 255 x it lies far from
// a rounding boundary and the RGBA8 value is the same on every device.
GLINT_FUNC vec4 integrateSourceColour(uint source) {
    if (source == kSourceEnvironment) return vec4(0.6f, 0.6f, 0.6f, 1.0f);
    if (source == kSourceSslr) return vec4(0.2f, 0.4f, 1.0f, 1.0f);
    if (source == kSourceRt) return vec4(1.0f, 0.2f, 0.2f, 1.0f);
    if (source == kSourceFallback) return vec4(1.0f, 0.8f, 0.2f, 1.0f);
    return vec4(0.0f, 0.0f, 0.0f, 1.0f);
}

// Which trace a traced pixel's reflection takes (the Far Cry 6 talk):
// full SSLR confidence, SSLR alone; below it the more confident trace: a
// ray-traced result is fully confident (its miss is the true environment),
// so RT wins where it traced; else whatever SSLR found; else the
// environment map. One definition: integrate picks its source with it and
// the particle trace (passes/particles.h) its ray's length, so particles
// are composited exactly up to the surface the reflection shows.
// rtTrusted: the ray-traced result may override a partial SSLR hit. A miss
// is not, while the BVH is still building objects in range (their rays pass
// through where they stand; scene::BvhPlan::complete): SSLR is the fallback
// while the BVH builds (the Far Cry 6 talk).
GLINT_CONST uint kTraceNone = 0u;
GLINT_CONST uint kTraceSslr = 1u;
GLINT_CONST uint kTraceRt = 2u;

// While the BVH builds, an SSLR hit the trace gave no confidence (near the
// screen's border, near its thickness, a back face) still ranks above a
// ray-traced miss: it is at least the reflection of something on screen.
GLINT_CONST float kSslrFallbackConfidence = 1.0f / 1024.0f;

// The confidence integrate and the particle trace give an SSLR hit.
GLINT_FUNC float sslrHitConfidence(float stored, bool rtMissesTrusted) {
    return rtMissesTrusted ? stored : max(stored, kSslrFallbackConfidence);
}

GLINT_FUNC uint chooseReflectionTrace(float sslrConfidence, float confidenceThreshold, bool rtTraced, bool rtTrusted) {
    if (sslrConfidence >= confidenceThreshold) return kTraceSslr;
    if (rtTraced && (rtTrusted || !(sslrConfidence > 0.0f))) return kTraceRt;
    if (sslrConfidence > 0.0f) return kTraceSslr;
    return kTraceNone;
}

// Per-frame constants (a storage buffer: with the lighting they outgrow the
// 128 bytes of push constants every device has; 504 bytes).
struct IntegrateConstants {
    mat4 inverseViewProjection;          // unjittered, the G-buffer's camera
    // Last frame's unjittered matrices and position: where an SSLR hit was
    // last frame (its G-buffer motion) becomes a world point.
    mat4 previousViewProjection;
    mat4 previousInverseViewProjection;
    vec4 cameraPosition;
    vec4 previousCameraPosition;
    SceneLighting lighting;
    uvec2 size;                  // pixels
    uvec2 tiles;                 // 8x8 tiles in x and y
    float confidenceThreshold;   // SSLR confidence that counts as a hit
    uint particlesBound;         // 1: composite the particle trace (passes/particles.h) over the reflection
    uint rtMissesTrusted;        // 0 while the BVH builds objects in range (IntegrateSettings::rtMissesTrusted)
    uint rtHitMotionBound;       // 1: the ray tracer's hit motion is bound (else its hits count as still)
    // The feedback's minFrameHits (passes/feedback.h): tiles stop adding
    // their hits to the frame's sum once it holds this many.
    uint minFrameHits;
    // 1: SSLR's hits are counted, not used (FeedbackSettings::
    // probesRenderAsRt; SSLR handed every ray on).
    uint sslrCountsOnly;
    // 1: write the source debug colour (IntegrateInputs::debugOutputs).
    uint debugOutputs;
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::IntegrateConstants) == 508);
#endif

#endif
