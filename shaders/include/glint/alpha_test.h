// Alpha-tested geometry (glTF alphaMode MASK) in the ray tracer: what the
// hit path reads of a geometry beyond its packed vertices. Shared by GLSL
// (glint/rt_geometry.glsl) and C++ (scene/alpha_test.h fills it,
// passes/bvh_update.cpp uploads it); scalar layout.
//
// The packed primitives (glint/packing.h) carry colours sampled at the
// vertices, far too coarse for a leaf's outline, so an alpha-tested
// geometry also gets, once at start-up:
//  - per triangle an AlphaTriangle: the base colour texture's coordinates
//    at its three vertices (half floats) and their alpha (unorm8);
//  - per base colour texture, one layer of the alpha mask array: the
//    texture's alpha channel resampled to a fixed square size (R8, with
//    mips), so one descriptor serves every alpha-tested material.
// The BLAS geometry is not opaque, and the any-hit shader (ray query: the
// candidate loop) accepts a candidate where vertex alpha x mask texel >=
// the material's cutoff, the G-buffer's test (gbuffer_surface.glsl).
#ifndef GLINT_ALPHA_TEST_H
#define GLINT_ALPHA_TEST_H

#include "glint/shared.h"

GLINT_BEGIN

// RtGeometryMaterial::alphaTriangles of a geometry without an alpha test.
GLINT_CONST uint kAlphaOpaque = 0xFFFFFFFFu;
// RtGeometryMaterial::alphaMask: bits 0-23 the mask layer (kAlphaNoMask:
// no texture, the vertex alpha alone), bits 24-25 and 26-27 the wrap modes
// along u and v (kAlphaWrap*).
GLINT_CONST uint kAlphaLayerBits = 0x00FFFFFFu;
GLINT_CONST uint kAlphaNoMask = 0x00FFFFFFu;
GLINT_CONST uint kAlphaWrapShiftU = 24u;
GLINT_CONST uint kAlphaWrapShiftV = 26u;
GLINT_CONST uint kAlphaWrapRepeat = 0u;
GLINT_CONST uint kAlphaWrapClamp = 1u;
GLINT_CONST uint kAlphaWrapMirror = 2u;

// One row per primitive offset row (glint/packing.h's
// primitiveOffsetSlot: a TLAS instance's BLAS geometry), 76 bytes.
struct RtGeometryMaterial {
    vec3 emission;        // glTF units: the material's mean (scene::meanEmission)
    uint alphaTriangles;  // the geometry's first AlphaTriangle; kAlphaOpaque: no alpha test
    uint alphaMask;       // layer | wrap u << kAlphaWrapShiftU | wrap v << kAlphaWrapShiftV
    float alphaCutoff;    // glTF alphaCutoff
    // The instance's motion: the rows of the 3x4 matrix that takes a world
    // point on it this frame to where that point was last frame (last
    // frame's object-to-world times the inverse of this frame's; identity
    // for a still instance). Reflections reproject a moving object's hits
    // with it (passes/temporal.h).
    vec4 previousFromCurrent[3];
    // Skinned and morphed vertices move inside the object too: where the
    // geometry's BLAS was rebuilt this frame over an earlier shape, its
    // first glint/bvh_shared.h DeformMotion (per triangle, in the frame's
    // deform motion buffer); else kNoDeformMotion (the shape the rays meet
    // is last frame's).
    uint deformMotion;
};

// One triangle of an alpha-tested geometry, 16 bytes: the base colour
// texture's coordinates at its vertices (KHR_texture_transform applied,
// then moved by whole periods of the wrap towards 0 so that half floats
// keep their precision) and the vertices' alpha (baseColorFactor.a x
// COLOR_0.a).
struct AlphaTriangle {
    uvec3 uv;    // packHalf2x16(uv) per vertex
    uint alpha;  // vertex k's alpha as unorm8 in bits 8k..8k+7
};

GLINT_END

#endif
