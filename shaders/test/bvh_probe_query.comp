#version 460
// Test probe, ray query backend: traces BvhProbeRays through the BVH
// update's TLAS and reads the hit's packed surface from the primitive pool
// through the primitive offset buffer, as the reflection hit path does.
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/bvh_shared.h"
#include "glint/packing.h"

layout(local_size_x = kBvhProbeGroupSize) in;

layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1, scalar) readonly buffer Pool { PackedPrimitive pool[]; };
layout(set = 0, binding = 2, scalar) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 3, scalar) readonly buffer Rays { BvhProbeRay rays[]; };
layout(set = 0, binding = 4, scalar) writeonly buffer Hits { BvhProbeHit hits[]; };
layout(push_constant, scalar) uniform Push { uint rayCount; };

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= rayCount) {
        return;
    }
    const BvhProbeRay ray = rays[i];
    rayQueryEXT query;
    rayQueryInitializeEXT(query, tlas, gl_RayFlagsOpaqueEXT, kInstanceMaskAll, ray.origin, ray.tMin, ray.direction,
                          ray.tMax);
    while (rayQueryProceedEXT(query)) {
    }
    BvhProbeHit h;
    h.hit = 0u;
    if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        h.hit = 1u;
        h.customIndex = rayQueryGetIntersectionInstanceCustomIndexEXT(query, true);
        h.geometry = rayQueryGetIntersectionGeometryIndexEXT(query, true);
        h.primitive = rayQueryGetIntersectionPrimitiveIndexEXT(query, true);
        h.t = rayQueryGetIntersectionTEXT(query, true);
        h.barycentrics = rayQueryGetIntersectionBarycentricsEXT(query, true);
        const uint slot = primitiveOffsetSlot(h.customIndex, h.geometry);
        const SurfaceVertex s = interpolateSurface(pool[offsets[slot] + h.primitive], h.barycentrics);
        h.albedo = s.albedo;
        h.roughness = s.roughness;
        h.normal = s.normal;
        h.metallic = s.metallic;
        h.reflectance = s.reflectance;
    }
    hits[i] = h;
}
