// Integrate (passes/integrate.h), the body of every variant: one 8x8
// workgroup per tile. Each pixel picks the source of its reflection from
// its class and the confidences of the traces (a follower reads its quad
// leader's traces), writes the radiance, the hit distance and a debug
// colour, and the tile's SSLR hit/miss counts go into its feedback counter.
//
// The variant file defines which inputs exist this frame:
//   GLINT_INTEGRATE_SSLR      1: SSLR radiance, confidence and hits are bound
//   GLINT_INTEGRATE_RT        1: RT radiance and hit distance are bound
//   GLINT_INTEGRATE_FEEDBACK  1: the reprojected and the new counters are bound
// so a frame without one declares and binds nothing for it.
#extension GL_EXT_scalar_block_layout : require

#include "glint/feedback_shared.h"
#include "glint/gbuffer_shared.h"
#include "glint/integrate_shared.h"
#include "glint/ray_generation_shared.h"
#include "glint/sslr_shared.h"
// The prefiltered environment (glint/environment.glsl).
#define GLINT_ENVIRONMENT_BINDING 17
#include "glint/brdf.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D depthTexture;
layout(set = 0, binding = 1) uniform sampler2D normalTexture;
layout(set = 0, binding = 2) uniform sampler2D roughnessMetalTexture;
layout(set = 0, binding = 3, scalar) readonly buffer Constants { IntegrateConstants C; };
layout(set = 0, binding = 4, scalar) readonly buffer Rays { PackedRay rays[]; };
layout(set = 0, binding = 5, scalar) readonly buffer Classes { uint classes[]; };
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D radianceImage;
layout(set = 0, binding = 7, r32f) uniform writeonly image2D hitDistanceImage;
// The source's debug colour, written where C.debugOutputs says so.
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D sourceImage;
// RGBA16F has no required storage format: the context enables
// shaderStorageImageWriteWithoutFormat.
layout(set = 0, binding = 18) uniform writeonly image2D hitMotionImage;
// The G-buffer's motion (pixels to last frame): an SSLR hit's motion.
layout(set = 0, binding = 19) uniform sampler2D motionTexture;
#if GLINT_INTEGRATE_FEEDBACK
layout(set = 0, binding = 9, scalar) readonly buffer Reprojected { uint reprojected[]; };
// The tiles' counters, then the frame's sum of SSLR hits (added to).
layout(set = 0, binding = 10, scalar) buffer Counters { uint counters[]; };
#endif
#if GLINT_INTEGRATE_SSLR
layout(set = 0, binding = 11) uniform sampler2D sslrRadianceTexture;
layout(set = 0, binding = 12) uniform sampler2D sslrConfidenceTexture;
layout(set = 0, binding = 13) uniform sampler2D sslrHitTexture;
#endif
#if GLINT_INTEGRATE_RT
layout(set = 0, binding = 14) uniform sampler2D rtRadianceTexture;
layout(set = 0, binding = 15) uniform sampler2D rtHitDistanceTexture;
// Read where C.rtHitMotionBound says it holds the trace's hit motion.
layout(set = 0, binding = 20) uniform sampler2D rtHitMotionTexture;
#endif

// The particle trace's radiance (passes/particles.h): bound in every
// variant, read only where C.particlesBound says it holds this frame's
// trace (otherwise the pass binds a stand-in texture).
layout(set = 0, binding = 16) uniform sampler2D particlesTexture;

// The largest finite half float: radiance above it would become +Inf in the
// RGBA16F output.
const float kMaxHalf = 65504.0;

shared uint sharedHits;
shared uint sharedMisses;

// By the bits, not isnan/isinf: an implementation may assume floats are
// finite (Vulkan's default float controls) and fold those tests away, and
// NaN or Inf from an upstream pass must not get through.
bool isFinite(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }
bool isFinite(vec2 v) { return isFinite(v.x) && isFinite(v.y); }
bool isFinite(vec3 v) { return isFinite(v.x) && isFinite(v.y) && isFinite(v.z); }

