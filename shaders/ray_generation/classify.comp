#version 460
// Ray generation and tile classification (passes/ray_generation.h): one
// workgroup per 8x8 tile. Each pixel is classified (sky, env, SSLR,
// hybrid, RT), draws one GGX visible-normal reflection ray, and rough
// pixels of a 2x2 quad share the quad leader's ray; the tile then appends
// its SSLR and hybrid pixels' ray leaders to the SSLR ray list and its RT
// pixels' leaders to the RT ray list, counting both in their args, and
// opens SSLR's colour pyramid passes when a listed ray cone-traces.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/feedback_shared.h"
#include "glint/ray_generation_shared.h"
#include "glint/sampling.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D depthTexture;
layout(set = 0, binding = 1) uniform sampler2D normalTexture;
layout(set = 0, binding = 2) uniform sampler2D roughnessMetalTexture;
layout(set = 0, binding = 3, scalar) writeonly buffer Rays { PackedRay rays[]; };
layout(set = 0, binding = 4, scalar) writeonly buffer Classes { uint classes[]; };
layout(set = 0, binding = 5, scalar) writeonly buffer SslrRays { PackedRay sslrRays[]; };
layout(set = 0, binding = 6, scalar) writeonly buffer RtRays { PackedRay rtRays[]; };
layout(set = 0, binding = 7, scalar) buffer SslrArgs { uint sslrArgs[]; };
layout(set = 0, binding = 8, rgba8) uniform writeonly image2D classDebug;
layout(set = 0, binding = 9, scalar) buffer RtArgs { uint rtArgs[]; };
// The feedback pass's kTileMode* per tile (glint/feedback_shared.h); read
// only when pc.tileModesEnabled is 1.
layout(set = 0, binding = 10, scalar) readonly buffer TileModes { uint tileModes[]; };
// The spatiotemporal blue noise (glint/sampling.glsl); read only with kRayGenBlueNoise.
layout(set = 0, binding = 11, scalar) readonly buffer BlueNoise { uvec2 blueNoise[]; };

layout(push_constant, scalar) uniform Constants { RayGenerationConstants pc; };

shared uint sharedClass[64];
shared uint sharedRough[64];  // 1: may share its quad's ray
shared uint sharedDirection[64];
shared uint sharedSslrCount;  // SSLR and hybrid ray leaders of the tile
shared uint sharedSslrBase;   // their first slot in the SSLR list
shared uint sharedRtCount;    // RT ray leaders of the tile
shared uint sharedRtBase;     // their first slot in the RT list
shared uint sharedCone;       // 1: an SSLR ray leader of the tile cone-traces

// Colours of the classes for the debug view: black sky, grey env, blue
// SSLR, purple hybrid, red RT.
const vec4 kClassColours[5] = vec4[5](vec4(0.0, 0.0, 0.0, 1.0), vec4(0.5, 0.5, 0.5, 1.0), vec4(0.1, 0.3, 1.0, 1.0),
                                      vec4(0.7, 0.2, 0.9, 1.0), vec4(1.0, 0.15, 0.1, 1.0));

// The mode and the feedback refine the distance split: ssr and rt send
// every traced pixel one way; in hybrid mode the middle band follows its
// tile's feedback (Far Cry 6 talk), except that a
// random share of an RT tile's pixels stays hybrid, so SSLR keeps being
// tried there and the tile can come back to it when SSLR starts to hit;
// in a frame where SSLR does not pay (kTileModeRtOnly) none does.
uint applyMode(uint pixelClass, uvec2 pixel) {
    const uint mode = pc.flags & kRayGenModeMask;
    if (mode == kModeSsr) {
        return kPixelSslr;
    }
    if (mode == kModeRt) {
        return kPixelRt;
    }
    // While the BVH builds, a ray traced alone could pass where an unbuilt
    // object stands: every RT pixel tries SSLR first (the Far Cry 6 talk's
    // SSLR fallback while the BVH builds).
    if ((pc.flags & kRayGenSslrFirst) != 0u) {
        return pixelClass == kPixelRt ? kPixelHybrid : pixelClass;
    }
    if (pixelClass != kPixelHybrid || (pc.flags & kRayGenTileModes) == 0u) {
        return pixelClass;
    }
    const uint tileMode = tileModes[(pixel.y / kTileSize) * pc.tilesX + pixel.x / kTileSize];
    if (tileMode == kTileModeSslr) {
        return kPixelSslr;
    }
    // The frame's SSLR does not pay (passes/feedback.h): no pixel stays
    // hybrid, so that the SSLR list stays empty.
    if (tileMode == kTileModeRtOnly) {
        return kPixelRt;
    }
    if (tileMode == kTileModeRt) {
        // A dimension of its own (glint/sampling.glsl): the pixels kept
        // hybrid draw GGX samples from the whole lobe; the share is exact
        // on average over frames.
        const float u = (pc.flags & kRayGenBlueNoise) != 0u
                            ? blueNoiseChannel(blueNoise[blueNoiseTexel(pixel, pc.frame)], kBlueNoiseRtToHybrid)
                            : scalarNoise(pixel, pc.frame, kNoiseRtToHybrid);
        return u < pc.rtToHybridShare ? kPixelHybrid : kPixelRt;
    }
    return kPixelHybrid;
}

