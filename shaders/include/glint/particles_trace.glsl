// The particle trace (passes/particles.h): everything but the traversal,
// shared by its two backends (shaders/particles/trace_query.comp with ray
// query, shaders/particles/trace.rgen + trace.rahit with a ray tracing
// pipeline), so they give identical results: both hand every particle
// quad the ray crosses to particleConsiderHit, which keeps the nearest
// kParticleMaxHits covering ones in a sorted list, and the list is
// composited front to back here.
//
// One invocation per entry of ray generation's lists, i.e. per ray leader
// of a traced pixel (a follower's reflection takes its leader's particles
// in integrate, as it takes its traces): the SSLR list's leaders, then the
// RT list's RT pixels (its hybrid entries are SSLR's failures, traced with
// the SSLR list). The ray leaves the G-buffer surface along ray
// generation's direction and ends where the pixel's reflection ends: the
// hit distance of the trace integrate takes
// (glint/integrate_shared.h's chooseReflectionTrace over the same SSLR and
// RT outputs), so particles behind the reflected surface are not
// composited. Misses end at maxDistance. Only the leaders' texels are
// written.
#ifndef GLINT_PARTICLES_TRACE_GLSL
#define GLINT_PARTICLES_TRACE_GLSL

#extension GL_EXT_scalar_block_layout : require

#include "glint/integrate_shared.h"
#include "glint/particles_shared.h"
#include "glint/ray_generation_shared.h"
#include "glint/sslr_shared.h"

// Bindings (passes/particles.cpp pushes the same).
layout(set = 0, binding = 0) uniform accelerationStructureEXT particleTlas;
layout(set = 0, binding = 1) uniform sampler2D depthTexture;
layout(set = 0, binding = 2, scalar) readonly buffer RayList { PackedRay rayList[]; };
layout(set = 0, binding = 3, scalar) readonly buffer Classes { uint classes[]; };
layout(set = 0, binding = 4, scalar) readonly buffer Particles { ParticleData particles[]; };
layout(set = 0, binding = 5, scalar) readonly buffer Constants { ParticleTraceConstants C; };
layout(set = 0, binding = 6) uniform sampler2D sslrRadianceTexture;
layout(set = 0, binding = 7) uniform sampler2D sslrConfidenceTexture;
layout(set = 0, binding = 8) uniform sampler2D sslrHitTexture;
layout(set = 0, binding = 9) uniform sampler2D rtRadianceTexture;
layout(set = 0, binding = 10) uniform sampler2D rtHitDistanceTexture;
layout(set = 0, binding = 11, rgba16f) uniform writeonly image2D particleImage;
// The walked list's args (glint/ray_generation_shared.h): its length.
layout(set = 0, binding = 12, scalar) readonly buffer RayListArgs { uint rayListArgs[]; };
layout(push_constant, scalar) uniform Push { ParticleTracePush pushed; };

// The nearest covering particle hits of one ray, sorted by (t, particle).
struct ParticleHits {
    uint count;
    float t[kParticleMaxHits];
    uint particle[kParticleMaxHits];
};

void particleHitsClear(inout ParticleHits h) {
    h.count = 0u;
    for (uint i = 0u; i < kParticleMaxHits; ++i) {
        h.t[i] = 0.0;
        h.particle[i] = 0u;
    }
}

// Adds (t, particle) keeping the kParticleMaxHits smallest, one entry per
// particle (its nearer triangle: a ray along a quad's diagonal may report
// both). The result does not depend on the order hits arrive in, which
// traversal does not define.
void particleHitsInsert(inout ParticleHits h, float t, uint particle) {
    for (uint i = 0u; i < h.count; ++i) {
        if (h.particle[i] == particle) {
            if (t >= h.t[i]) {
                return;
            }
            for (uint j = i; j + 1u < h.count; ++j) {
                h.t[j] = h.t[j + 1u];
                h.particle[j] = h.particle[j + 1u];
            }
            h.count -= 1u;
            break;
        }
    }
    uint position = h.count;
    for (uint i = 0u; i < h.count; ++i) {
        if (t < h.t[i] || (t == h.t[i] && particle < h.particle[i])) {
            position = i;
            break;
        }
    }
    if (position >= kParticleMaxHits) {
        return;
    }
    for (uint j = min(h.count, kParticleMaxHits - 1u); j > position; --j) {
        h.t[j] = h.t[j - 1u];
        h.particle[j] = h.particle[j - 1u];
    }
    h.t[position] = t;
    h.particle[position] = particle;
    h.count = min(h.count + 1u, kParticleMaxHits);
}