// World position of a pixel position (in pixels) at a reversed-Z depth.
vec3 worldPosition(vec2 pixelPosition, float depth) {
    const vec2 ndc = pixelPosition / vec2(C.size) * 2.0 - 1.0;
    const vec4 world = C.inverseViewProjection * vec4(ndc, depth, 1.0);
    return world.xyz / world.w;
}

// Where the surface seen at pixel position `pixelPosition` (pixels, this
// frame) was last frame: the G-buffer's motion there gives last frame's
// pixel, and the point is taken at the view depth last frame's camera has
// for `position` (exact for motion across the view; the G-buffer keeps no
// depth motion). Returns last frame's position minus this one's.
vec3 surfaceMotion(ivec2 texel, vec3 position) {
    const vec2 motion = texelFetch(motionTexture, texel, 0).xy;
    if (!isFinite(motion)) {
        return vec3(0.0);
    }
    const vec2 previousPixel = vec2(texel) + 0.5 + motion;
    const vec2 ndc = previousPixel / vec2(C.size) * 2.0 - 1.0;
    const vec4 near = C.previousInverseViewProjection * vec4(ndc, 1.0, 1.0);
    const vec3 camera = C.previousCameraPosition.xyz;
    const vec3 dir = near.xyz / near.w - camera;
    const mat4 m = C.previousViewProjection;
    const vec3 wRow = vec3(m[0][3], m[1][3], m[2][3]);
    const float w = dot(wRow, position) + m[3][3];
    const float wPerUnit = dot(wRow, dir);
    if (!(abs(wPerUnit) > 1e-12) || !(w > 0.0)) {
        return vec3(0.0);
    }
    const vec3 previous = camera + dir * (w / wPerUnit);
    const vec3 d = previous - position;
    return isFinite(d) ? d : vec3(0.0);
}

struct Reflection {
    vec3 radiance;
    float reflects;     // kReflects where a surface reflects, kReflectsNoiseFree for a cone trace's hit
    float hitDistance;
    vec3 hitMotion;     // last frame's reflected point minus this frame's
    uint source;
};

