// What a ray-traced hit reads of its geometry beyond the packed primitive
// (glint/alpha_test.h): the material row of its (instance, geometry) and,
// for alpha-tested geometry, the alpha test. Included by the reflection
// trace (glint/rt_trace.glsl) and by its any-hit shader
// (shaders/rt_trace/trace.rahit), which share one pipeline layout, so the
// bindings are declared here once (passes/rt_trace.cpp pushes them).
#ifndef GLINT_RT_GEOMETRY_GLSL
#define GLINT_RT_GEOMETRY_GLSL

#extension GL_EXT_scalar_block_layout : require

#include "glint/alpha_test.h"
#include "glint/packing.h"

// Parallel to the primitive offsets (passes/bvh_update.h's
// BvhUpdateOutputs::materials).
layout(set = 0, binding = 12, scalar) readonly buffer GeometryMaterials { RtGeometryMaterial geometryMaterials[]; };
layout(set = 0, binding = 13, scalar) readonly buffer AlphaTriangles { AlphaTriangle alphaTriangles[]; };
layout(set = 0, binding = 14) uniform sampler2DArray alphaMasks;

RtGeometryMaterial rtGeometryMaterial(uint customIndex, uint geometry) {
    return geometryMaterials[primitiveOffsetSlot(customIndex, geometry)];
}

// One coordinate through a wrap mode the sampler (which repeats) does not
// apply: clamped to the edge texels' centres, or mirrored every period.
float rtAlphaWrap(float u, uint mode, float texels) {
    if (mode == kAlphaWrapClamp) {
        return clamp(u, 0.5 / texels, 1.0 - 0.5 / texels);
    }
    if (mode == kAlphaWrapMirror) {
        const float m = u - 2.0 * floor(u * 0.5);
        return m > 1.0 ? 2.0 - m : m;
    }
    return u;
}

// Whether the triangle `primitive` of geometry `geometry` of the instance
// with custom index `customIndex` covers the point at `barycentrics` (of
// vertices 1 and 2): vertex alpha x the mask texel >= the cutoff, as the
// G-buffer's alpha test. Geometry without an alpha test always covers.
// The mask is read at its base level: the hit has no footprint to choose
// a mip by, and the mask is already far smaller than the texture.
bool rtAlphaCovers(uint customIndex, uint geometry, uint primitive, vec2 barycentrics) {
    const RtGeometryMaterial m = rtGeometryMaterial(customIndex, geometry);
    if (m.alphaTriangles == kAlphaOpaque) {
        return true;
    }
    const AlphaTriangle t = alphaTriangles[m.alphaTriangles + primitive];
    const vec3 w = vec3(1.0 - barycentrics.x - barycentrics.y, barycentrics.x, barycentrics.y);
    const vec3 vertexAlpha = vec3(float(t.alpha & 0xFFu), float((t.alpha >> 8u) & 0xFFu),
                                  float((t.alpha >> 16u) & 0xFFu)) / 255.0;
    float alpha = dot(w, vertexAlpha);
    const uint layer = m.alphaMask & kAlphaLayerBits;
    if (layer != kAlphaNoMask) {
        const vec2 uv = w.x * unpackHalf2x16(t.uv.x) + w.y * unpackHalf2x16(t.uv.y) + w.z * unpackHalf2x16(t.uv.z);
        const vec2 texels = vec2(textureSize(alphaMasks, 0).xy);
        const vec2 wrapped = vec2(rtAlphaWrap(uv.x, (m.alphaMask >> kAlphaWrapShiftU) & 3u, texels.x),
                                  rtAlphaWrap(uv.y, (m.alphaMask >> kAlphaWrapShiftV) & 3u, texels.y));
        alpha *= textureLod(alphaMasks, vec3(wrapped, float(layer)), 0.0).r;
    }
    return alpha >= m.alphaCutoff;
}

#endif
