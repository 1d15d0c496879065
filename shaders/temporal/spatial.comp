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

#include "glint/temporal_shared.h"
#include "temporal_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 1) uniform sampler2D depthTexture;
layout(set = 0, binding = 2) uniform sampler2D normalTexture;
layout(set = 0, binding = 3) uniform sampler2D roughnessMetalTexture;
layout(set = 0, binding = 4) uniform sampler2D accumulatedTexture;
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D resolvedImage;

float ramp(float x, float start, float end) {
    if (x <= start) return 0.0;
    if (x >= end) return 1.0;
    return smoothstep(start, end, x);
}

// The workgroup's pixels and a border of the filter's radius, as the taps
// want them, loaded once per workgroup (each texel was read by up to 25
// taps, four images each, where it is now read once): colour and whether
// the texel counts (a = 1: it has history and a surface), world position
// and roughness, normal. Loaded only where some pixel of the group filters.
const int kTile = int(kTemporalGroupSize) + 2 * int(kTemporalMaxSpatialRadius);
shared vec4 tileColour[kTile * kTile];
shared vec4 tilePositionRoughness[kTile * kTile];
shared vec3 tileNormal[kTile * kTile];
shared uint groupFilters;

void loadTile(int radius) {
    const int side = int(kTemporalGroupSize) + 2 * radius;
    const ivec2 origin = ivec2(gl_WorkGroupID.xy) * int(kTemporalGroupSize) - radius;
    const vec2 size = vec2(frame.size);
    for (int i = int(gl_LocalInvocationIndex); i < side * side; i += int(kTemporalGroupSize * kTemporalGroupSize)) {
        const ivec2 q = origin + ivec2(i % side, i / side);
        const int slot = (i / side) * kTile + i % side;
        tileColour[slot] = vec4(0.0);
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(frame.size)))) {
            continue;
        }
        const vec4 tap = texelFetch(accumulatedTexture, q, 0);
        const float depth = texelFetch(depthTexture, q, 0).x;
        if (!(tap.a > 0.0) || !(depth > 0.0)) {
            continue;
        }
        tileColour[slot] = vec4(tap.rgb, 1.0);
        tilePositionRoughness[slot] =
            vec4(worldPosition(frame.inverseViewProjection, vec2(q) + 0.5, size, depth),
                 texelFetch(roughnessMetalTexture, q, 0).r);
        tileNormal[slot] = texelFetch(normalTexture, q, 0).xyz;
    }
}

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    const bool inside = p.x < int(frame.size.x) && p.y < int(frame.size.y);
    const int radius = int(min(frame.spatialRadius, kTemporalMaxSpatialRadius));
    // No history length: nothing reflects here (or nothing finite yet).
    vec4 centre = vec4(0.0);
    float roughness = 0.0;
    float strength = 0.0;
    if (inside) {
        centre = texelFetch(accumulatedTexture, p, 0);
        roughness = texelFetch(roughnessMetalTexture, p, 0).r;
        strength = ramp(roughness, frame.spatialRoughnessStart, frame.spatialRoughnessEnd);
    }
    const bool filters = centre.a > 0.0 && radius > 0 && strength > 0.0 && roughness <= frame.spatialRoughnessMax;
    if (gl_LocalInvocationIndex == 0u) {
        groupFilters = 0u;
    }
    barrier();
    if (filters) {
        atomicOr(groupFilters, 1u);
    }
    barrier();
    if (groupFilters != 0u) {
        loadTile(radius);
    }
    barrier();
    if (!inside) {
        return;
    }
    if (!(centre.a > 0.0)) {
        imageStore(resolvedImage, p, vec4(0.0));
        return;
    }
    if (!filters) {
        imageStore(resolvedImage, p, vec4(centre.rgb, 1.0));
        return;
    }
    const vec2 size = vec2(frame.size);
    const vec3 position = worldPosition(frame.inverseViewProjection, vec2(p) + 0.5, size,
                                        texelFetch(depthTexture, p, 0).x);
    const vec3 normal = normalize(texelFetch(normalTexture, p, 0).xyz);
    const float w = viewDepth(frame.viewProjection, position);
    // Sigma of half the radius (plus half a pixel) keeps the window's
    // corners near zero weight.
    const float sigma = 0.5 * float(radius) + 0.5;
    const ivec2 local = ivec2(gl_LocalInvocationID.xy) + radius;
    vec3 sum = centre.rgb;
    float weightSum = 1.0;
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            const int slot = (local.y + dy) * kTile + local.x + dx;
            const vec4 tap = tileColour[slot];
            if ((dx == 0 && dy == 0) || !(tap.a > 0.0)) continue;
            const vec4 tapPositionRoughness = tilePositionRoughness[slot];
            const vec3 tapNormal = tileNormal[slot];
            const float plane = abs(dot(tapPositionRoughness.xyz - position, normal)) /
                                max(frame.spatialPlaneSigma * w, 1e-6);
            const float weight = exp(-float(dx * dx + dy * dy) / (2.0 * sigma * sigma)) * exp(-plane) *
                                 pow(max(dot(tapNormal, normal), 0.0), frame.spatialNormalPower) *
                                 exp(-abs(tapPositionRoughness.w - roughness) / max(frame.spatialRoughnessSigma, 1e-6));
            if (weight > 0.0 && isFinite(tap.rgb)) {
                sum += weight * tap.rgb;
                weightSum += weight;
            }
        }
    }
    imageStore(resolvedImage, p, vec4(mix(centre.rgb, sum / weightSum, strength), 1.0));
}
