// Ray generation and tile classification (passes/ray_generation.cpp,
// shaders/ray_generation/*): constants, the packed ray and the push
// constants, shared by GLSL and C++. Buffers use scalar layout.
//
// Outputs, per pixel p = y * width + x:
//   rays[p]    PackedRay; pixelFlags == kNoRay where the pixel traces nothing
//   classes[p] one of kPixel*
// and two ray lists (below), each with its args: the SSLR list (the ray
// leaders of the SSLR and hybrid pixels) and the RT list (those of the RT
// pixels; SSLR appends the hybrid rays it could not resolve).
#ifndef GLINT_RAY_GENERATION_SHARED_H
#define GLINT_RAY_GENERATION_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

// 8x8 tiles: the Far Cry 6 talk's and FidelityFX's tile.
GLINT_CONST uint kTileSize = 8u;

// Pixel classes. Sky: nothing to reflect. Env: rougher than the cutoff, the
// environment map alone. Sslr: beyond the BVH, screen space only. Hybrid:
// SSLR first, RT for what it misses (the feedback counters decide later).
// Rt: near pixels, straight to the ray tracer.
GLINT_CONST uint kPixelSky = 0u;
GLINT_CONST uint kPixelEnv = 1u;
GLINT_CONST uint kPixelSslr = 2u;
GLINT_CONST uint kPixelHybrid = 3u;
GLINT_CONST uint kPixelRt = 4u;
GLINT_CONST uint kPixelClassCount = 5u;

// A packed ray (8 bytes).
//   pixelFlags: bits 0-14 x, 15-28 y of the pixel whose ray this is (up to
//               32767 x 16383, as FidelityFX SSSR packs its rays), bit 29
//               kRayReused: this pixel reuses that (quad leader's) ray,
//               bit 30 kRayCone (SSLR list entries only): SSLR cone-traces
//               it (its roughness is at least the cone roughness), bit 31
//               unused
//   direction:  world-space unit direction, octahedral, two 16-bit snorms
// A leader's own entry has its own pixel; a follower's entry names the
// leader, so later passes trace leaders only and followers read the
// leader's result.
struct PackedRay {
    uint pixelFlags;
    uint direction;
};

GLINT_CONST uint kNoRay = 0xFFFFFFFFu;
GLINT_CONST uint kRayReused = 1u << 29u;
GLINT_CONST uint kRayCone = 1u << 30u;
GLINT_CONST uint kRayPixelXMask = 0x7FFFu;
GLINT_CONST uint kRayPixelYShift = 15u;
GLINT_CONST uint kRayPixelYMask = 0x3FFFu;


// Reflection modes (RayGenerationSettings::mode): hybrid is the Far Cry 6
// scheme; ssr turns every traced pixel into SSLR (the environment where it
// finds nothing), rt every one into RT.
GLINT_CONST uint kModeHybrid = 0u;
GLINT_CONST uint kModeSsr = 1u;
GLINT_CONST uint kModeRt = 2u;

// A ray list: PackedRay entries (one per pixel of capacity), leaders only,
// traced one invocation per entry. A tile's leaders take consecutive slots,
// so a workgroup's rays stay close on screen. The SSLR list holds the SSLR
// and hybrid pixels' leaders (compacted: an 8x8 dispatch per tile ran
// about 3 idle lanes for every traced one on plaza). The RT list holds the
// RT pixels' leaders, then the hybrid rays SSLR could not resolve. The
// args buffer of a list (kRayListArgsWords uints):
//   words 0-2  VkDispatchIndirectCommand {ceil(count / kRayListGroupSize), 1, 1}
//              (compute, kRayListGroupSize invocations per group)
//   words 3-5  VkTraceRaysIndirectCommandKHR {count, 1, 1} (RT pipeline);
//              word kRayListCountOffset is the list's length
// Appenders reserve slots with atomicAdd on the count; one whose slots
// include a group's first slot raises the group count to its end's with
// atomicMax (rayListOpensGroup), so both commands stay consistent: the
// appender of the last group's first slot sets the final count. (Every
// appender raising it put tens of thousands of atomics a frame on one
// word.)
GLINT_CONST uint kRayListGroupSize = 64u;
GLINT_CONST uint kRayListDispatchOffset = 0u;
GLINT_CONST uint kRayListCountOffset = 3u;
GLINT_CONST uint kRayListArgsWords = 6u;
// The SSLR list's args go on with the indirect dispatches of SSLR's two
// colour-pyramid passes (glint/sslr_shared.h): words 32-34 and 35-37, each
// {groups x, groups y, z}, z = 0 unless a listed ray cone-traces (then 1).
// They start 128 bytes in, on a cache line of their own, so that the tiles
// that look at them do not queue behind the count's atomics on the list's
// line (docs/results/log/05-2026-12-06-a.md, "the passes every mode runs": that look cost ray
// generation 0.013 ms of its 0.065 in the city on an H100).
GLINT_CONST uint kSslrArgsPyramidOffset = 32u;
GLINT_CONST uint kSslrArgsWords = 38u;

