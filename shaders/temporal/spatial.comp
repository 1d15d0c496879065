#version 460
// The spatial filter of the temporal pass (passes/temporal.h): an
// edge-aware blur of the accumulated reflections, strong where the surface
// is rough (its reflection is blurry anyway and its rays noisy) and off for
// mirrors. A Gaussian over a (2r+1)^2 window, each tap weighted by how far
// it lies off this pixel's plane, how far its normal turns away and how
// different its roughness is (the cross-bilateral weights of SVGF, Schied
// et al., HPG 2017, with a plane distance in place of a depth gradient).
// It reads the history but writes only the resolved image: fed back into
// the history it would blur again every frame.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/integrate_shared.h"
#include "glint/packing.h"
#include "glint/temporal_shared.h"
#include "temporal_common.glsl"

layout(local_size_x = kTemporalSpatialGroupSize, local_size_y = kTemporalSpatialGroupSize) in;

layout(set = 0, binding = 1) uniform sampler2D depthTexture;
// This frame's surface as the accumulation wrote it (temporal.surface:
// view depth, roughness, octahedral normal): one read a tap instead of
// the G-buffer's three.
layout(set = 0, binding = 2) uniform sampler2D surfaceTexture;
layout(set = 0, binding = 3) uniform sampler2D accumulatedTexture;
layout(set = 0, binding = 4, rgba16f) uniform writeonly image2D resolvedImage;
// This frame's reflection radiance (the accumulation's input): its a says
// where it is noise-free (TemporalInputs::radiance).
layout(set = 0, binding = 5) uniform sampler2D radianceTexture;

float ramp(float x, float start, float end) {
    if (x <= start) return 0.0;
    if (x >= end) return 1.0;
    return smoothstep(start, end, x);
}

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.size.x) || p.y >= int(frame.size.y)) {
        return;
    }
    const vec4 centre = texelFetch(accumulatedTexture, p, 0);
    // No history length: nothing reflects here (or nothing finite yet).
    if (!(centre.a > 0.0)) {
        imageStore(resolvedImage, p, vec4(0.0));
        return;
    }
    const vec4 surface = texelFetch(surfaceTexture, p, 0);
    const float roughness = surface.y;
    const float strength = ramp(roughness, frame.spatialRoughnessStart, frame.spatialRoughnessEnd);
    int radius = int(min(frame.spatialRadius, kTemporalMaxSpatialRadius));
    const bool filtered = radius > 0 && strength > 0.0 && roughness <= frame.spatialRoughnessMax;
    // A smaller window (or none) where this frame's radiance is noise-free
    // (read only where the filter would run).
    if (filtered && frame.spatialNoiseFreeRadius < uint(radius) &&
        reflectsNoiseFree(texelFetch(radianceTexture, p, 0).a)) {
        radius = int(frame.spatialNoiseFreeRadius);
    }
    if (!filtered || radius == 0) {
        imageStore(resolvedImage, p, vec4(centre.rgb, 1.0));
        return;
    }
    const vec2 size = vec2(frame.size);
    const vec3 normal = octDecode(clamp(surface.zw, vec2(-1.0), vec2(1.0)));
    // A tap's distance to this pixel's plane from its view depth alone
    // (temporal_common.glsl's planeDistanceSteps): a few FMAs a tap
    // instead of a position reconstructed from depth.
    const float depth = texelFetch(depthTexture, p, 0).x;
    const vec3 position = worldPosition(frame.inverseViewProjection, vec2(p) + 0.5, size, depth);
    const float w = viewDepth(frame.viewProjection, position);
    const float planeOffset = dot(frame.cameraPosition.xyz - position, normal);
    const vec3 steps = planeDistanceSteps(frame.inverseViewProjection, frame.viewProjection, frame.cameraPosition.xyz,
                                          vec2(p) + 0.5, normal);
    // Sigma of half the radius (plus half a pixel) keeps the window's
    // corners near zero weight.
    const float sigma = 0.5 * float(radius) + 0.5;
    // The weight's four factors are one exp2 of a sum (and the normal's
    // power one log2): exp(-x) = exp2(-x log2(e)).
    const float kLog2e = 1.4426950408889634;
    const float gaussianScale = kLog2e / (2.0 * sigma * sigma);
    const float planeScale = kLog2e / max(frame.spatialPlaneSigma * w, 1e-6);
    const float roughnessScale = kLog2e / max(frame.spatialRoughnessSigma, 1e-6);
    vec3 sum = centre.rgb;
    float weightSum = 1.0;
    // A plain loop over the frame's radius: unrolled at the default radius
    // (every tap read before any test) it took 48 registers instead of 38
    // and was slower on an H100 at 1080p (0.0445 -> 0.0472 ms on the plaza,
    // 0.0754 -> 0.0768 in the city; docs/results/log/07-2026-12-07.md, ninth
    // session).
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            const ivec2 q = p + ivec2(dx, dy);
            if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(frame.size)))) {
                continue;
            }
            const vec4 tap = texelFetch(accumulatedTexture, q, 0);
            const vec4 tapSurface = texelFetch(surfaceTexture, q, 0);
            if (!(tap.a > 0.0) || !(tapSurface.x > 0.0)) continue;
            const float facing = dot(octDecode(clamp(tapSurface.zw, vec2(-1.0), vec2(1.0))), normal);
            if (!(facing > 0.0)) continue;
            const float distance =
                abs(planeOffset + tapSurface.x * (steps.x + float(dx) * steps.y + float(dy) * steps.z));
            const float exponent = frame.spatialNormalPower * log2(facing) -
                                   (float(dx * dx + dy * dy) * gaussianScale + distance * planeScale +
                                    abs(tapSurface.y - roughness) * roughnessScale);
            const float weight = exp2(exponent);
            if (weight > 0.0 && isFinite(tap.rgb)) {
                sum += weight * tap.rgb;
                weightSum += weight;
            }
        }
    }
    imageStore(resolvedImage, p, vec4(mix(centre.rgb, sum / weightSum, strength), 1.0));
}
