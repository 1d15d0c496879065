#version 460
// The one hit shader of the ray-traced reflections (passes/rt_trace.h) for
// primary and shadow rays alike: it reports which triangle was hit, where
// and under which instance transform; the ray generation shader reads the
// packed primitive and lights it (glint/rt_trace.glsl), as the ray query
// backend does.
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require

#include "glint/rt_hit.glsl"

layout(location = 0) rayPayloadInEXT RtHit payload;
hitAttributeEXT vec2 barycentrics;

void main() {
    payload.hit = 1u;
    payload.customIndex = gl_InstanceCustomIndexEXT;
    payload.geometry = gl_GeometryIndexEXT;
    payload.primitive = gl_PrimitiveID;
    payload.barycentrics = barycentrics;
    payload.t = gl_HitTEXT;
    payload.worldToObject = mat3(gl_WorldToObjectEXT);
}
