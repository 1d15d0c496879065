// Packed primitives: the surface a reflection ray's hit shader reads.
//
// Far Cry 6 (GDC 2022, "Performant Reflective Beauty") unwraps every triangle
// of a reflection BLAS into one pool buffer so a hit needs one load instead
// of index buffer -> vertex buffer -> material -> textures. Per vertex
// 8 bytes, so 24 bytes per triangle:
//
//   word 0: albedo R, G, B (8 bits each, sRGB-encoded) | smoothness (8 bits)
//   word 1: octahedral normal X, Y (8-bit snorm each) | metallic (8 bits)
//           | reflectance (8 bits)
//
// Both GLSL and C++ compile this file, so the maths exists once: C++ tests
// run the same encoders the compute pass runs. In C++ the GLSL built-ins
// resolve to glm; the code therefore avoids swizzles, which glm does not
// have without GLM_FORCE_SWIZZLE, and uses float literals with an `f` suffix
// (valid GLSL since 4.00) so glm's scalar/vector operators deduce float.
#ifndef GLINT_PACKING_H
#define GLINT_PACKING_H

#include "glint/shared.h"

#ifdef __cplusplus
#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
namespace glint::shader {
using glm::abs;
using glm::clamp;
using glm::dot;
using glm::floor;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
} // namespace glint::shader
#define GLINT_FUNC inline
#else
#define GLINT_FUNC
#endif

GLINT_BEGIN

// ---------------------------------------------------------------------------
// Layout
// ---------------------------------------------------------------------------

GLINT_CONST uint kPackedVertexBytes = 8;
GLINT_CONST uint kPackedPrimitiveBytes = 24;

// Largest magnitude of an 8-bit snorm; -128 is unused so 0 is exact and the
// axis directions survive quantisation unchanged.
GLINT_CONST float kSnorm8Max = 127.0f;
GLINT_CONST float kUnorm8Max = 255.0f;

// Dielectric specular reflectance as Filament defines it (Filament
// "Physically Based Rendering", section 4.8.3.2): f0 = 0.16 * reflectance^2,
// so the default 0.5 gives f0 = 0.04, the 4% of common dielectrics.
GLINT_CONST float kDefaultReflectance = 0.5f;

struct PackedVertex {
    uint albedoSmoothness;           // R8 G8 B8 (sRGB) | smoothness 8
    uint normalMetallicReflectance;  // oct X8 Y8 (snorm) | metallic 8 | reflectance 8
};

struct PackedPrimitive {
    PackedVertex vertices[3];
};

// The surface at one vertex, unpacked: linear albedo, perceptual roughness
// (1 - smoothness), unit normal in the BLAS's object space.
struct SurfaceVertex {
    vec3 albedo;
    float roughness;
    vec3 normal;
    float metallic;
    float reflectance;
};

// ---------------------------------------------------------------------------
// How a hit finds its primitive
// ---------------------------------------------------------------------------
// The primitive offset buffer holds, per TLAS instance, one row per BLAS
// geometry: offsets[customIndex + geometryIndex] is that geometry's first
// triangle in the pool, so
//     pool[offsets[gl_InstanceCustomIndexEXT + gl_GeometryIndexEXT] + gl_PrimitiveID]
// is the hit triangle. The BVH planner fills both (glint/scene/bvh_planner.h).
GLINT_FUNC uint primitiveOffsetSlot(uint instanceCustomIndex, uint geometryIndex) {
    return instanceCustomIndex + geometryIndex;
}

// Instance masks of the reflection TLAS. Rays leaving the first-person
// objects can skip them (they would hit the inside of the camera).
GLINT_CONST uint kInstanceMaskWorld = 0x01u;
GLINT_CONST uint kInstanceMaskFirstPerson = 0x02u;
GLINT_CONST uint kInstanceMaskLongRange = 0x04u;
GLINT_CONST uint kInstanceMaskAll = 0xFFu;

