#version 460
// Test probe (tests/gpu/environment_test.cpp): glint/environment.glsl's
// lookups, exactly as the passes call them, for a list of directions and
// roughnesses.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/gbuffer_shared.h"
#define GLINT_ENVIRONMENT_BINDING 2
#include "glint/environment.glsl"

layout(local_size_x = 64) in;

// xyz: direction (unit), w: perceptual roughness.
layout(set = 0, binding = 0, scalar) readonly buffer Queries { vec4 queries[]; };
layout(set = 0, binding = 1, scalar) readonly buffer Lighting { SceneLighting lighting; };
// Per query: environmentRadiance, then environmentIrradiance of the direction as a normal.
layout(set = 0, binding = 3, scalar) writeonly buffer Results { vec4 results[]; };
layout(push_constant, scalar) uniform Push { uint count; };

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= count) {
        return;
    }
    const vec4 q = queries[i];
    results[2u * i] = vec4(environmentRadiance(lighting, q.xyz, q.w), 0.0);
    results[2u * i + 1u] = vec4(environmentIrradiance(lighting, q.xyz), 0.0);
}
