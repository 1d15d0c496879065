// The ray-traced hits and lighting pass (passes/rt_trace.h): everything but
// the traversal, shared by its two backends (shaders/rt_trace/trace_query.comp
// with ray query, shaders/rt_trace/trace.rgen with a ray tracing pipeline),
// so they give bit-identical results. A backend enables its ray extension,
// includes this file, defines the two trace functions declared below and
// calls rtTraceListEntry() once per list entry.
//
// Per entry: the origin is the G-buffer surface at the entry's pixel,
// reconstructed from depth and moved off the surface (rtOffsetOrigin); the
// ray's length shrinks with the surface's roughness; a hit's packed
// primitive (glint/packing.h) is interpolated at the hit's barycentrics and
// lit with the G-buffer's own lighting (glint/brdf.glsl's shadeSurface),
// the sun's visibility from a shadow ray (or, with shadowMapAtHits, from
// the G-buffer's shadow map where it covers the hit), plus its geometry's
// emission (one colour per geometry: the material's mean, scaled as the
// G-buffer scales emission); a miss takes the environment. Both rays pass through the
// cut-outs of alpha-tested geometry (glint/rt_geometry.glsl).
#ifndef GLINT_RT_TRACE_GLSL
#define GLINT_RT_TRACE_GLSL

#extension GL_EXT_scalar_block_layout : require

#include "glint/gbuffer_shared.h"
// The prefiltered environment (glint/environment.glsl): misses and the
// hits' ambient light.
#define GLINT_ENVIRONMENT_BINDING 11
#include "glint/brdf.glsl"
#include "glint/bvh_shared.h"
#include "glint/packing.h"
#include "glint/ray_generation_shared.h"
#include "glint/rt_hit.glsl"
#include "glint/rt_trace_shared.h"

// Bindings (passes/rt_trace.cpp pushes the same).
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1) uniform sampler2D depthTexture;
layout(set = 0, binding = 2) uniform sampler2D normalTexture;
layout(set = 0, binding = 3) uniform sampler2D roughnessMetalTexture;
layout(set = 0, binding = 4, scalar) readonly buffer RayList { PackedRay rayList[]; };
layout(set = 0, binding = 5, scalar) readonly buffer RayListArgs { uint rayListArgs[]; };
layout(set = 0, binding = 6, scalar) readonly buffer Pool { PackedPrimitive pool[]; };
layout(set = 0, binding = 7, scalar) readonly buffer Offsets { uint primitiveOffsets[]; };
layout(set = 0, binding = 8, scalar) readonly buffer Constants { RtTraceConstants rt; };
layout(set = 0, binding = 9, rgba16f) uniform writeonly image2D radianceImage;
layout(set = 0, binding = 10, r32f) uniform writeonly image2D hitDistanceImage;
// xyz: where the hit point was last frame minus where it is (world; zero
// for misses and still objects); RGBA16F has no required storage format:
// the context enables shaderStorageImageWriteWithoutFormat.
layout(set = 0, binding = 15) uniform writeonly image2D hitMotionImage;
// How this frame's rebuilt deformable geometry moved inside its objects
// (RtGeometryMaterial::deformMotion).
layout(set = 0, binding = 16, scalar) readonly buffer DeformMotions { DeformMotion deformMotions[]; };
// Bindings 12-14: the material rows and the alpha test.
#include "glint/rt_geometry.glsl"
// The G-buffer's shadow map (read where rt.shadowMapAtHits is 1; otherwise
// a stand-in texture).
layout(set = 0, binding = 17) uniform sampler2D shadowMapTexture;
#include "glint/sun_shadow.glsl"

// The backend's traversals, both with rt.instanceMask and rtRayFlags():
// alpha-tested geometry is not opaque in its BLAS, and a candidate counts
// only where rtAlphaCovers() says so (an any-hit shader, or the ray query's
// candidate loop).
RtHit rtTraceClosest(vec3 origin, vec3 direction, float tMax);
// Whether anything lies on the segment (it may stop at the first hit).
bool rtTraceOccluded(vec3 origin, vec3 direction, float tMax);

struct RtRay {
    ivec2 pixel;      // where the result goes (the ray's own pixel or its quad leader's)
    vec3 origin;      // world, off the surface
    vec3 direction;   // world, unit
    float tMax;
    float roughness;  // perceptual, of the surface the ray leaves
};