Reflection integratePixel(uvec2 pixel) {
    Reflection r;
    r.radiance = vec3(0.0);
    r.reflects = 0.0;
    r.hitDistance = kMissHitDistance;
    r.hitMotion = vec3(0.0);
    r.source = kSourceSky;
    // Every read that depends on nothing else goes out first, so that their
    // latencies overlap rather than add up (this pass is a chain of reads:
    // the class, the ray, its leader's traces, an SSLR hit's surface).
    const uint index = pixel.y * C.size.x + pixel.x;
    const ivec2 p = ivec2(pixel);
    const uint pixelClass = classes[index];
    const PackedRay ray = rays[index];
    const float depth = texelFetch(depthTexture, p, 0).x;
    const vec3 n = texelFetch(normalTexture, p, 0).xyz;
    const float roughness = texelFetch(roughnessMetalTexture, p, 0).x;
    if (pixelClass == kPixelSky || pixelClass >= kPixelClassCount) {
        return r;
    }
    const vec3 position = worldPosition(vec2(pixel) + 0.5, depth);
    const vec3 N = n * inversesqrt(max(dot(n, n), 1e-12));
    const vec3 V = normalize(C.cameraPosition.xyz - position);
    r.reflects = kReflects;
    // The environment map, for env pixels and for traces that found nothing.
    r.radiance = environmentRadiance(C.lighting, reflect(-V, N), roughness);
    r.source = pixelClass == kPixelEnv ? kSourceEnvironment : kSourceFallback;
    if (pixelClass == kPixelEnv) {
        return r;
    }

    // A follower's traces are its quad leader's (glint/ray_generation_shared.h).
    const bool traced = ray.pixelFlags != kNoRay;
    const ivec2 leader = traced ? ivec2(unpackRayPixel(ray.pixelFlags)) : p;
    const bool ownRay = traced && (ray.pixelFlags & kRayReused) == 0u;

    // The ray tracer's and the particle trace's outputs are read beside
    // SSLR's, not after them; the RT ones are used only where SSLR handed
    // the ray on.
#if GLINT_INTEGRATE_RT
    vec4 rtRadianceSample = vec4(0.0);
    float rtDistanceSample = kMissHitDistance;
    vec3 rtMotionSample = vec3(0.0);
    if (traced && (pixelClass == kPixelRt || pixelClass == kPixelHybrid)) {
        rtRadianceSample = texelFetch(rtRadianceTexture, leader, 0);
        rtDistanceSample = texelFetch(rtHitDistanceTexture, leader, 0).x;
        if (C.rtHitMotionBound != 0u) {
            rtMotionSample = texelFetch(rtHitMotionTexture, leader, 0).xyz;
        }
    }
#endif
    const vec4 particles = traced && C.particlesBound != 0u ? texelFetch(particlesTexture, leader, 0) : vec4(0.0);

    float confidence = 0.0;
    vec3 sslrRadiance = vec3(0.0);
    vec2 sslrHitUv = vec2(0.0);
    bool sslrCone = false;  // the hit is the cone trace's (glint/sslr_shared.h, kSslrHitCone)
    // The traces write their rays' pixels only (nothing is cleared): the RT
    // outputs hold this ray's result at RT pixels and at the hybrid pixels
    // SSLR handed on, those whose stored confidence is not at least the
    // threshold (glint/sslr_shared.h).
    bool handedToRt = pixelClass == kPixelRt || pixelClass == kPixelHybrid;
#if GLINT_INTEGRATE_SSLR
    if (traced && (pixelClass == kPixelSslr || pixelClass == kPixelHybrid)) {
        const vec4 radiance = texelFetch(sslrRadianceTexture, leader, 0);
        const float c = texelFetch(sslrConfidenceTexture, leader, 0).x;
        // A probe that renders as rt: SSLR handed every hybrid ray on, and
        // its hits are counted, not used (beyond the reach, kPixelSslr, it
        // still stands alone).
        const bool countsOnly = C.sslrCountsOnly != 0u && pixelClass == kPixelHybrid;
        handedToRt = pixelClass == kPixelHybrid && (countsOnly || !(c >= C.confidenceThreshold));
        const vec2 hitUv = texelFetch(sslrHitTexture, leader, 0).xy;
        // A non-finite result is no hit: the pixel falls through to the
        // next source rather than carrying NaN into temporal accumulation.
        if (radiance.a > 0.5 && isFinite(radiance.rgb) && isFinite(c) && isFinite(hitUv)) {
            confidence = sslrHitConfidence(clamp(c, 0.0, 1.0), C.rtMissesTrusted != 0u);
            sslrRadiance = radiance.rgb;
            sslrHitUv = hitUv;
            sslrCone = sslrHitIsCone(radiance.a);
        }
#if GLINT_INTEGRATE_FEEDBACK
        // The counters count traced rays: leaders only, once each.
        if (ownRay && confidence >= C.confidenceThreshold) {
            atomicAdd(sharedHits, 1u);
        } else if (ownRay) {
            atomicAdd(sharedMisses, 1u);
        }
#endif
        // Counted, not used: the ray tracer's result stands (rt's image).
        if (countsOnly) {
            confidence = 0.0;
        }
    }
#endif

    bool rtTraced = false;
    vec3 rtRadiance = vec3(0.0);
    float rtHitDistance = kMissHitDistance;
    vec3 rtHitMotion = vec3(0.0);
#if GLINT_INTEGRATE_RT
    if (traced && handedToRt) {
        const vec4 radiance = rtRadianceSample;
        const float d = rtDistanceSample;
        rtTraced = radiance.a > 0.5 && isFinite(radiance.rgb);
        rtRadiance = radiance.rgb;
        // A follower takes its leader's ray length: the quad shares one ray,
        // and its origins lie a pixel apart.
        rtHitDistance = isFinite(d) ? clamp(d, 0.0, kMissHitDistance) : kMissHitDistance;
        if (C.rtHitMotionBound != 0u) {
            rtHitMotion = isFinite(rtMotionSample) ? rtMotionSample : vec3(0.0);
        }
    }
#endif

    // glint/integrate_shared.h's chooseReflectionTrace, which the particle
    // trace shares.
    const uint trace = chooseReflectionTrace(confidence, C.confidenceThreshold, rtTraced,
                                             C.rtMissesTrusted != 0u || rtHitDistance < kMissHitDistance);
    if (trace == kTraceRt) {
        r.radiance = rtRadiance;
        r.hitDistance = rtHitDistance;
        r.hitMotion = rtHitDistance < kMissHitDistance ? rtHitMotion : vec3(0.0);
        r.source = kSourceRt;
    }
    if (trace == kTraceSslr) {
        r.radiance = sslrRadiance;
        r.source = kSourceSslr;
        if (sslrCone) {
            r.reflects = kReflectsNoiseFree;
        }
        // The reflected point is the surface the depth buffer holds at the
        // hit texel, measured from this pixel's own surface.
        const ivec2 hitTexel = ivec2(sslrHitTexel(sslrHitUv, C.size));
        const float hitDepth = texelFetch(depthTexture, hitTexel, 0).x;
        if (hitDepth > 0.0) {
            const vec3 hitPosition = worldPosition(vec2(hitTexel) + 0.5, hitDepth);
            r.hitDistance = min(length(hitPosition - position), kMissHitDistance);
            r.hitMotion = surfaceMotion(hitTexel, hitPosition);
        }
    }
    // Particles between the surface and what it reflects (the leader's
    // trace, premultiplied, a = coverage) in front of the reflection. The
    // hit distance stays the reflected surface's: particles are soft and
    // partly transparent, and temporal reprojection follows what lies
    // behind them.
    if (traced && C.particlesBound != 0u) {
        if (isFinite(particles.rgb) && isFinite(particles.a)) {
            const float coverage = clamp(particles.a, 0.0, 1.0);
            r.radiance = max(particles.rgb, vec3(0.0)) + (1.0 - coverage) * r.radiance;
            // The particles come from the pixel's own (stochastic) ray.
            if (coverage > 0.0) {
                r.reflects = kReflects;
            }
        }
    }
    return r;
}