// The hit distance that stands for "at infinity" (a miss, the sky, the
// environment): finite so that half floats hold it (their largest finite
// value) and reprojection through the reflected point stays finite.
GLINT_CONST float kMissHitDistance = 65504.0f;

// Push constants of classify.comp (128 bytes).
struct RayGenerationConstants {
    mat4 inverseViewProjection;  // unjittered
    vec4 cameraPosition;
    uvec2 size;
    uint frame;
    float roughnessCutoff;
    float reuseRoughness;
    float rtMaxDistance;
    float sslrMinDistance;
    uint flags;             // kRayGen*: the mode and what is enabled
    float coneRoughness;    // SSLR pixels at least this rough cone-trace (kRayCone)
    float rtToHybridShare;  // share of an RT tile's hybrid pixels kept hybrid
    uint tilesX;
    uint pad0;
};

// RayGenerationConstants::flags: the mode (kMode*) in the low two bits.
GLINT_CONST uint kRayGenModeMask = 3u;
GLINT_CONST uint kRayGenReuse = 1u << 2u;      // rough quads share one ray
GLINT_CONST uint kRayGenTileModes = 1u << 3u;  // hybrid pixels follow the feedback's tile modes
GLINT_CONST uint kRayGenCheckerboard = 1u << 4u;  // half the smooth hybrid and RT pixels share a neighbour's ray
GLINT_CONST uint kRayGenBlueNoise = 1u << 5u;  // GGX samples and the hybrid share from the blue noise (glint/sampling.glsl)
GLINT_CONST uint kRayGenSslrFirst = 1u << 6u;  // hybrid mode: RT pixels try SSLR first (the BVH is building)
GLINT_CONST uint kRayGenClassDebug = 1u << 7u;  // write the class debug colours (RayGenerationInputs::debugOutputs)

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::PackedRay) == 8);
static_assert(sizeof(glint::shader::RayGenerationConstants) == 128);
#endif

// ---------------------------------------------------------------------------
// Packing (both languages)
// ---------------------------------------------------------------------------
#include "glint/packing.h"

GLINT_BEGIN

GLINT_CONST float kSnorm16Max = 32767.0f;

// Whether slots [begin, end) of a ray list include the first slot of a
// group of kRayListGroupSize.
GLINT_FUNC bool rayListOpensGroup(uint begin, uint end) {
    return (begin + kRayListGroupSize - 1u) / kRayListGroupSize < (end + kRayListGroupSize - 1u) / kRayListGroupSize;
}

GLINT_FUNC uint encodeSnorm16(float x) {
    return uint(int(floor(clamp(x, -1.0f, 1.0f) * kSnorm16Max + 0.5f))) & 0xFFFFu;
}

GLINT_FUNC float decodeSnorm16(uint bits) {
    int v = int(bits & 0xFFFFu);
    if (v >= 32768) {
        v -= 65536;
    }
    return max(float(v) / kSnorm16Max, -1.0f);
}

// Octahedral (glint/packing.h's octEncode), 16 bits per component: about
// 5e-5 rad of error, far below a pixel's footprint at any distance.
GLINT_FUNC uint packRayDirection(vec3 d) {
    const vec2 e = octEncode(d);
    return encodeSnorm16(e.x) | (encodeSnorm16(e.y) << 16u);
}

GLINT_FUNC vec3 unpackRayDirection(uint bits) {
    return octDecode(vec2(decodeSnorm16(bits), decodeSnorm16(bits >> 16u)));
}

GLINT_FUNC uint packRayPixel(uvec2 pixel, bool reused) {
    return (pixel.x & kRayPixelXMask) | ((pixel.y & kRayPixelYMask) << kRayPixelYShift) | (reused ? kRayReused : 0u);
}

GLINT_FUNC uvec2 unpackRayPixel(uint pixelFlags) {
    return uvec2(pixelFlags & kRayPixelXMask, (pixelFlags >> kRayPixelYShift) & kRayPixelYMask);
}

GLINT_END

#endif
