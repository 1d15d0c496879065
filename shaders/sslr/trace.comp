#version 460
// Screen-space reflections (passes/sslr.h): one invocation per entry of
// ray generation's SSLR ray list (dispatched indirectly from its args).
// Each ray leader of an SSLR or hybrid pixel marches its ray across the depth
// buffer in screen space: kLinearSteps large steps with a per-pixel random
// start offset, then a binary search between the last step in front of the
// surface and the first behind it (the Far Cry 6 talk's linear-then-refine
// trace; 64 + 8 steps by default). Hits sample the lit colour, re-lit for
// the direction the ray sees the surface from; the confidence falls to
// zero for misses, thick or back-facing hits and near the screen border,
// and hybrid rays below the threshold are listed for RT.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/gbuffer_shared.h"
#include "glint/brdf.glsl"
#include "glint/ray_generation_shared.h"
#include "glint/sampling.glsl"
#include "glint/sslr_shared.h"

layout(local_size_x = kRayListGroupSize) in;

layout(set = 0, binding = 0) uniform sampler2D depthTexture;
layout(set = 0, binding = 1) uniform sampler2D normalTexture;
layout(set = 0, binding = 2) uniform sampler2D litTexture;
layout(set = 0, binding = 3, scalar) readonly buffer Classes { uint classes[]; };
layout(set = 0, binding = 4, scalar) readonly buffer SslrRays { PackedRay sslrRays[]; };
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D radianceImage;
// R16F and RG32F are not among the formats every device can store with a
// format qualifier; the context enables shaderStorageImageWriteWithoutFormat.
layout(set = 0, binding = 6) uniform writeonly image2D confidenceImage;
layout(set = 0, binding = 7) uniform writeonly image2D hitImage;
layout(set = 0, binding = 8, scalar) writeonly buffer RtRays { PackedRay rtRays[]; };
layout(set = 0, binding = 9, scalar) buffer RtArgs { uint rtArgs[]; };
layout(set = 0, binding = 10) uniform sampler2D roughnessMetalTexture;
// The lit colour's box-filtered mip chain from level 1 on (pyramid_*.comp;
// level m is its mip m - 1), sampled trilinearly by the cone trace.
layout(set = 0, binding = 11) uniform sampler2D pyramidTexture;
// The SSLR list's args: its length at kRayListCountOffset.
layout(set = 0, binding = 12, scalar) readonly buffer SslrArgs { uint sslrArgs[]; };
// Ray generation's spatiotemporal blue noise (glint/sampling.glsl); read
// only with kSslrFlagBlueNoise.
layout(set = 0, binding = 13, scalar) readonly buffer BlueNoise { uvec2 blueNoise[]; };
// The G-buffer's albedo and its lighting: the re-lighting's (kSslrFlagRelight).
layout(set = 0, binding = 14) uniform sampler2D albedoTexture;
layout(set = 0, binding = 15, scalar) readonly buffer Lighting { SceneLighting lighting; };

layout(push_constant, scalar) uniform Constants { SslrConstants pc; };

// View-space z (negative in front of the camera) of a reversed-Z depth;
// see SslrConstants for the projection's form. Depth 0 (the sky) is
// infinitely far: the caller tests it first.
float viewZ(float depth) { return -pc.projection.w / (depth + pc.projection.z); }

// View-space position of a pixel position (in pixels) at a depth.
vec3 viewPosition(vec2 pixelPosition, float depth) {
    const vec2 ndc = pixelPosition / vec2(pc.size) * 2.0 - 1.0;
    const float z = viewZ(depth);
    return vec3(ndc.x * -z / pc.projection.x, ndc.y * -z / pc.projection.y, z);
}

// Homogeneous clip position (x, y, w) of a view-space point.
vec3 clipXYW(vec3 p) { return vec3(pc.projection.x * p.x, pc.projection.y * p.y, -p.z); }

vec2 toPixels(vec3 clip) { return (clip.xy / clip.z * 0.5 + 0.5) * vec2(pc.size); }

struct March {
    vec2 start;   // pixels
    vec2 delta;   // pixels, start to end
    float k0;     // 1 / w at the start (linear in screen space)
    float dk;
};

