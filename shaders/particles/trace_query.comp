#version 460
// The particle trace (passes/particles.h), ray query backend: one
// invocation per ray list entry. The particle quads are not opaque, so
// every quad on the segment comes back as a candidate; none is committed
// (the nearest hits are kept in the invocation's list instead). Everything else is
// glint/particles_trace.glsl, shared with the ray tracing pipeline backend.
#extension GL_EXT_ray_query : require
#extension GL_GOOGLE_include_directive : require

#include "glint/particles_trace.glsl"

layout(local_size_x = kRayListGroupSize) in;

ParticleHits particleTraceSegment(vec3 origin, vec3 direction, float tMax, uint cullMask) {
    ParticleHits hits;
    particleHitsClear(hits);
    rayQueryEXT query;
    rayQueryInitializeEXT(query, particleTlas, gl_RayFlagsNoneEXT, cullMask, origin, 0.0, direction, tMax);
    while (rayQueryProceedEXT(query)) {
        if (rayQueryGetIntersectionTypeEXT(query, false) == gl_RayQueryCandidateIntersectionTriangleEXT) {
            particleConsiderHit(hits, origin, direction, rayQueryGetIntersectionTEXT(query, false),
                                uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, false)));
        }
    }
    return hits;
}

void main() {
    particleTraceSlot(gl_GlobalInvocationID.x);
}
