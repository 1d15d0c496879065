// Particles in the reflections (passes/particles.h) and the particle TLAS
// the BVH update builds for them (passes/bvh_update.h): the particle record,
// its soft round footprint, the nearest-hits list the particle trace keeps,
// and the constants of the passes; shared by GLSL and C++. Buffers use
// scalar layout.
//
// A particle is a camera-facing quad of half-size `radius` (two triangles,
// primitives 2i and 2i + 1 of particle i in the particle BLAS), emitting
// colour.rgb (radiance, the lit colour's units) with a soft round coverage
// (particleCoverage). Both the traced quads and the forward pass's
// billboards span the camera's right and up vectors, so a point on a quad
// is centre + radius * (u * right + v * up) in both and the coverage, a
// function of u^2 + v^2, is the same seen directly and in a reflection.
#ifndef GLINT_PARTICLES_SHARED_H
#define GLINT_PARTICLES_SHARED_H

#include "glint/shared.h"
#include "glint/packing.h"  // GLINT_FUNC and the glm names in C++

GLINT_BEGIN

// One particle (32 bytes), as scene::Particle.
struct ParticleData {
    vec3 position;  // world
    float radius;   // half the quad's side
    vec4 color;     // linear RGB radiance, alpha = coverage at the centre
};

GLINT_CONST uint kParticleBillboardGroupSize = 64u;
GLINT_CONST uint kParticleTraceGroupSize = 8u;  // 8x8 pixels per workgroup (ray query backend)
GLINT_CONST uint kParticleQuadVertices = 6u;    // two unindexed triangles per particle

// Push constants of the billboard dispatch (shaders/bvh/particle_quads.comp)
// and the forward pass's vertex shader: the camera's basis (32 bytes).
struct ParticleBillboardParams {
    vec3 right;  // world, unit: the camera's +x
    uint count;  // particles
    vec3 up;     // world, unit: the camera's +y
    uint pad;
};

// Corner k (0..5) of a particle's two triangles in quad coordinates
// (u, v) in {-1, 1}^2: (-1,-1) (1,-1) (1,1) and (-1,-1) (1,1) (-1,1), both
// counter-clockwise seen from the camera.
GLINT_FUNC vec2 particleQuadCorner(uint k) {
    const float u = (k == 1u || k == 2u || k == 4u) ? 1.0f : -1.0f;
    const float v = (k == 2u || k == 4u || k == 5u) ? 1.0f : -1.0f;
    return vec2(u, v);
}

// Coverage of a particle at squared quad radius r2 = u^2 + v^2: alpha at
// the centre falling smoothly to 0 at the inscribed circle, (1 - r2)^2 (a
// C1 edge: no ring where a soft particle ends; no texture to sample).
GLINT_FUNC float particleCoverage(float alpha, float r2) {
    const float k = max(1.0f - r2, 0.0f);
    return clamp(alpha, 0.0f, 1.0f) * k * k;
}

// Coverage of `particle` at world point `p` on its quad.
GLINT_FUNC float particleCoverageAt(ParticleData particle, vec3 p) {
    const vec3 d = p - particle.position;
    const float r = max(particle.radius, 1e-20f);
    return particleCoverage(particle.color.w, dot(d, d) / (r * r));
}

// How many particle hits a reflection ray composites: the nearest ones
// with any coverage, in front of the reflection's hit. Traversal finds
// hits in no particular order, so exact front-to-back compositing needs
// them sorted; a fixed list keeps the ray tracing payload and the ray
// query loop's state small. 8 holds the plaza's lamp glows (four particles
// around each lamp, a ray meets at most a few); farther hits past the 8th
// are dropped.
GLINT_CONST uint kParticleMaxHits = 8u;

// Constants of the particle trace (a storage buffer: 112 bytes).
struct ParticleTraceConstants {
    mat4 inverseViewProjection;  // unjittered, the G-buffer's camera (as integrate reconstructs)
    vec4 cameraPosition;
    uvec2 size;                  // pixels
    float confidenceThreshold;   // integrate's (which trace a pixel's reflection takes)
    float maxDistance;           // the longest particle ray (misses reach this far)
    uint sslrBound;              // 1: the SSLR outputs are bound (else dummies)
    uint rtBound;                // 1: the RT outputs are bound (else dummies)
    uint pad0;
    uint pad1;
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::ParticleData) == 32);
static_assert(sizeof(glint::shader::ParticleBillboardParams) == 32);
static_assert(sizeof(glint::shader::ParticleTraceConstants) == 112);
#endif

#endif