// With the alpha test off (RtTraceSettings::alphaTest) every triangle is
// opaque, whatever its BLAS says: no any-hit shader runs.
uint rtRayFlags() { return rt.alphaTest != 0u ? gl_RayFlagsNoneEXT : gl_RayFlagsOpaqueEXT; }

float rtMax3(vec3 v) { return max(v.x, max(v.y, v.z)); }

// One unit in the last place of a positive normal float: its exponent's
// power of two times 2^-23 (exact; no transcendental to round differently).
float rtUlp(float x) { return uintBitsToFloat(floatBitsToUint(x) & 0x7F800000u) * (1.0 / 8388608.0); }

// `p` moved along the unit normal `n` off its surface by the expected error
// of a point computed from coordinates as large as p's and `reference`'s,
// measured over `distance` with `errorPerDistance` beyond float rounding
// (glint/rt_trace_shared.h's robust ray origins).
vec3 rtOffsetOrigin(vec3 p, vec3 n, vec3 reference, float distance, float errorPerDistance) {
    const float magnitude = max(max(rtMax3(abs(p)), rtMax3(abs(reference))), kRtOriginMinimum);
    const float offset = kRtOriginUlps * rtUlp(magnitude) + (kRtDistanceRelativeError + errorPerDistance) * distance;
    return p + n * (offset * rt.originOffsetScale);
}

// Rougher reflections blur what they meet, so far hits are worth less than
// their cost: the length falls linearly from maxDistance at roughness 0 to
// shortRangeFraction of it at shortRangeRoughness and beyond (the Far Cry 6
// talk's range shrinking with roughness).
float rtRayLength(float roughness) {
    const float k = clamp(roughness / max(rt.shortRangeRoughness, 1e-6), 0.0, 1.0);
    return rt.maxDistance * mix(1.0, rt.shortRangeFraction, k);
}

// The ray of list entry `index`; false where the entry names no surface
// (no ray, a pixel outside the image, the sky), which traces nothing.
bool rtSetupRay(uint index, out RtRay ray) {
    const PackedRay packed = rayList[index];
    ray.pixel = ivec2(0);
    ray.origin = vec3(0.0);
    ray.direction = vec3(0.0, 1.0, 0.0);
    ray.tMax = 0.0;
    ray.roughness = 0.0;
    if (packed.pixelFlags == kNoRay) {
        return false;
    }
    const uvec2 pixel = unpackRayPixel(packed.pixelFlags);
    if (pixel.x >= rt.size.x || pixel.y >= rt.size.y) {
        return false;
    }
    const ivec2 p = ivec2(pixel);
    const float depth = texelFetch(depthTexture, p, 0).x;
    const vec4 normal = texelFetch(normalTexture, p, 0);
    // glint/gbuffer_shared.h: depth 0 and normal.w 0 where nothing was drawn.
    if (depth <= 0.0 || normal.w < 0.5) {
        return false;
    }
    // The surface at the pixel's (jittered) sample: see RtTraceConstants.
    const vec2 ndc = (vec2(pixel) + 0.5) / vec2(rt.size) * 2.0 - 1.0;
    const vec4 world = rt.inverseViewProjection * vec4(ndc, depth, 1.0);
    const vec3 position = world.xyz / world.w;
    const vec3 n = normalize(normal.xyz);
    ray.pixel = p;
    ray.origin = rtOffsetOrigin(position, n, rt.cameraPosition.xyz, length(rt.cameraPosition.xyz - position),
                                rt.rasterErrorPerDistance);
    ray.direction = unpackRayDirection(packed.direction);
    ray.roughness = clamp(texelFetch(roughnessMetalTexture, p, 0).x, 0.0, 1.0);
    ray.tMax = rtRayLength(ray.roughness);
    return true;
}

// The packed surface at a hit, in world space. Reflection rays pass
// through the backs of single-sided triangles (traversal culls them), so a
// back face hit is double-sided: lit as a front face, the normal turned
// towards the ray, as the G-buffer turns a double-sided back face's.
Surface rtHitSurface(RtRay ray, RtHit hit) {
    const uint slot = primitiveOffsetSlot(hit.customIndex, hit.geometry);
    const SurfaceVertex v = interpolateSurface(pool[primitiveOffsets[slot] + hit.primitive], hit.barycentrics);
    // Normals transform by the inverse transpose of the object-to-world map.
    const vec3 n = normalize(transpose(hit.worldToObject) * v.normal);
    Surface s;
    s.position = ray.origin + hit.t * ray.direction;
    s.normal = faceforward(n, ray.direction, n);
    s.albedo = v.albedo;
    s.roughness = v.roughness;
    s.metallic = v.metallic;
    s.reflectance = v.reflectance;
    return s;
}