// A quad the ray crosses at t: kept when the particle covers that point.
void particleConsiderHit(inout ParticleHits h, vec3 origin, vec3 direction, float t, uint primitive) {
    const uint particle = primitive / 2u;
    if (particle >= uint(particles.length())) {
        return;
    }
    if (particleCoverageAt(particles[particle], origin + t * direction) > 0.0) {
        particleHitsInsert(h, t, particle);
    }
}

#ifndef GLINT_PARTICLES_ANY_HIT

// The largest finite half float: the RGBA16F output's limit.
const float kParticleMaxHalf = 65504.0;

// The backend's traversal: every particle quad on [0, tMax] in the
// instances `cullMask` selects offered to particleConsiderHit, none
// committed.
ParticleHits particleTraceSegment(vec3 origin, vec3 direction, float tMax, uint cullMask);

// The particle TLAS instance a ray sees: the quads facing the camera axis
// its direction is largest along (glint/particles_shared.h).
uint particleCullMask(vec3 direction) {
    const vec3 view = vec3(dot(direction, C.cameraRight.xyz), dot(direction, C.cameraUp.xyz),
                           dot(direction, C.cameraBack.xyz));
    return particleAxisMask(particleQuadAxis(view));
}

// Whether the segment from `origin` along `direction` (unit) to tMax meets
// the particles' box (slab test; a zero component divides to +-infinity,
// which the slabs handle).
bool particleSegmentMeetsBounds(vec3 origin, vec3 direction, float tMax) {
    const vec3 inverse = 1.0 / direction;
    const vec3 a = (C.boundsMin.xyz - origin) * inverse;
    const vec3 b = (C.boundsMax.xyz - origin) * inverse;
    const vec3 near = min(a, b), far = max(a, b);
    const float enter = max(max(near.x, near.y), max(near.z, 0.0));
    const float leave = min(min(far.x, far.y), min(far.z, tMax));
    return enter <= leave;
}

bool particleFinite(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }
bool particleFinite(vec3 v) { return particleFinite(v.x) && particleFinite(v.y) && particleFinite(v.z); }

// World position of a pixel position (in pixels) at a reversed-Z depth, as
// integrate reconstructs it.
vec3 particleWorldPosition(vec2 pixelPosition, float depth) {
    const vec2 ndc = pixelPosition / vec2(C.size) * 2.0 - 1.0;
    const vec4 world = C.inverseViewProjection * vec4(ndc, depth, 1.0);
    return world.xyz / world.w;
}