// The depth buffer's depth under the ray at screen parameter t, and its
// texel.
float depthUnder(March m, float t, out ivec2 texel) {
    texel = clamp(ivec2(floor(m.start + t * m.delta)), ivec2(0), ivec2(pc.size) - 1);
    return texelFetch(depthTexture, texel, 0).x;
}

// Whether the ray at screen parameter t lies in front of a surface of the
// depth buffer at `depth`, or over the sky (depth 0), decided in depth
// without a division: the ray's reversed-Z depth, P32 / w - P22, is affine
// in 1 / w and so in t, and lies above the buffer's where the ray is
// nearer than the surface. Most steps end here.
bool inFront(March m, float t, float depth) {
    return depth <= 0.0 || pc.projection.w * (m.k0 + t * m.dk) - pc.projection.z > depth;
}

// The ray's view distance (view units, along -z) at screen parameter t.
float rayDistance(March m, float t) { return 1.0 / (m.k0 + t * m.dk); }

// Along one axis, the screen parameter at which a ray starting at `start`
// (pixels) and moving `delta` over t in [0, 1] leaves [0, size]; 1 where it
// hardly moves along it.
float screenExit(float start, float delta, float size) {
    if (!(abs(delta) > 1e-6)) return 1.0;
    return ((delta > 0.0 ? size : 0.0) - start) / delta;
}

const float kMaxSlope = 10.0;  // the slant hitTolerance counts at most

// Half a pixel's width at a view distance, in view units.
float halfPixelAt(float surface) { return surface / (abs(pc.projection.y) * float(pc.size.y)); }

// How far behind the depth buffer at `texel` a ray's refined crossing may
// lie and still be a hit: the thickness (a share of the view distance), or
// where the surface is seen at a slant, what its depth changes over half a
// pixel. The depth buffer holds one depth per texel, its centre's; a ray
// that meets the surface where it enters the texel, half a pixel from the
// centre, lies behind that depth by up to that much: many times the
// thickness on a street far ahead or at a low resolution, where the
// thickness alone rejected real hits. (A thin object seen face on gets the
// thickness alone: a ray passing behind it is no hit.)
// `worldNormal` is the G-buffer's at the texel.
float hitTolerance(vec3 worldNormal, ivec2 texel, float depth, float surface) {
    const vec3 normal = mat3(pc.view) * worldNormal;
    const vec3 toSurface = normalize(viewPosition(vec2(texel) + 0.5, depth));
    const float facing = abs(dot(normal, toSurface));
    // tan of the angle between the view ray and the normal, at most
    // kMaxSlope.
    const float slope = sqrt(max(1.0 - facing * facing, 0.0)) / max(facing, 1.0 / kMaxSlope);
    return max(pc.thickness * surface, halfPixelAt(surface) * slope);
}

// The most hitTolerance can be at a view distance, whatever the normal: a
// crossing farther behind is no hit, decided without reading the normal
// (most crossings of a ray passing behind an occluder lie far behind it).
float largestTolerance(float surface) {
    return max(pc.thickness * surface, halfPixelAt(surface) * kMaxSlope);
}

// The lit colour at a hit texel as the ray sees it. The G-buffer lit the
// surface for the camera (glint/brdf.glsl's shadeSurface); of that light
// only the sun's specular reflection depends on the direction it leaves
// in, so the camera's is swapped for the ray's, as the ray-traced hits
// light a surface from the ray's side. The sun's visibility is the
// G-buffer's (lit.a). `worldNormal` is the G-buffer's at the texel,
// `hitView` the texel's view-space position, `worldDirection` the ray's.
vec3 relit(vec4 lit, ivec2 texel, vec3 worldNormal, vec3 hitView, vec3 worldDirection) {
    if (!(lit.a > 0.0)) return lit.rgb;  // in the sun's shadow: nothing to swap
    Surface s;
    s.position = vec3(0.0);  // unused by sunSpecular
    s.normal = worldNormal;
    s.albedo = texelFetch(albedoTexture, texel, 0).rgb;
    const vec3 material = texelFetch(roughnessMetalTexture, texel, 0).xyz;
    s.roughness = material.x;
    s.metallic = material.y;
    s.reflectance = material.z;
    // The view matrix is a rotation and translation: its inverse rotation
    // is the transpose.
    const vec3 toCamera = transpose(mat3(pc.view)) * normalize(-hitView);
    const vec3 swapped = sunSpecular(lighting, s, -worldDirection) - sunSpecular(lighting, s, toCamera);
    // The G-buffer shaded with the material's roughness and normal; they
    // come back here at 8 and 16 bits: a sharp highlight taken away may
    // exceed what it added.
    return max(lit.rgb + swapped * lit.a, vec3(0.0));
}

