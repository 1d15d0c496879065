#version 460
// The particles in the direct view (passes/particles.h): six vertices per
// particle, no vertex buffer; the quad spans the camera's right and up, as
// the particle TLAS's quads do (shaders/bvh/particle_quads.comp), so the
// coverage seen here and in a reflection is one function of the same quad
// coordinates.
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/particles_shared.h"

layout(set = 0, binding = 0, scalar) readonly buffer Particles { ParticleData particles[]; };
layout(push_constant, scalar) uniform Push {
    mat4 viewProjection;  // the G-buffer's, jittered: the billboards land on its depth
    ParticleBillboardParams basis;
};

layout(location = 0) out vec2 quadPosition;
layout(location = 1) flat out vec4 color;

void main() {
    const uint particle = uint(gl_VertexIndex) / kParticleQuadVertices;
    const uint corner = uint(gl_VertexIndex) % kParticleQuadVertices;
    const ParticleData p = particles[particle];
    const vec2 c = particleQuadCorner(corner);
    const vec3 world = p.position + p.radius * (c.x * basis.right + c.y * basis.up);
    gl_Position = viewProjection * vec4(world, 1.0);
    quadPosition = c;
    color = p.color;
}