// Hit group offsets (instance SBT record offset): every scene instance uses
// the one packed-primitive hit path; particles live in their own TLAS.
GLINT_CONST uint kSbtOffsetPackedPrimitives = 0u;
GLINT_CONST uint kSbtOffsetParticles = 1u;

// ---------------------------------------------------------------------------
// Scalar quantisation (round to nearest; floor(x + 0.5) rather than round()
// because GLSL leaves the direction of round(0.5) to the implementation)
// ---------------------------------------------------------------------------

GLINT_FUNC uint encodeUnorm8(float x) {
    return uint(floor(clamp(x, 0.0f, 1.0f) * kUnorm8Max + 0.5f));
}

GLINT_FUNC float decodeUnorm8(uint bits) {
    return float(bits & 0xFFu) / kUnorm8Max;
}

GLINT_FUNC uint encodeSnorm8(float x) {
    // Through int: converting a negative float straight to uint is undefined
    // in both languages.
    return uint(int(floor(clamp(x, -1.0f, 1.0f) * kSnorm8Max + 0.5f))) & 0xFFu;
}

GLINT_FUNC float decodeSnorm8(uint bits) {
    int v = int(bits & 0xFFu);
    if (v >= 128) {
        v -= 256;
    }
    return max(float(v) / kSnorm8Max, -1.0f);
}

// IEC 61966-2-1 sRGB transfer functions (exact, not the 2.2 power).
GLINT_FUNC float linearToSrgb(float c) {
    c = clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? c * 12.92f : 1.055f * pow(c, 1.0f / 2.4f) - 0.055f;
}

GLINT_FUNC float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : pow((c + 0.055f) / 1.055f, 2.4f);
}

// Filament's mapping (see kDefaultReflectance).
GLINT_FUNC float reflectanceToF0(float reflectance) {
    return 0.16f * reflectance * reflectance;
}

// ---------------------------------------------------------------------------
// Octahedral normals
// ---------------------------------------------------------------------------
// Cigolle, Donow, Evangelakos, Mara, McGuire, Meyer, "A Survey of Efficient
// Representations for Independent Unit Vectors", JCGT 3(2), 2014: project
// onto the octahedron |x|+|y|+|z| = 1 and fold the lower half over the
// diagonals. 8 bits per component with rounding stays within 1 degree; the
// "precise" encoder, which tries the four neighbouring codes and keeps the
// one that decodes closest (the paper's oct16P), within 0.65 degrees.

GLINT_FUNC float signNotZero(float x) {
    return x >= 0.0f ? 1.0f : -1.0f;
}

// Unit vector -> point of [-1, 1]^2.
GLINT_FUNC vec2 octEncode(vec3 n) {
    const float l1 = abs(n.x) + abs(n.y) + abs(n.z);
    const vec2 p = vec2(n.x, n.y) * (1.0f / l1);
    if (n.z >= 0.0f) {
        return p;
    }
    return vec2((1.0f - abs(p.y)) * signNotZero(p.x), (1.0f - abs(p.x)) * signNotZero(p.y));
}

// Point of [-1, 1]^2 -> unit vector.
GLINT_FUNC vec3 octDecode(vec2 e) {
    vec3 n = vec3(e.x, e.y, 1.0f - abs(e.x) - abs(e.y));
    if (n.z < 0.0f) {
        const float x = (1.0f - abs(n.y)) * signNotZero(n.x);
        const float y = (1.0f - abs(n.x)) * signNotZero(n.y);
        n.x = x;
        n.y = y;
    }
    return normalize(n);
}

// 16 bits: X in bits 0-7, Y in bits 8-15, each an 8-bit snorm.
GLINT_FUNC uint packOctNormal(vec3 n) {
    const vec2 e = octEncode(n);
    return encodeSnorm8(e.x) | (encodeSnorm8(e.y) << 8u);
}

GLINT_FUNC vec3 unpackOctNormal(uint bits) {
    return octDecode(vec2(decodeSnorm8(bits), decodeSnorm8(bits >> 8u)));
}