void main() {
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    const uint lane = gl_LocalInvocationIndex;
    if (lane == 0u) {
        sharedHits = 0u;
        sharedMisses = 0u;
    }
    barrier();

    if (pixel.x < C.size.x && pixel.y < C.size.y) {
        const Reflection r = integratePixel(pixel);
        const vec3 radiance = clamp(r.radiance, vec3(0.0), vec3(kMaxHalf));
        const bool finite = isFinite(radiance) && isFinite(r.hitDistance) && isFinite(r.hitMotion);
        const ivec2 p = ivec2(pixel);
        imageStore(radianceImage, p, vec4(finite ? radiance : vec3(0.0), r.reflects));
        imageStore(hitDistanceImage, p, vec4(finite ? r.hitDistance : kMissHitDistance));
        imageStore(hitMotionImage, p, vec4(finite ? r.hitMotion : vec3(0.0), 0.0));
        if (C.debugOutputs != 0u) {
            imageStore(sourceImage, p, integrateSourceColour(r.source));
        }
    }
    barrier();

#if GLINT_INTEGRATE_FEEDBACK
    // This frame's counts and, rotated into the previous half, the counts
    // the feedback pass carried here from last frame (glint/feedback_shared.h).
    // length(): the buffers are bound whole, whatever the image's size.
    if (lane == 0u) {
        const uint tile = gl_WorkGroupID.y * C.tiles.x + gl_WorkGroupID.x;
        const uint carried = tile < uint(reprojected.length()) ? reprojected[tile] : 0u;
        if (tile < uint(counters.length())) {
            counters[tile] = rotateFeedback(carried, sharedHits, sharedMisses);
        }
        // The frame's sum, which next frame's feedback compares with
        // minFrameHits: once it holds that many the answer is known, and
        // the tiles stop adding (one atomic on one word per tile would
        // queue up behind each other).
        const uint total = C.tiles.x * C.tiles.y;
        if (sharedHits != 0u && total < uint(counters.length()) &&
            counters[total] < kFeedbackFrameHitsStart + C.minFrameHits) {
            atomicAdd(counters[total], sharedHits);
        }
    }
#endif
}
