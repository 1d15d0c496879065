#version 460
// Reflection motion and temporal accumulation (passes/temporal.h), one
// thread per pixel:
//   1. reflection motion: the reflected (virtual) point lies hitDistance
//      behind the surface along the view ray; projected with last frame's
//      view-projection it says where last frame saw this reflection
//      (misses: the view direction alone, a point at infinity); where the
//      reflected object itself moved (hitMotionTexture), last frame's
//      virtual point is the mirror image of where it was. Rough
//      reflections are blurry and follow the surface instead: the two
//      motions blend by roughness;
//   2. history at the blended motion (at the surface's where that finds
//      nothing; with TemporalSettings::oneHistoryCandidate off, at both
//      motions, the two histories blended), bilinear over four taps, each
//      tap kept only if last frame's surface there lies on this pixel's
//      plane with a similar normal and roughness (disocclusion and history
//      rejection; not where the pixel reflects the environment alone, whose
//      radiance has no noise and follows the normal: the clip box bounds
//      its ghost);
//   3. sanitise this frame's radiance: NaN and Inf are dropped (the pixel
//      takes its neighbours' mean), the rest is clamped to [0, maxRadiance]
//      so nothing a half float cannot hold reaches the history;
//   4. variance clipping of the history in YCoCg over the (2 r + 1)^2
//      neighbourhood (r = clampRadius where quads share rays, else 1: 3x3)
//      (Salvi, "An Excursion in Temporal Supersampling", GDC 2016; YCoCg,
//      clipping towards the mean and the luma-compressed space as Karis,
//      "High Quality Temporal Supersampling", SIGGRAPH 2014);
//   5. an exponential moving average with weight 1 / history length, the
//      length capped at maxHistoryFrames, stored in half floats rounded
//      stochastically (passes/temporal.h's kTemporalRadianceHistoryFormat).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/packing.h"
#include "glint/ray_generation_shared.h"
#include "glint/sampling.glsl"
#include "glint/temporal_shared.h"
#include "temporal_common.glsl"

layout(local_size_x = kTemporalAccumulateGroupSize, local_size_y = kTemporalAccumulateGroupSize) in;

layout(set = 0, binding = 1) uniform sampler2D depthTexture;
layout(set = 0, binding = 2) uniform sampler2D normalTexture;
layout(set = 0, binding = 3) uniform sampler2D roughnessMetalTexture;
layout(set = 0, binding = 4) uniform sampler2D motionTexture;
layout(set = 0, binding = 5) uniform sampler2D radianceTexture;
layout(set = 0, binding = 6) uniform sampler2D hitDistanceTexture;
layout(set = 0, binding = 7) uniform sampler2D previousRadianceTexture;
layout(set = 0, binding = 8) uniform sampler2D previousSurfaceTexture;
layout(set = 0, binding = 9, rgba16f) uniform writeonly image2D radianceHistory;
layout(set = 0, binding = 10, rgba16f) uniform writeonly image2D surfaceHistory;
// RG16F and R16F are not among the formats every device can store with a
// format qualifier; the context enables shaderStorageImageWriteWithoutFormat.
layout(set = 0, binding = 11) uniform writeonly image2D motionImage;
layout(set = 0, binding = 12) uniform writeonly image2D lengthImage;
// xyz: where the reflected point was last frame minus where it is (world;
// passes/integrate.h's hitMotion). Read where frame.hitMotionBound says so.
layout(set = 0, binding = 13) uniform sampler2D hitMotionTexture;