GLINT_FUNC uint packOctNormalPrecise(vec3 n) {
    const vec2 e = octEncode(n) * kSnorm8Max;
    const vec2 base = floor(e);
    uint best = 0u;
    float bestDistance = 8.0f;
    for (int i = 0; i < 4; ++i) {
        const float qx = clamp(base.x + float(i & 1), -kSnorm8Max, kSnorm8Max);
        const float qy = clamp(base.y + float(i >> 1), -kSnorm8Max, kSnorm8Max);
        const uint bits = (uint(int(qx)) & 0xFFu) | ((uint(int(qy)) & 0xFFu) << 8u);
        // Squared chord rather than the cosine: for errors under a degree
        // the cosine sits within float rounding of 1 and cannot rank the
        // candidates; the chord keeps full relative precision.
        const vec3 d = unpackOctNormal(bits) - n;
        const float distance = dot(d, d);
        if (distance < bestDistance) {
            bestDistance = distance;
            best = bits;
        }
    }
    return best;
}

// ---------------------------------------------------------------------------
// Vertices
// ---------------------------------------------------------------------------

GLINT_FUNC PackedVertex packVertex(SurfaceVertex s) {
    PackedVertex p;
    p.albedoSmoothness = encodeUnorm8(linearToSrgb(s.albedo.x)) | (encodeUnorm8(linearToSrgb(s.albedo.y)) << 8u) |
                         (encodeUnorm8(linearToSrgb(s.albedo.z)) << 16u) | (encodeUnorm8(1.0f - s.roughness) << 24u);
    p.normalMetallicReflectance =
        packOctNormalPrecise(s.normal) | (encodeUnorm8(s.metallic) << 16u) | (encodeUnorm8(s.reflectance) << 24u);
    return p;
}

GLINT_FUNC SurfaceVertex unpackVertex(PackedVertex p) {
    SurfaceVertex s;
    s.albedo = vec3(srgbToLinear(decodeUnorm8(p.albedoSmoothness)),
                    srgbToLinear(decodeUnorm8(p.albedoSmoothness >> 8u)),
                    srgbToLinear(decodeUnorm8(p.albedoSmoothness >> 16u)));
    s.roughness = 1.0f - decodeUnorm8(p.albedoSmoothness >> 24u);
    s.normal = unpackOctNormal(p.normalMetallicReflectance);
    s.metallic = decodeUnorm8(p.normalMetallicReflectance >> 16u);
    s.reflectance = decodeUnorm8(p.normalMetallicReflectance >> 24u);
    return s;
}

// The surface at barycentrics (b1, b2) of a hit (weights of vertices 1 and
// 2, as ray tracing reports them).
GLINT_FUNC SurfaceVertex interpolateSurface(PackedPrimitive prim, vec2 barycentrics) {
    const SurfaceVertex a = unpackVertex(prim.vertices[0]);
    const SurfaceVertex b = unpackVertex(prim.vertices[1]);
    const SurfaceVertex c = unpackVertex(prim.vertices[2]);
    const float w0 = 1.0f - barycentrics.x - barycentrics.y;
    SurfaceVertex s;
    s.albedo = a.albedo * w0 + b.albedo * barycentrics.x + c.albedo * barycentrics.y;
    s.roughness = a.roughness * w0 + b.roughness * barycentrics.x + c.roughness * barycentrics.y;
    s.normal = normalize(a.normal * w0 + b.normal * barycentrics.x + c.normal * barycentrics.y);
    s.metallic = a.metallic * w0 + b.metallic * barycentrics.x + c.metallic * barycentrics.y;
    s.reflectance = a.reflectance * w0 + b.reflectance * barycentrics.x + c.reflectance * barycentrics.y;
    return s;
}

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::PackedVertex) == glint::shader::kPackedVertexBytes);
static_assert(sizeof(glint::shader::PackedPrimitive) == glint::shader::kPackedPrimitiveBytes);
#endif

#endif