void main() {
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    const uint lane = gl_LocalInvocationIndex;
    const bool inside = pixel.x < pc.size.x && pixel.y < pc.size.y;
    if (lane == 0u) {
        sharedSslrCount = 0u;
        sharedRtCount = 0u;
        sharedCone = 0u;
    }

    uint pixelClass = kPixelSky;
    uint direction = 0u;
    bool rough = false;
    bool cone = false;
    if (inside) {
        const ivec2 p = ivec2(pixel);
        const float depth = texelFetch(depthTexture, p, 0).x;
        const vec4 normal = texelFetch(normalTexture, p, 0);
        const float roughness = texelFetch(roughnessMetalTexture, p, 0).x;
        // gbuffer_shared.h: normal.w = 0 and depth 0 (reversed Z) where no
        // geometry was drawn.
        if (normal.w > 0.5 && depth > 0.0) {
            const vec2 ndc = (vec2(pixel) + 0.5) / vec2(pc.size) * 2.0 - 1.0;
            const vec4 world = pc.inverseViewProjection * vec4(ndc, depth, 1.0);
            const vec3 position = world.xyz / world.w;
            const vec3 toCamera = pc.cameraPosition.xyz - position;
            const float distance = length(toCamera);
            if (roughness > pc.roughnessCutoff) {
                pixelClass = kPixelEnv;
            } else {
                pixelClass = distance < pc.rtMaxDistance ? kPixelRt
                             : distance >= pc.sslrMinDistance ? kPixelSslr
                                                              : kPixelHybrid;
                pixelClass = applyMode(pixelClass, pixel);
                vec2 u;
                if ((pc.flags & kRayGenBlueNoise) != 0u) {
                    const uvec2 texel = blueNoise[blueNoiseTexel(pixel, pc.frame)];
                    u = vec2(blueNoiseChannel(texel, kBlueNoiseGgxX), blueNoiseChannel(texel, kBlueNoiseGgxY));
                } else {
                    u = ggxNoise(pixel, pc.frame);
                }
                const vec3 l = sampleReflection(normalize(normal.xyz), toCamera / distance, roughness, u);
                direction = packRayDirection(l);
                rough = (pc.flags & kRayGenReuse) != 0u && roughness >= pc.reuseRoughness;
                cone = roughness >= pc.coneRoughness;
            }
        }
    }
    sharedClass[lane] = pixelClass;
    sharedRough[lane] = rough ? 1u : 0u;
    sharedDirection[lane] = direction;
    barrier();

    // The quad's leader rotates with the frame so every pixel of a quad
    // traces its own ray once every four frames (temporal accumulation
    // then sees all four). A pixel shares the leader's ray when both are
    // rough and in the same class (the same pass will trace it).
    const uvec2 local = gl_LocalInvocationID.xy;
    const uint leaderCorner = pc.frame & 3u;
    uvec2 leaderLocal = (local & ~1u) + uvec2(leaderCorner & 1u, leaderCorner >> 1u);
    bool shares = rough;
    // Checkerboard (kRayGenCheckerboard): of the smooth hybrid and RT
    // pixels, those on the frame's off squares take the ray of their
    // neighbour in the row, an on square of the same class (FidelityFX
    // Hybrid Reflections' checkerboarded RT; the squares swap every frame,
    // so temporal accumulation sees every pixel's own ray every other frame).
    if (!rough && (pc.flags & kRayGenCheckerboard) != 0u && (pixelClass == kPixelHybrid || pixelClass == kPixelRt) &&
        ((pixel.x + pixel.y + pc.frame) & 1u) == 1u) {
        leaderLocal = uvec2(local.x ^ 1u, local.y);
        shares = sharedRough[leaderLocal.y * 8u + leaderLocal.x] == 0u;
    }
    const uint leaderLane = leaderLocal.y * 8u + leaderLocal.x;
    const uvec2 leaderPixel = gl_WorkGroupID.xy * 8u + leaderLocal;
    const bool leaderInside = leaderPixel.x < pc.size.x && leaderPixel.y < pc.size.y;
    const bool reused = shares && leaderLane != lane && leaderInside && sharedRough[leaderLane] == (rough ? 1u : 0u) &&
                        sharedClass[leaderLane] == pixelClass;

    if (inside) {
        const uint index = pixel.y * pc.size.x + pixel.x;
        classes[index] = pixelClass;
        PackedRay ray;
        if (pixelClass < kPixelSslr) {
            ray.pixelFlags = kNoRay;
            ray.direction = 0u;
        } else if (reused) {
            ray.pixelFlags = packRayPixel(leaderPixel, true);
            ray.direction = sharedDirection[leaderLane];
        } else {
            ray.pixelFlags = packRayPixel(pixel, false);
            ray.direction = direction;
        }
        rays[index] = ray;
        if ((pc.flags & kRayGenClassDebug) != 0u) {
            imageStore(classDebug, ivec2(pixel), kClassColours[pixelClass]);
        }
    }
    // Ray leaders take consecutive slots of the tile's range in their list:
    // one global atomic per tile and list, not per ray.
    const bool leader = inside && pixelClass >= kPixelSslr && !reused;
    const bool rtLeader = leader && pixelClass == kPixelRt;
    const bool sslrLeader = leader && !rtLeader;
    uint localSlot = 0u;
    if (rtLeader) {
        localSlot = atomicAdd(sharedRtCount, 1u);
    } else if (sslrLeader) {
        localSlot = atomicAdd(sharedSslrCount, 1u);
        if (cone) {
            atomicOr(sharedCone, 1u);
        }
    }
    barrier();

    if (lane == 0u) {
        if (sharedSslrCount != 0u) {
            const uint base = atomicAdd(sslrArgs[kRayListCountOffset], sharedSslrCount);
            sharedSslrBase = base;
            const uint end = base + sharedSslrCount;
            if (rayListOpensGroup(base, end)) {
                atomicMax(sslrArgs[kRayListDispatchOffset], (end + kRayListGroupSize - 1u) / kRayListGroupSize);
            }
        }
        // A ray that cone-traces needs SSLR's colour pyramid: its two passes'
        // dispatches get their z (glint/ray_generation_shared.h). Read
        // first: once a tile has set them, the others leave the two words
        // alone, rather than queue two atomics each on the same addresses
        // (a stale 0 read costs only a redundant atomicMax).
        if (sharedCone != 0u && sslrArgs[kSslrArgsPyramidOffset + 5u] == 0u) {
            atomicMax(sslrArgs[kSslrArgsPyramidOffset + 2u], 1u);
            atomicMax(sslrArgs[kSslrArgsPyramidOffset + 5u], 1u);
        }
        if (sharedRtCount != 0u) {
            const uint base = atomicAdd(rtArgs[kRayListCountOffset], sharedRtCount);
            sharedRtBase = base;
            const uint end = base + sharedRtCount;
            if (rayListOpensGroup(base, end)) {
                atomicMax(rtArgs[kRayListDispatchOffset], (end + kRayListGroupSize - 1u) / kRayListGroupSize);
            }
        }
    }
    barrier();
    if (leader) {
        PackedRay ray;
        ray.pixelFlags = packRayPixel(pixel, false);
        ray.direction = direction;
        if (rtLeader) {
            rtRays[sharedRtBase + localSlot] = ray;
        } else {
            ray.pixelFlags |= cone ? kRayCone : 0u;
            sslrRays[sharedSslrBase + localSlot] = ray;
        }
    }
}