vec3 rgbToYCoCg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 yCoCgToRgb(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// The neighbourhood statistics and the clip work on c / (1 + luma(c))
// (Karis 2014's "tonemap before resolve"): a firefly counts as at most 1
// there, so one huge sample cannot drag its neighbours' boxes, and the
// histories clipped into them, towards itself.
float luma(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
vec3 compress(vec3 c) { return c / (1.0 + luma(c)); }
vec3 expand(vec3 c) { return c / max(1.0 - luma(c), 1e-4); }

// This frame's radiance at a texel, or false where it reflects nothing or
// is not finite.
bool currentRadiance(ivec2 texel, out vec3 radiance) {
    const vec4 r = texelFetch(radianceTexture, texel, 0);
    radiance = vec3(0.0);
    if (!(r.a > 0.0) || !isFinite(r.rgb)) {
        return false;
    }
    radiance = clamp(r.rgb, vec3(0.0), vec3(frame.maxRadiance));
    return true;
}

struct Pixel {
    ivec2 texel;
    vec3 position;
    vec3 normal;
    float roughness;
    float w;
    bool environment;  // rougher than frame.environmentRoughness: the environment map alone
    // The plane test's terms (not for environment pixels;
    // temporal_common.glsl's planeDistanceSteps, last frame's camera): a
    // history texel t at last frame's view depth w_t lies
    // planeOffset + w_t (planeStep.x + dx planeStep.y + dy planeStep.z)
    // off this pixel's plane, with (dx, dy) = t - texel.
    float planeOffset;
    vec3 planeStep;
};

// One history texel, or false where last frame saw another surface there:
// off the plane (by more than planeTolerance of the view depth: a
// disocclusion, or an object that moved across depth), turned away, of
// another roughness, or holding nothing usable. An environment pixel skips
// the surface tests (passes/temporal.h, TemporalInputs::environmentRoughness).
bool historyTap(ivec2 texel, Pixel px, out vec4 radiance) {
    radiance = vec4(0.0);
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, ivec2(frame.size)))) {
        return false;
    }
    if (px.environment) {
        // A history length says a surface was there (writeNothing stores
        // none): its radiance alone is read.
        radiance = texelFetch(previousRadianceTexture, texel, 0);
        return radiance.a >= 1.0 && isFinite(radiance.rgb);
    }
    const vec4 surface = texelFetch(previousSurfaceTexture, texel, 0);
    radiance = texelFetch(previousRadianceTexture, texel, 0);
    if (!(surface.x > 0.0) || !(radiance.a >= 1.0) || !isFinite(radiance.rgb) || !isFinite(surface.yzw)) {
        return false;
    }
    const vec2 d = vec2(texel - px.texel);
    const float offPlane = px.planeOffset + surface.x * (px.planeStep.x + d.x * px.planeStep.y + d.y * px.planeStep.z);
    if (!(abs(offPlane) <= frame.planeTolerance * px.w)) {
        return false;
    }
    const vec3 n = octDecode(clamp(surface.zw, vec2(-1.0), vec2(1.0)));
    if (dot(n, px.normal) < frame.normalTolerance) {
        return false;
    }
    return abs(surface.y - px.roughness) <= frame.roughnessTolerance;
}

// Bilinear history at a continuous position (pixels), over the valid taps
// only (renormalised): false when less than a hundredth of the footprint is
// valid (as SVGF's reprojection does, Schied et al., HPG 2017).
bool sampleHistory(vec2 position, Pixel px, out vec3 radiance, out float historyLength) {
    radiance = vec3(0.0);
    historyLength = 0.0;
    if (!isFinite(position)) {
        return false;
    }
    // Far outside the image: nothing to find, and the ivec conversion
    // below must stay in range.
    const vec2 size = vec2(frame.size);
    if (any(lessThan(position, vec2(-1.0))) || any(greaterThan(position, size + 1.0))) {
        return false;
    }
    const vec2 base = floor(position - 0.5);
    const vec2 f = position - 0.5 - base;
    float weightSum = 0.0;
    for (int i = 0; i < 4; ++i) {
        const ivec2 offset = ivec2(i & 1, i >> 1);
        const float weight = (offset.x == 1 ? f.x : 1.0 - f.x) * (offset.y == 1 ? f.y : 1.0 - f.y);
        vec4 tap;
        if (weight > 0.0 && historyTap(ivec2(base) + offset, px, tap)) {
            radiance += weight * tap.rgb;
            historyLength += weight * tap.a;
            weightSum += weight;
        }
    }
    if (weightSum < 0.01) {
        return false;
    }
    radiance /= weightSum;
    historyLength /= weightSum;
    return true;
}

// One of the two half floats around x (finite, in [0, 65504]): the upper
// with probability (x - lower) / (upper - lower) for u uniform in [0, 1),
// so the mean is x, where rounding to nearest (or towards zero) would stall
// an average whose steps are below half a half float's step. The result is
// a half float, which the RGBA16F store keeps exactly whatever its
// rounding. From the bits (a float32 whose 13 low mantissa bits are zero is
// a half float in the half's normal range; the next one up is 2^13 bits
// on), not through packHalf2x16 and back: on lavapipe that round trip came
// back as x itself (the history was bit-identical to a plain store's), as
// if folded away. Below the half's normal range (2^-14) the store rounds
// the result as it will: an error below 2^-23.
float roundToHalf(float x, float u) {
    const uint lowerBits = floatBitsToUint(x) & ~0x1FFFu;
    const float lower = uintBitsToFloat(lowerBits);
    const float upper = min(uintBitsToFloat(lowerBits + 0x2000u), 65504.0);
    return upper > lower && u * (upper - lower) < x - lower ? upper : lower;
}