void rtWriteResult(RtRay ray, vec3 radiance, float hitDistance, vec3 hitMotion) {
    imageStore(radianceImage, ray.pixel, vec4(radiance, 1.0));
    imageStore(hitDistanceImage, ray.pixel, vec4(hitDistance));
    imageStore(hitMotionImage, ray.pixel, vec4(hitMotion, 0.0));
}

// Where the hit point was last frame, relative to where it is: its
// instance's motion (glint/alpha_test.h's previousFromCurrent) and, on
// geometry whose BLAS was rebuilt this frame, its triangle's own movement
// inside the object (skinning, morphing) at the hit's barycentrics.
vec3 rtHitMotion(RtHit hit, vec3 position) {
    const RtGeometryMaterial m = rtGeometryMaterial(hit.customIndex, hit.geometry);
    const mat4x3 previousFromCurrent =
        transpose(mat3x4(m.previousFromCurrent[0], m.previousFromCurrent[1], m.previousFromCurrent[2]));
    vec3 previous = previousFromCurrent * vec4(position, 1.0);
    if (m.deformMotion != kNoDeformMotion) {
        const DeformMotion d = deformMotions[m.deformMotion + hit.primitive];
        const vec3 w = vec3(1.0 - hit.barycentrics.x - hit.barycentrics.y, hit.barycentrics);
        vec3 moved = vec3(0.0);
        for (int k = 0; k < 3; ++k) {
            moved += w[k] * vec3(unpackHalf2x16(d.vertices[k].x), unpackHalf2x16(d.vertices[k].y).x);
        }
        // Last frame's object-to-world linear part is previousFromCurrent's
        // times this frame's.
        previous += mat3(previousFromCurrent) * (inverse(hit.worldToObject) * moved);
    }
    return previous - position;
}

// Traces list entry `index` and writes its result.
void rtTraceListEntry(uint index) {
    RtRay ray;
    if (!rtSetupRay(index, ray)) {
        return;
    }
    const RtHit hit = rtTraceClosest(ray.origin, ray.direction, ray.tMax);
    if (hit.hit == 0u) {
        rtWriteResult(ray, environmentRadiance(rt.lighting, ray.direction, ray.roughness), kMissHitDistance, vec3(0.0));
        return;
    }
    const Surface s = rtHitSurface(ray, hit);
    const vec3 toSun = rt.lighting.sunDirection.xyz;
    float sunVisibility = 1.0;
    // Facing away from the sun, the sun adds nothing whatever its visibility.
    const float NoL = dot(s.normal, toSun);
    if (rt.shadows != 0u && NoL > 0.0) {
        // The shadow map where it covers the hit (inside it; a map fitted
        // to the view fades out from fadeStart, and from there the ray
        // answers; a map of the whole scene does not fade), else a shadow
        // ray.
        float mapVisibility = -1.0;
        const bool faded = rt.shadow.fadeEnd > rt.shadow.fadeStart &&
                           !(distance(s.position, rt.cameraPosition.xyz) < rt.shadow.fadeStart);
        if (rt.shadowMapAtHits != 0u && !faded) {
            mapVisibility = sunShadowMapVisibility(shadowMapTexture, rt.shadow, NoL, s.position, s.normal);
        }
        if (mapVisibility >= 0.0) {
            sunVisibility = mapVisibility;
        } else {
            // The hit point's error grows with the origin's magnitude and t.
            const vec3 shadowOrigin = rtOffsetOrigin(s.position, s.normal, ray.origin, hit.t, 0.0);
            sunVisibility = rtTraceOccluded(shadowOrigin, toSun, rt.shadowDistance) ? 0.0 : 1.0;
        }
    }
    // Emission, unlit and unshadowed as in the G-buffer's lit colour.
    const vec3 emission = rtGeometryMaterial(hit.customIndex, hit.geometry).emission * rt.lighting.sunDirection.w;
    rtWriteResult(ray, shadeSurface(rt.lighting, s, -ray.direction, sunVisibility) + emission, hit.t,
                  rtHitMotion(hit, s.position));
}

#endif
