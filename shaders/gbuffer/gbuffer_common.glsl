// Bindings of the G-buffer pipelines (passes/gbuffer.cpp declares the same)
// and the skinning the G-buffer and the shadow map share, so a skinned
// mesh casts the shadow of the pose it is drawn in.
#ifndef GLINT_GBUFFER_COMMON_GLSL
#define GLINT_GBUFFER_COMMON_GLSL

#extension GL_EXT_scalar_block_layout : require

#include "glint/gbuffer_shared.h"

layout(set = 0, binding = 0, scalar) readonly buffer Frame { GBufferFrame frame; };
layout(set = 0, binding = 1, scalar) readonly buffer Instances { GBufferInstance instances[]; };
layout(set = 0, binding = 2, scalar) readonly buffer Vertices { GBufferVertex vertices[]; };
layout(set = 0, binding = 3, scalar) readonly buffer Joints { mat4 joints[]; };
layout(set = 0, binding = 4, scalar) readonly buffer PreviousJoints { mat4 previousJoints[]; };
layout(push_constant, scalar) uniform Push { GBufferDraw draw; };
// The prefiltered environment (glint/environment.glsl, declared by
// glint/brdf.glsl in the shaders that light); binding 5 is the shadow map.
#define GLINT_ENVIRONMENT_BINDING 6

// Linear blend skinning with the same guards as the BVH's pack pass: zero
// weights and joints past the instance's skin contribute nothing.
mat4 skinMatrix(GBufferVertex v, GBufferInstance inst, bool previous) {
    const uint joint[4] = uint[4](v.joints.x & 0xFFFFu, v.joints.x >> 16u, v.joints.y & 0xFFFFu, v.joints.y >> 16u);
    mat4 m = mat4(0.0);
    for (int k = 0; k < 4; ++k) {
        if (v.weights[k] > 0.0 && joint[k] < inst.jointCount) {
            const uint j = inst.jointOffset + joint[k];
            m += v.weights[k] * (previous ? previousJoints[j] : joints[j]);
        }
    }
    return m;
}

#endif