// 0 below `start`, 1 from `end`, smooth between (smoothstep is undefined
// for start >= end).
float ramp(float x, float start, float end) {
    if (x <= start) return 0.0;
    if (x >= end) return 1.0;
    return smoothstep(start, end, x);
}

// The reflection motion and history length images, for their debug views
// (passes/temporal.h, TemporalInputs::debugOutputs).
void writeDebugOutputs(ivec2 p, vec2 motion, float historyLength) {
    if (frame.debugOutputs != 0u) {
        imageStore(motionImage, p, vec4(motion, 0.0, 0.0));
        imageStore(lengthImage, p, vec4(historyLength));
    }
}

void writeNothing(ivec2 p, vec2 motion) {
    imageStore(radianceHistory, p, vec4(0.0));
    imageStore(surfaceHistory, p, vec4(0.0));
    writeDebugOutputs(p, motion, 0.0);
}

// The workgroup's pixels and a border of the clip box's radius around them
// (frame.clampRadius, at most kTemporalMaxClampRadius), as the clip box's
// statistics want them: YCoCg of the compressed radiance, w = 1 where this
// frame's radiance there is valid. Loaded once per workgroup: a 5x5 box
// would otherwise fetch and convert every texel 25 times. The array holds
// the largest border; only the frame's is loaded (400 texels for the 256
// pixels of a 16x16 workgroup at the default radius 2, instead of 484),
// and no pixel reads beyond it.
const int kTile = int(kTemporalAccumulateGroupSize) + 2 * int(kTemporalMaxClampRadius);
shared vec4 tile[kTile * kTile];

void loadTile() {
    const int border = int(min(frame.clampRadius, kTemporalMaxClampRadius));
    const int side = int(kTemporalAccumulateGroupSize) + 2 * border;
    const int skip = int(kTemporalMaxClampRadius) - border;  // the array's unused rows and columns
    const ivec2 origin = ivec2(gl_WorkGroupID.xy) * int(kTemporalAccumulateGroupSize) - border;
    const int invocations = int(kTemporalAccumulateGroupSize * kTemporalAccumulateGroupSize);
    for (int i = int(gl_LocalInvocationIndex); i < side * side; i += invocations) {
        const ivec2 offset = ivec2(i % side, i / side);
        const ivec2 q = origin + offset;
        vec4 entry = vec4(0.0);
        vec3 c;
        if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, ivec2(frame.size))) && currentRadiance(q, c)) {
            entry = vec4(rgbToYCoCg(compress(c)), 1.0);
        }
        tile[(offset.y + skip) * kTile + offset.x + skip] = entry;
    }
    barrier();
}