// The distance integrate will give pixel p's reflection and the trace it
// takes it from (integrate.glsl, same inputs, same choice).
float particleReflectionDistance(ivec2 p, uint pixelClass, vec3 position, out uint trace) {
    float confidence = 0.0;
    vec2 sslrHitUv = vec2(0.0);
    // Where SSLR handed the ray on, as integrate decides it (integrate.glsl).
    bool handedToRt = pixelClass == kPixelRt || pixelClass == kPixelHybrid;
    if (C.sslrBound != 0u && (pixelClass == kPixelSslr || pixelClass == kPixelHybrid)) {
        const vec4 radiance = texelFetch(sslrRadianceTexture, p, 0);
        const float c = texelFetch(sslrConfidenceTexture, p, 0).x;
        const bool countsOnly = C.sslrBound == 2u && pixelClass == kPixelHybrid;
        handedToRt = pixelClass == kPixelHybrid && (countsOnly || !(c >= C.confidenceThreshold));
        const vec2 hitUv = texelFetch(sslrHitTexture, p, 0).xy;
        if (radiance.a > 0.5 && particleFinite(radiance.rgb) && particleFinite(c) && particleFinite(hitUv.x) &&
            particleFinite(hitUv.y)) {
            confidence = countsOnly ? 0.0 : sslrHitConfidence(clamp(c, 0.0, 1.0), C.rtMissesTrusted != 0u);
            sslrHitUv = hitUv;
        }
    }
    bool rtTraced = false;
    float rtHitDistance = kMissHitDistance;
    if (C.rtBound != 0u && handedToRt) {
        const vec4 radiance = texelFetch(rtRadianceTexture, p, 0);
        const float d = texelFetch(rtHitDistanceTexture, p, 0).x;
        rtTraced = radiance.a > 0.5 && particleFinite(radiance.rgb);
        rtHitDistance = particleFinite(d) ? clamp(d, 0.0, kMissHitDistance) : kMissHitDistance;
    }
    trace = chooseReflectionTrace(confidence, C.confidenceThreshold, rtTraced,
                                  C.rtMissesTrusted != 0u || rtHitDistance < kMissHitDistance);
    if (trace == kTraceRt) {
        return rtHitDistance;
    }
    if (trace == kTraceSslr) {
        const ivec2 hitTexel = ivec2(sslrHitTexel(sslrHitUv, C.size));
        const float hitDepth = texelFetch(depthTexture, hitTexel, 0).x;
        if (hitDepth > 0.0) {
            const vec3 hitPosition = particleWorldPosition(vec2(hitTexel) + 0.5, hitDepth);
            return min(length(hitPosition - position), kMissHitDistance);
        }
    }
    return kMissHitDistance;
}

// Front to back: premultiplied rgb, a = coverage.
vec4 particleComposite(ParticleHits h, vec3 origin, vec3 direction) {
    vec4 sum = vec4(0.0);
    for (uint i = 0u; i < h.count; ++i) {
        const ParticleData particle = particles[h.particle[i]];
        const float a = particleCoverageAt(particle, origin + h.t[i] * direction);
        sum.rgb += (1.0 - sum.a) * a * max(particle.color.rgb, vec3(0.0));
        sum.a += (1.0 - sum.a) * a;
    }
    return sum;
}

// Traces the ray of list slot `slot` (a traced pixel's leader) and writes
// its pixel's particles (0 where it finds none).
void particleTraceSlot(uint slot) {
    if (slot >= rayListArgs[kRayListCountOffset]) {
        return;  // the ray query backend's last group
    }
    const PackedRay ray = rayList[slot];
    const uvec2 pixel = unpackRayPixel(ray.pixelFlags);
    if (pixel.x >= C.size.x || pixel.y >= C.size.y) {
        return;
    }
    const ivec2 p = ivec2(pixel);
    const uint pixelClass = classes[pixel.y * C.size.x + pixel.x];
    if (pushed.list == kParticleListRt && pixelClass == kPixelHybrid) {
        return;  // SSLR's failure, traced from the SSLR list
    }
    vec4 result = vec4(0.0);
    const float depth = texelFetch(depthTexture, p, 0).x;
    if (depth > 0.0) {
        const vec3 position = particleWorldPosition(vec2(pixel) + 0.5, depth);
        const vec3 direction = unpackRayDirection(ray.direction);
        // A ray whose longest segment misses the particles' box has
        // nothing to find: it skips the reads that find where its
        // reflection ends (on the H200 at 1080p they were most of this
        // pass's time on the plaza, the trace itself a tenth).
        if (particleFinite(position) && particleSegmentMeetsBounds(position, direction, C.maxDistance)) {
            uint trace;
            const float tMax = min(particleReflectionDistance(p, pixelClass, position, trace), C.maxDistance);
            // What SSLR resolved already shows the particles it saw in
            // the lit colour: each particle reaches a pixel by one road.
            const bool seenBySslr = C.sslrSeesParticles != 0u && trace == kTraceSslr;
            if (!seenBySslr && tMax > 0.0 && particleSegmentMeetsBounds(position, direction, tMax)) {
                const ParticleHits hits = particleTraceSegment(position, direction, tMax, particleCullMask(direction));
                result = particleComposite(hits, position, direction);
            }
        }
    }
    result.rgb = clamp(result.rgb, vec3(0.0), vec3(kParticleMaxHalf));
    imageStore(particleImage, p, result);
}

#endif

#endif
