// The BVH update's compute pass (shaders/bvh/pack_primitives.comp) and the
// probes that read its results back: structs shared by GLSL and C++
// (passes/bvh_update.cpp, tests). Buffers use scalar layout.
#ifndef GLINT_BVH_SHARED_H
#define GLINT_BVH_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

GLINT_CONST uint kBvhPackGroupSize = 64;
GLINT_CONST uint kBvhProbeGroupSize = 64;

// One vertex of a reflection-LOD geometry, uploaded once (32 bytes). The
// material words are final: texture sampling at the vertices does not
// change from frame to frame, so the CPU does it once at upload
// (scene::surfaceAtVertex) and the per-frame pass only transforms and
// packs the normal.
struct BvhSourceVertex {
    vec3 position;  // object space, bind pose for skinned geometry
    vec3 normal;    // as surfaceAtVertex gives it (not renormalised)
    uint albedoSmoothness;     // PackedVertex word 0, final
    uint metallicReflectance;  // PackedVertex word 1 without the normal: metallic << 16 | reflectance << 24
};

// Skinning inputs of one vertex of a skinned geometry (24 bytes).
struct BvhSkinVertex {
    uvec2 joints;  // four 16-bit joint indices: x = j0 | j1 << 16, y = j2 | j3 << 16
    vec4 weights;
};

// BvhPackParams::motionOffset and RtGeometryMaterial::deformMotion of a
// geometry that did not change shape this frame.
GLINT_CONST uint kNoDeformMotion = 0xFFFFFFFFu;

// Push constants of one pack dispatch: one BLAS geometry (24 bytes).
struct BvhPackParams {
    uint triangleCount;
    uint poolOffset;      // first triangle of the geometry in the primitive pool
    uint positionOffset;  // first vertex of the geometry in its BLAS's unwrapped positions
    uint jointOffset;     // first matrix of the instance in the joint palette
    uint jointCount;      // joints of the instance's skin; 0: not skinned
    // A rebuild of a deformable BLAS: its first DeformMotion this frame,
    // written from the positions its last build left; kNoDeformMotion on a
    // first build (no earlier shape) and for static BLASes.
    uint motionOffset;
};

// How one triangle of a deformed BLAS moved inside its object: per vertex,
// where it was at the BLAS's previous build minus where it is now (object
// space; packHalf2x16(x, y), packHalf2x16(z, 0)), 24 bytes. Written by the
// pack dispatch of a rebuild, read by the reflection trace's hit motion
// (RtGeometryMaterial::deformMotion) in the same frame.
struct DeformMotion {
    uvec2 vertices[3];
};

// A probe ray and what it hit, read back by tests and debug tools: the hit's
// identity and the packed surface interpolated at it, found through the
// primitive offset buffer exactly as the reflection hit path finds it.
struct BvhProbeRay {
    vec3 origin;
    float tMin;
    vec3 direction;
    float tMax;
};

struct BvhProbeHit {
    uint hit;  // 1 when a triangle was hit
    uint customIndex;
    uint geometry;
    uint primitive;
    float t;
    vec2 barycentrics;
    float roughness;
    vec3 albedo;
    float metallic;
    vec3 normal;  // object space of the BLAS
    float reflectance;
};

GLINT_END

#endif
