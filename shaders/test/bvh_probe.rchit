#version 460
// The packed-primitive hit path: instance custom index + geometry index ->
// primitive offset -> the hit triangle's packed surface.
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/bvh_shared.h"
#include "glint/packing.h"

layout(set = 0, binding = 1, scalar) readonly buffer Pool { PackedPrimitive pool[]; };
layout(set = 0, binding = 2, scalar) readonly buffer Offsets { uint offsets[]; };

layout(location = 0) rayPayloadInEXT BvhProbeHit payload;
hitAttributeEXT vec2 barycentrics;

void main() {
    payload.hit = 1u;
    payload.customIndex = gl_InstanceCustomIndexEXT;
    payload.geometry = gl_GeometryIndexEXT;
    payload.primitive = gl_PrimitiveID;
    payload.t = gl_HitTEXT;
    payload.barycentrics = barycentrics;
    const uint slot = primitiveOffsetSlot(gl_InstanceCustomIndexEXT, gl_GeometryIndexEXT);
    const SurfaceVertex s = interpolateSurface(pool[offsets[slot] + gl_PrimitiveID], barycentrics);
    payload.albedo = s.albedo;
    payload.roughness = s.roughness;
    payload.normal = s.normal;
    payload.metallic = s.metallic;
    payload.reflectance = s.reflectance;
}
