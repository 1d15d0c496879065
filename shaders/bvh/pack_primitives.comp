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

mat4 skinMatrix(uint v) {
    const BvhSkinVertex s = skin[v];
    const uint joint[4] = uint[4](s.joints.x & 0xFFFFu, s.joints.x >> 16u, s.joints.y & 0xFFFFu, s.joints.y >> 16u);
    mat4 m = mat4(0.0f);
    for (int k = 0; k < 4; ++k) {
        // Same guards as the CPU reference: zero weights and joints past the
        // instance's skin contribute nothing.
        if (s.weights[k] > 0.0f && joint[k] < params.jointCount) {
            m += s.weights[k] * joints[params.jointOffset + joint[k]];
        }
    }
    return m;
}

void main() {
    const uint t = gl_GlobalInvocationID.x;
    if (t >= params.triangleCount) {
        return;
    }
    PackedPrimitive prim;
    DeformMotion motion;
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
            motion.vertices[k] = uvec2(packHalf2x16(moved.xy), packHalf2x16(vec2(moved.z, 0.0f)));
        }
        positions[slot] = p;
        prim.vertices[k].albedoSmoothness = src.albedoSmoothness;
        prim.vertices[k].normalMetallicReflectance = packOctNormalPrecise(n) | src.metallicReflectance;
    }
    pool[params.poolOffset + t] = prim;
    if (params.motionOffset != kNoDeformMotion) {
        deformMotions[params.motionOffset + t] = motion;
    }
}
