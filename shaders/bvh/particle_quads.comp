#version 460
// The particle BLASes' build input (passes/bvh_update.h): one thread per
// particle writes its three quads, one facing each of the camera's axes
// (glint/particles_shared.h), two unwrapped triangles each
// (particleQuadCorner). Axis a's quads fill the a-th third of the buffer,
// so in each axis's BLAS primitives 2i and 2i + 1 are particle i. Rebuilt
// every frame: the quads turn with the camera.
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/particles_shared.h"

layout(local_size_x = kParticleBillboardGroupSize) in;

layout(set = 0, binding = 0, scalar) readonly buffer Particles { ParticleData particles[]; };
layout(set = 0, binding = 1, scalar) writeonly buffer Positions { vec3 positions[]; };
layout(push_constant, scalar) uniform Push { ParticleBillboardParams params; };

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= params.count) {
        return;
    }
    const ParticleData p = particles[i];
    for (uint axis = 0u; axis < kParticleQuadAxes; ++axis) {
        const vec3 u = particleQuadSpanU(params, axis);
        const vec3 v = particleQuadSpanV(params, axis);
        const uint first = (axis * params.count + i) * kParticleQuadVertices;
        for (uint k = 0u; k < kParticleQuadVertices; ++k) {
            const vec2 c = particleQuadCorner(k) * p.radius;
            positions[first + k] = p.position + c.x * u + c.y * v;
        }
    }
}