// The clip box's sums over the (2 r + 1)^2 tile entries around this pixel.
void boxSums(const int r, inout vec3 sum, inout vec3 sumSquares, inout float count) {
    const ivec2 local = ivec2(gl_LocalInvocationID.xy) + int(kTemporalMaxClampRadius);
    for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
            const vec4 entry = tile[(local.y + dy) * kTile + local.x + dx];
            sum += entry.xyz;
            sumSquares += entry.xyz * entry.xyz;
            count += entry.w;
        }
    }
}

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    // This pixel's own reads go out before the tile's and its barrier, so
    // that their latencies overlap (the edge groups' outside invocations
    // read the last texel and write nothing).
    const ivec2 texel = min(p, ivec2(frame.size) - 1);
    vec2 surfaceMotion = texelFetch(motionTexture, texel, 0).xy;
    const float depth = texelFetch(depthTexture, texel, 0).x;
    const vec4 normalSample = texelFetch(normalTexture, texel, 0);
    const float reflectMask = texelFetch(radianceTexture, texel, 0).a;
    const float roughness = texelFetch(roughnessMetalTexture, texel, 0).r;
    const float hitDistance = texelFetch(hitDistanceTexture, texel, 0).x;
    loadTile();
    if (p.x >= int(frame.size.x) || p.y >= int(frame.size.y)) {
        return;
    }
    const vec2 size = vec2(frame.size);
    const vec2 centre = vec2(p) + 0.5;
    if (!isFinite(surfaceMotion)) {
        surfaceMotion = vec2(0.0);
    }
    if (!(depth > 0.0) || !(normalSample.w > 0.0) || !(reflectMask > 0.0) || !isFinite(normalSample.xyz)) {
        writeNothing(p, surfaceMotion);
        return;
    }

    Pixel px;
    px.position = worldPosition(frame.inverseViewProjection, centre, size, depth);
    px.normal = normalize(normalSample.xyz);
    px.roughness = roughness;
    px.w = viewDepth(frame.viewProjection, px.position);
    px.environment = px.roughness > frame.environmentRoughness;
    px.texel = p;
    px.planeOffset = 0.0;
    px.planeStep = vec3(0.0);
    if (!px.environment) {
        px.planeOffset = dot(frame.previousCameraPosition.xyz - px.position, px.normal);
        px.planeStep = planeDistanceSteps(frame.previousInverseViewProjection, frame.previousViewProjection,
                                          frame.previousCameraPosition.xyz, centre, px.normal);
    }

    // 1. Reflection motion through the virtual point.
    const vec3 viewDir = normalize(px.position - frame.cameraPosition.xyz);
    vec4 clip;
    if (!(hitDistance < kMissHitDistance)) {
        // At infinity (NaN lands here too): only the direction reprojects.
        clip = frame.previousViewProjection * vec4(viewDir, 0.0);
    } else {
        // The virtual point is the mirror image of the reflected one in the
        // surface's plane; a reflected point that moved by m moved its
        // image by m mirrored in that plane.
        vec3 virtualPoint = px.position + viewDir * max(hitDistance, 0.0);
        if (frame.hitMotionBound != 0u) {
            const vec3 m = texelFetch(hitMotionTexture, p, 0).xyz;
            if (isFinite(m)) {
                virtualPoint += reflect(m, px.normal);
            }
        }
        clip = frame.previousViewProjection * vec4(virtualPoint, 1.0);
    }
    // Motion runs between unjittered positions (the G-buffer's
    // convention); every point of the view ray, the virtual one included,
    // has the surface's unjittered position this frame.
    const vec4 currentClip = frame.viewProjection * vec4(px.position, 1.0);
    const vec2 unjittered = (currentClip.xy / currentClip.w * 0.5 + 0.5) * size;
    // Behind last frame's camera the virtual point has no pixel.
    const bool virtualValid = clip.w > 1e-6;
    const vec2 virtualMotion = virtualValid ? (clip.xy / clip.w * 0.5 + 0.5) * size - unjittered : surfaceMotion;
    const float surfaceWeight =
        virtualValid ? ramp(px.roughness, frame.surfaceMotionRoughnessStart, frame.surfaceMotionRoughnessEnd) : 1.0;
    const vec2 reflectionMotion = mix(virtualMotion, surfaceMotion, surfaceWeight);

    // 2. History at the blended motion, the surface's where that finds
    // nothing (frame.oneHistoryCandidate, the default); without it, at both
    // candidates blended by roughness, either one alone where the other is
    // rejected.
    vec3 history = vec3(0.0);
    float historyLength = 0.0;
    bool hasHistory = false;
    if (frame.resetHistory == 0u && frame.oneHistoryCandidate != 0u) {
        // Every pixel the same way (no warp runs both branches): the
        // blended motion is the virtual point's for a mirror and the
        // surface's for a rough pixel, so only glossy pixels read less.
        float blendedLength = 0.0;
        hasHistory = sampleHistory(centre + reflectionMotion, px, history, blendedLength);
        if (!hasHistory && distance(reflectionMotion, surfaceMotion) >= 1e-3) {
            hasHistory = sampleHistory(centre + surfaceMotion, px, history, blendedLength);
        }
        historyLength = hasHistory ? max(floor(blendedLength + 0.5), 1.0) : 0.0;
    } else if (frame.resetHistory == 0u) {
        vec3 virtualHistory = vec3(0.0), surfaceHistoryRadiance = vec3(0.0);
        float virtualLength = 0.0, surfaceLength = 0.0;
        bool virtualOk = false, surfaceOk = false;
        if (surfaceWeight < 1.0) {
            virtualOk = sampleHistory(centre + virtualMotion, px, virtualHistory, virtualLength);
        }
        if (surfaceWeight > 0.0 || !virtualOk) {
            if (surfaceWeight < 1.0 && distance(virtualMotion, surfaceMotion) < 1e-3) {
                // The same taps (a static camera, a mirror at rest).
                surfaceOk = virtualOk;
                surfaceHistoryRadiance = virtualHistory;
                surfaceLength = virtualLength;
            } else {
                surfaceOk = sampleHistory(centre + surfaceMotion, px, surfaceHistoryRadiance, surfaceLength);
            }
        }
        float wv = virtualOk ? 1.0 - surfaceWeight : 0.0;
        float ws = surfaceOk ? surfaceWeight : 0.0;
        if (virtualOk && !surfaceOk) wv = 1.0;
        if (surfaceOk && !virtualOk) ws = 1.0;
        if (wv + ws > 0.0) {
            hasHistory = true;
            history = (wv * virtualHistory + ws * surfaceHistoryRadiance) / (wv + ws);
            // A count of frames: blending taps may leave it a hair off an
            // integer, which a half-float store rounding towards zero (as
            // Vulkan allows) would turn into a frame less every frame.
            historyLength = max(floor((wv * virtualLength + ws * surfaceLength) / (wv + ws) + 0.5), 1.0);
        }
    }

    // 3. This frame's radiance and its neighbourhood's statistics, after
    // the history: the history taps' reads above go out together, and the
    // statistics (mean, sigma, count, this frame's radiance) would be live
    // across them. On an H100, 60 registers with the statistics first (at
    // most half the warps an SM holds), 47 after: the pass 0.1072 -> 0.0975
    // ms on the plaza at 1080p.
    vec3 current;
    bool hasCurrent = currentRadiance(p, current);
    vec3 sum = vec3(0.0);
    vec3 sumSquares = vec3(0.0);
    float count = 0.0;
    // The wide box only where neighbouring pixels share rays; 3x3 where
    // each has its own, and where none is traced (the environment).
    const bool sharedRays = px.roughness >= frame.sharedRayRoughness && !px.environment;
    const uint radius = sharedRays ? frame.clampRadius : min(frame.clampRadius, 1u);
    const int r = int(min(radius, kTemporalMaxClampRadius));
    // Literal radii for the two boxes in use: each unrolls.
    if (r == 1) {
        boxSums(1, sum, sumSquares, count);
    } else if (r == 2) {
        boxSums(2, sum, sumSquares, count);
    } else {
        boxSums(r, sum, sumSquares, count);
    }
    const vec3 mean = count > 0.0 ? sum / count : vec3(0.0);
    const vec3 sigma = count > 0.0 ? sqrt(max(sumSquares / count - mean * mean, vec3(0.0))) : vec3(0.0);
    if (!hasCurrent && count > 0.0) {
        // A NaN or Inf sample: its neighbours' mean stands in for it.
        current = clamp(expand(max(yCoCgToRgb(mean), vec3(0.0))), vec3(0.0), vec3(frame.maxRadiance));
        hasCurrent = true;
    }

    // 4. Variance clipping: pull the history along the line to the mean
    // until it lies inside mean +- gamma sigma.
    if (hasHistory && frame.neighbourhoodClamp != 0u && count > 0.0) {
        const vec3 extent = max(frame.clampGamma * sigma, vec3(1e-4));
        const vec3 offset = rgbToYCoCg(compress(history)) - mean;
        const vec3 units = abs(offset / extent);
        const float m = max(units.x, max(units.y, units.z));
        if (m > 1.0) {
            history = clamp(expand(max(yCoCgToRgb(mean + offset / m), vec3(0.0))), vec3(0.0),
                            vec3(frame.maxRadiance));
        }
    }

    // 5. Accumulate.
    vec3 result;
    float newLength;
    if (!hasCurrent) {
        // Nothing finite anywhere near: keep the history as it is.
        result = history;
        newLength = hasHistory ? historyLength : 0.0;
    } else {
        newLength = hasHistory ? min(historyLength + 1.0, frame.maxHistoryFrames) : 1.0;
        result = mix(history, current, 1.0 / max(newLength, 1.0));
    }
    result = clamp(result, vec3(0.0), vec3(frame.maxRadiance));
    // One draw for the three channels: each rounds without bias whatever
    // the others do.
    const float u = scalarNoise(uvec2(p), frame.frame, kNoiseHistoryRounding);
    result = vec3(roundToHalf(result.r, u), roundToHalf(result.g, u), roundToHalf(result.b, u));

    imageStore(radianceHistory, p, vec4(result, newLength));
    imageStore(surfaceHistory, p, vec4(px.w, px.roughness, octEncode(px.normal)));
    writeDebugOutputs(p, reflectionMotion, newLength);
}
