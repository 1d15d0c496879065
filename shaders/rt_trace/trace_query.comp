#version 460
// Ray-traced hits and lighting (passes/rt_trace.h), ray query backend:
// one invocation per RT list entry, dispatched indirectly from the list's
// args (word 0); invocations past the list's length (word
// kRayListCountOffset) trace nothing. Everything but the two traversals is
// glint/rt_trace.glsl, shared with the ray tracing pipeline backend.
#extension GL_EXT_ray_query : require
#extension GL_GOOGLE_include_directive : require

#include "glint/rt_trace.glsl"

layout(local_size_x = kRtTraceGroupSize) in;

// Traversal: the only candidates are triangles of alpha-tested (not opaque)
// geometry; each one that covers its point is committed, as the pipeline's
// any-hit shader accepts it (a ray that terminates on its first hit then
// stops).
void rtProceed(rayQueryEXT query) {
    while (rayQueryProceedEXT(query)) {
        if (rayQueryGetIntersectionTypeEXT(query, false) == gl_RayQueryCandidateIntersectionTriangleEXT &&
            rtAlphaCovers(rayQueryGetIntersectionInstanceCustomIndexEXT(query, false),
                          rayQueryGetIntersectionGeometryIndexEXT(query, false),
                          rayQueryGetIntersectionPrimitiveIndexEXT(query, false),
                          rayQueryGetIntersectionBarycentricsEXT(query, false))) {
            rayQueryConfirmIntersectionEXT(query);
        }
    }
}

RtHit rtTraceClosest(vec3 origin, vec3 direction, float tMax) {
    rayQueryEXT query;
    // Through the back of single-sided triangles (glTF doubleSided false;
    // double-sided instances disable the culling, passes/bvh_update.cpp).
    rayQueryInitializeEXT(query, tlas, rtRayFlags() | gl_RayFlagsCullBackFacingTrianglesEXT, rt.instanceMask,
                          origin, 0.0, direction, tMax);
    rtProceed(query);
    RtHit h;
    h.hit = 0u;
    h.customIndex = 0u;
    h.geometry = 0u;
    h.primitive = 0u;
    h.barycentrics = vec2(0.0);
    h.t = 0.0;
    h.worldToObject = mat3(1.0);
    if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        h.hit = 1u;
        h.customIndex = rayQueryGetIntersectionInstanceCustomIndexEXT(query, true);
        h.geometry = rayQueryGetIntersectionGeometryIndexEXT(query, true);
        h.primitive = rayQueryGetIntersectionPrimitiveIndexEXT(query, true);
        h.barycentrics = rayQueryGetIntersectionBarycentricsEXT(query, true);
        h.t = rayQueryGetIntersectionTEXT(query, true);
        h.worldToObject = mat3(rayQueryGetIntersectionWorldToObjectEXT(query, true));
    }
    return h;
}

bool rtTraceOccluded(vec3 origin, vec3 direction, float tMax) {
    rayQueryEXT query;
    rayQueryInitializeEXT(query, tlas, rtRayFlags() | gl_RayFlagsTerminateOnFirstHitEXT, rt.instanceMask,
                          origin, 0.0, direction, tMax);
    rtProceed(query);
    return rayQueryGetIntersectionTypeEXT(query, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}

void main() {
    const uint index = gl_GlobalInvocationID.x;
    if (index >= rayListArgs[kRayListCountOffset]) {
        return;
    }
    rtTraceListEntry(index);
}
