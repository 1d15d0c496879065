#version 460
// Smoke trace, ray query backend (lavapipe and any device with VK_KHR_ray_query).
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/smoke_shared.h"

layout(local_size_x = kSmokeGroupSize, local_size_y = kSmokeGroupSize) in;

layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1, scalar) writeonly buffer Hits { SmokeHit hits[]; };
layout(push_constant, scalar) uniform Push { SmokeCamera camera; };

void main() {
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, camera.size.xy))) {
        return;
    }
    rayQueryEXT query;
    rayQueryInitializeEXT(query, tlas, gl_RayFlagsOpaqueEXT, 0xff, camera.origin.xyz, kSmokeTMin,
                          smokeRayDirection(camera, pixel), kSmokeTMax);
    while (rayQueryProceedEXT(query)) {
    }
    SmokeHit h = smokeMiss();
    if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        const vec2 bary = rayQueryGetIntersectionBarycentricsEXT(query, true);
        h = SmokeHit(1u, rayQueryGetIntersectionInstanceCustomIndexEXT(query, true),
                     rayQueryGetIntersectionGeometryIndexEXT(query, true),
                     rayQueryGetIntersectionPrimitiveIndexEXT(query, true), rayQueryGetIntersectionTEXT(query, true),
                     bary.x, bary.y, 0u);
    }
    hits[pixel.y * camera.size.x + pixel.x] = h;
}