void writeResult(ivec2 pixel, vec3 radiance, float confidence, vec2 hitUv, bool hit, bool cone) {
    imageStore(radianceImage, pixel, vec4(radiance, hit ? (cone ? kSslrHitCone : kSslrHitRay) : 0.0));
    imageStore(confidenceImage, pixel, vec4(confidence));
    imageStore(hitImage, pixel, vec4(hitUv, 0.0, 0.0));
}

void main() {
    const uint entry = gl_GlobalInvocationID.x;
    if (entry >= sslrArgs[kRayListCountOffset]) {
        return;
    }
    // Leaders only (followers read their leader's result,
    // ray_generation_shared.h), each an SSLR or hybrid pixel.
    const PackedRay ray = sslrRays[entry];
    const uvec2 pixel = unpackRayPixel(ray.pixelFlags);
    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y) {
        return;
    }
    const uint index = pixel.y * pc.size.x + pixel.x;
    const uint pixelClass = classes[index];
    const ivec2 p = ivec2(pixel);
    const vec2 centre = vec2(pixel) + 0.5;
    const vec3 origin = viewPosition(centre, texelFetch(depthTexture, p, 0).x);
    vec3 direction = normalize(mat3(pc.view) * unpackRayDirection(ray.direction));
    // Cone trace for rough pixels (Far Cry 6 talk's rough tiles; Uludag,
    // "Hi-Z Screen-Space Cone-Traced Reflections", GPU Pro 5): march the
    // mirror direction and take the lobe's spread from the pyramid below,
    // instead of one stochastic GGX direction per frame: the result is
    // noise-free where it hits. (The RT list keeps the stochastic ray.)
    const float roughness = texelFetch(roughnessMetalTexture, p, 0).x;
    // Ray generation marks the rays that cone-trace, and opens the
    // pyramid's passes only when it marks one.
    const bool cone = pc.pyramidMips > 0u && (ray.pixelFlags & kRayCone) != 0u;
    if (cone) {
        const vec3 normalView = normalize(mat3(pc.view) * texelFetch(normalTexture, p, 0).xyz);
        const vec3 mirror = reflect(normalize(origin), normalView);
        if (dot(mirror, normalView) > 1e-3) {
            direction = normalize(mirror);
        }
    }

    // Clip the ray in view space: no further than maxDistance, and in
    // front of the near plane (z = -P32 where depth is 1) so w stays > 0.
    float rayLength = pc.maxDistance;
    const float nearZ = -pc.projection.w / (1.0 + pc.projection.z);
    if (direction.z > 0.0) {
        rayLength = min(rayLength, (nearZ - origin.z) / direction.z * 0.99);
    }
    const vec3 clip0 = clipXYW(origin);
    const vec3 clip1 = clipXYW(origin + rayLength * direction);
    March m;
    m.start = toPixels(clip0);
    m.delta = toPixels(clip1) - m.start;
    m.k0 = 1.0 / clip0.z;
    m.dk = 1.0 / clip1.z - m.k0;

    // Screen exit: the largest t in [0, 1] with the position inside the
    // image, per axis. (Not the 16 bytes of local memory NVIDIA reports for
    // this shader, GLINT_PIPELINE_STATS=1: they stayed when a loop indexing
    // m's vectors by a variable gave way to this; the optimised SPIR-V has
    // no function-local variable left.)
    const float tEnd = max(min(1.0, min(screenExit(m.start.x, m.delta.x, float(pc.size.x)),
                                        screenExit(m.start.y, m.delta.y, float(pc.size.y)))),
                           0.0);
    const float pixelsPerT = length(m.delta);

    // The random start offset (a fraction of one step, new every frame)
    // turns the banding of large steps into noise the temporal filter
    // removes (Far Cry 6 talk).
    const float jitter = (pc.flags & kSslrFlagBlueNoise) != 0u
                             ? blueNoiseChannel(blueNoise[blueNoiseTexel(pixel, pc.frame)], kBlueNoiseSslrOffset)
                             : scalarNoise(pixel, pc.frame, kNoiseSslrOffset);
    // No more steps than the ray's on-screen length has pixels per
    // minStepPixels: finer steps would read the same texels again.
    uint steps = pc.linearSteps;
    if (pc.minStepPixels > 0.0) {
        steps = clamp(uint(ceil(tEnd * pixelsPerT / pc.minStepPixels)), 1u, pc.linearSteps);
    }
    const float step = tEnd / float(steps);
    float tFront = 0.0;
    float tHit = -1.0;
    ivec2 hitTexel = ivec2(0);
    float hitDepth = 0.0;
    vec3 hitNormal = vec3(0.0);  // world, the G-buffer's at hitTexel
    float gap = 0.0;
    // A ray passing behind a thick occluder lies behind the depth buffer at
    // every step, and a search between two such steps finds that occluder
    // again. So a step behind is refined only where the last step lay in
    // front, where its own gap is thin enough to be a hit, or where the
    // depth buffer lies farther than at the last step (another surface,
    // which the ray may have met between the two). Each search costs
    // refineSteps dependent reads; searching at every step behind made
    // rays that pass behind something the pass's slowest (on the H200 at
    // 1080p the pass took 0.165 -> 0.116 ms on the plaza, 0.096 -> 0.055
    // on DamagedHelmet, for 0.7% more hybrid rays handed to RT;
    // docs/results/log/03-2026-12-03-04.md, third round).
    // One step's depth read at a time, each after the last step's test:
    // reading four steps' depths before testing the first (their reads in
    // flight together), with the refinement's midpoint and quarter points
    // read together, took 56 registers instead of 40 and made the pass
    // slower on an H100 at 1080p (0.1107 -> 0.1444 ms on the plaza, 0.1312
    // -> 0.1320 in the city; docs/results/log/07-2026-12-07.md, ninth
    // session).
    bool wasBehind = false;
    float lastSurface = 0.0;
    for (uint i = 0u; i < steps; ++i) {
        const float t = (float(i) + jitter) * step;
        // Within a pixel of the origin the ray can only find its own surface.
        if (t * pixelsPerT < 1.0) {
            tFront = t;
            continue;
        }
        ivec2 texel;
        const float depth = depthUnder(m, t, texel);
        if (inFront(m, t, depth)) {
            tFront = t;
            wasBehind = false;
            continue;
        }
        const float surface = -viewZ(depth);
        const float d = rayDistance(m, t) - surface;
        const bool sameOccluder = surface <= lastSurface * (1.0 + pc.thickness);
        lastSurface = surface;
        if (wasBehind && d > pc.thickness * surface && sameOccluder) {
            tFront = t;
            continue;
        }
        wasBehind = true;
        // A crossing: refine between the last point in front and this one.
        float lo = tFront, hi = t;
        ivec2 hiTexel = texel;
        float hiDepth = depth;
        for (uint j = 0u; j < pc.refineSteps; ++j) {
            const float mid = 0.5 * (lo + hi);
            ivec2 midTexel;
            const float midDepth = depthUnder(m, mid, midTexel);
            // Within a pixel of the origin counts as in front, as in the
            // march: there the ray leaves its own texel, whose one depth
            // (its centre's) a ray rising over a flat surface lies behind.
            // Searched into, it made the ray hit itself (confidence 0: a
            // back face) and stop.
            if (mid * pixelsPerT < 1.0 || inFront(m, mid, midDepth)) {
                lo = mid;
            } else {
                hi = mid;
                hiTexel = midTexel;
                hiDepth = midDepth;
            }
        }
        const float hiSurface = -viewZ(hiDepth);
        const float hiGap = rayDistance(m, hi) - hiSurface;
        // Thickness test: the depth buffer holds only front surfaces, so a
        // ray found far behind one passed behind it; keep marching.
        if (hiGap > largestTolerance(hiSurface)) {
            tFront = t;
            continue;
        }
        const vec3 hiNormal = texelFetch(normalTexture, hiTexel, 0).xyz;
        const float tolerance = hitTolerance(hiNormal, hiTexel, hiDepth, hiSurface);
        if (hiGap <= tolerance) {
            tHit = hi;
            hitTexel = hiTexel;
            hitDepth = hiDepth;
            hitNormal = hiNormal;
            gap = hiGap / tolerance;
            break;
        }
        tFront = t;
    }

    float confidence = 0.0;
    vec3 radiance = vec3(0.0);
    vec2 hitUv = vec2(0.0);
    if (tHit >= 0.0) {
        hitUv = sslrHitUv(uvec2(hitTexel), pc.size);
        // Back faces: the hit surface must face the ray (world normals; the
        // view matrix is a rotation and translation, so its inverse
        // rotation is the transpose).
        const vec3 worldDirection = cone ? transpose(mat3(pc.view)) * direction : unpackRayDirection(ray.direction);
        const float facing = dot(hitNormal, worldDirection) < 0.0 ? 1.0 : 0.0;
        const vec3 hitPosition = viewPosition(vec2(hitTexel) + 0.5, hitDepth);
        // The cone trace's pyramid level (0: the hit texel alone). The GGX
        // lobe around the mirror direction falls to half its peak at
        // tan(theta_h) = alpha sqrt(sqrt(2) - 1) ~ 0.64 alpha for the half
        // vector, twice that for the reflected ray. Its diameter where the
        // ray meets the surface, d * 2 tan, in that depth's pixels, is the
        // footprint; the pyramid level whose texels span it holds the
        // lobe's mean colour.
        float mip = 0.0;
        if (cone) {
            const float alpha = roughness * roughness;
            const float distance = length(hitPosition - origin);
            const float pixelsPerUnit = 0.5 * abs(pc.projection.y) * float(pc.size.y) / max(-hitPosition.z, 1e-6);
            const float footprint = 2.0 * 1.287 * alpha * distance * pixelsPerUnit;
            mip = clamp(log2(max(footprint, 1.0)), 0.0, float(pc.pyramidMips - 1u));
        }
        // Trilinear over the chain: the pyramid holds level m as its mip
        // m - 1; between levels 0 and 1 the hit texel (level 0's bilinear
        // at the hit's centre) blends with level 1. Only the texel is
        // re-lit for the ray: the pyramid's levels are lit for the camera,
        // and a footprint of many texels averages highlights that no one
        // swap would place.
        if (mip >= 1.0) {
            radiance = textureLod(pyramidTexture, hitUv, mip - 1.0).rgb;
        } else {
            const vec4 lit = texelFetch(litTexture, hitTexel, 0);
            radiance = (pc.flags & kSslrFlagRelight) != 0u && facing > 0.0
                           ? relit(lit, hitTexel, hitNormal, hitPosition, worldDirection)
                           : lit.rgb;
            if (mip > 0.0) {
                radiance = mix(radiance, textureLod(pyramidTexture, hitUv, 0.0).rgb, mip);
            }
        }
        // Fade near the border, where neighbouring rays start to leave the
        // screen, and as the hit's depth gap approaches the thickness (as
        // FidelityFX SSSR validates its hits).
        const vec2 border = min(hitUv, 1.0 - hitUv);
        const float edge = clamp(min(border.x, border.y) / max(pc.edgeFade, 1e-6), 0.0, 1.0);
        const float thick = 1.0 - smoothstep(0.5, 1.0, gap);
        confidence = clamp(facing * edge * thick, 0.0, 1.0);
    }
    writeResult(p, radiance, confidence, hitUv, tHit >= 0.0, cone);

    // Only hybrid rays go on: SSLR-class pixels lie beyond the BVH's reach
    //, where the ray tracer could find nothing better.
    // "Not at least the threshold", so a NaN goes on too: readers find the
    // ray traced wherever the stored confidence is not at least the
    // threshold (glint/sslr_shared.h).
    if (pixelClass == kPixelHybrid && !(confidence >= pc.confidenceThreshold)) {
        // Appended after ray generation's RT rays (glint/ray_generation_shared.h).
        const uint slot = atomicAdd(rtArgs[kRayListCountOffset], 1u);
        PackedRay handed = ray;
        handed.pixelFlags &= ~kRayCone;  // a mark for SSLR alone
        rtRays[slot] = handed;
        if (rayListOpensGroup(slot, slot + 1u)) {
            atomicMax(rtArgs[kRayListDispatchOffset], slot / kRayListGroupSize + 1u);
        }
    }
}
