#version 460
// The BVH update's compute pass, one dispatch per BLAS geometry, one thread
// per triangle: unwraps the triangle (optionally skinned, linear blend) into
// the BLAS's build positions and writes its packed primitive into the pool;
// on a rebuild of a deformable BLAS, also how far each vertex moved since
// the last build (DeformMotion, from the positions that build left).
// Mirrors scene::unwrapGeometry (packed_primitives.cpp), which the tests
// compare it against.
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/bvh_shared.h"
#include "glint/packing.h"

layout(local_size_x = kBvhPackGroupSize) in;

layout(set = 0, binding = 0, scalar) readonly buffer Vertices { BvhSourceVertex vertices[]; };
layout(set = 0, binding = 1, scalar) readonly buffer Indices { uint indices[]; };
layout(set = 0, binding = 2, scalar) readonly buffer Skin { BvhSkinVertex skin[]; };
layout(set = 0, binding = 3, scalar) readonly buffer Joints { mat4 joints[]; };
// Read before written: a rebuild's last shape.
layout(set = 0, binding = 4, scalar) buffer Positions { vec3 positions[]; };
layout(set = 0, binding = 5, scalar) writeonly buffer Pool { PackedPrimitive pool[]; };
layout(set = 0, binding = 6, scalar) writeonly buffer DeformMotions { DeformMotion deformMotions[]; };
layout(push_constant, scalar) uniform Push { BvhPackParams params; };

// One joint's share of a vertex's skin matrix. Same guards as the CPU
// reference: zero weights and joints past the instance's skin contribute
// nothing.
mat4 skinJoint(uint joint, float weight) {
    return weight > 0.0f && joint < params.jointCount ? weight * joints[params.jointOffset + joint] : mat4(0.0f);
}

// The four joints by name, in the reference's order: a loop indexing the
// joints and weights by a variable left them in function arrays.
mat4 skinMatrix(uint v) {
    const BvhSkinVertex s = skin[v];
    return skinJoint(s.joints.x & 0xFFFFu, s.weights.x) + skinJoint(s.joints.x >> 16u, s.weights.y) +
           skinJoint(s.joints.y & 0xFFFFu, s.weights.z) + skinJoint(s.joints.y >> 16u, s.weights.w);
}

void main() {
    const uint t = gl_GlobalInvocationID.x;
    if (t >= params.triangleCount) {
        return;
    }
    // Each vertex's results go straight to the buffers: a PackedPrimitive
    // and a DeformMotion built up in the loop are arrays indexed by k (the
    // optimised SPIR-V held both as function arrays), the likely content
    // of the 48 bytes of local memory NVIDIA reported for this shader
    // (GLINT_PIPELINE_STATS=1), their size. Not re-read there since.
    const uint primitive = params.poolOffset + t;
    const uint motionSlot = params.motionOffset + t;
    for (uint k = 0u; k < 3u; ++k) {
        const uint v = indices[3u * t + k];
        const BvhSourceVertex src = vertices[v];
        vec3 p = src.position;
        vec3 n = src.normal;
        if (params.jointCount > 0u) {
            const mat4 m = skinMatrix(v);
            p = (m * vec4(p, 1.0f)).xyz;
            // Rigs carry no non-uniform scale: the upper 3x3 transforms normals.
            const vec3 skinned = mat3(m) * n;
            n = length(skinned) > 0.0f ? normalize(skinned) : n;
        }
        const uint slot = params.positionOffset + 3u * t + k;
        if (params.motionOffset != kNoDeformMotion) {
            const vec3 moved = positions[slot] - p;
            deformMotions[motionSlot].vertices[k] = uvec2(packHalf2x16(moved.xy), packHalf2x16(vec2(moved.z, 0.0f)));
        }
        positions[slot] = p;
        pool[primitive].vertices[k].albedoSmoothness = src.albedoSmoothness;
        pool[primitive].vertices[k].normalMetallicReflectance = packOctNormalPrecise(n) | src.metallicReflectance;
    }
}
