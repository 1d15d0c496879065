// Particles in the reflections (passes/particles.h) and the particle TLAS
// the BVH update builds for them (passes/bvh_update.h): the particle record,
// its soft round footprint, the nearest-hits list the particle trace keeps,
// and the constants of the passes; shared by GLSL and C++. Buffers use
// scalar layout.
//
// A particle is a soft round sprite of radius `radius` around its centre,
// emitting colour.rgb (radiance, the lit colour's units) with a coverage
// that falls with the distance from the centre (particleCoverageAt). The
// forward pass draws it as a camera-facing billboard. A reflection ray,
// though, may meet that billboard edge-on (a floor seen at 45 degrees
// reflects rays at right angles to the view), and the sprite would vanish
// from the reflection: the Far Cry 6 talk's "missing sprites". So the
// particle BLASes hold three quads per particle, one facing each of the
// camera's axes (right, up, back; the last one is the billboard), each
// axis in its own BLAS and TLAS instance with its own instance mask, and a
// ray's cull mask takes only the axis its view-space direction is largest
// along (particleQuadAxis): each ray meets every particle once, through the
// quad that faces it best (at most 54.7 degrees from its normal). In every
// axis's BLAS primitives 2i and 2i + 1 are particle i. A point on any of
// the quads lies in a plane through the centre, so the coverage, a
// function of the distance from the centre, is the same seen directly and
// in a reflection.
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
GLINT_CONST uint kParticleQuadVertices = 6u;    // two unindexed triangles per quad

// The quads of a particle in the particle BLASes: one per view-space axis,
// named by the axis it faces (its normal). kParticleAxisBack's quad spans
// the camera's right and up: the billboard the forward pass draws.
GLINT_CONST uint kParticleQuadAxes = 3u;
GLINT_CONST uint kParticleAxisRight = 0u;
GLINT_CONST uint kParticleAxisUp = 1u;
GLINT_CONST uint kParticleAxisBack = 2u;

// Push constants of the quad dispatch (shaders/bvh/particle_quads.comp)
// and the forward pass's vertex shader: the camera's basis (48 bytes).
struct ParticleBillboardParams {
    vec3 right;  // world, unit: the camera's +x
    uint count;  // particles
    vec3 up;     // world, unit: the camera's +y
    uint pad0;
    vec3 back;   // world, unit: the camera's +z (it looks down -z)
    uint pad1;
};

// The particle TLAS instance holding axis `axis`'s quads has this mask.
GLINT_FUNC uint particleAxisMask(uint axis) { return 1u << axis; }

// The axis whose quads a ray with this view-space direction sees: the one
// its direction is largest along, so the quad meets it at most
// acos(1 / sqrt(3)) = 54.7 degrees from its normal. Ties go to back, then
// right: one axis for every direction, so no particle is counted twice.
GLINT_FUNC uint particleQuadAxis(vec3 viewDirection) {
    const vec3 a = abs(viewDirection);
    if (a.z >= a.x && a.z >= a.y) return kParticleAxisBack;
    return a.x >= a.y ? kParticleAxisRight : kParticleAxisUp;
}

// The two world directions (u, v) that span axis `axis`'s quad, from the
// camera's basis: a point of the quad is centre + radius * (c.x u + c.y v)
// for corners c of particleQuadCorner.
GLINT_FUNC vec3 particleQuadSpanU(ParticleBillboardParams basis, uint axis) {
    return axis == kParticleAxisRight ? basis.back : basis.right;
}
GLINT_FUNC vec3 particleQuadSpanV(ParticleBillboardParams basis, uint axis) {
    return axis == kParticleAxisUp ? basis.back : basis.up;
}

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

// Constants of the particle trace (a storage buffer: 160 bytes).
struct ParticleTraceConstants {
    mat4 inverseViewProjection;  // unjittered, the G-buffer's camera (as integrate reconstructs)
    vec4 cameraPosition;
    // The camera's right, up and back (w unused): the basis the BVH
    // update's quads were built in, which picks a ray's quad axis.
    vec4 cameraRight;
    vec4 cameraUp;
    vec4 cameraBack;
    uvec2 size;                  // pixels
    float confidenceThreshold;   // integrate's (which trace a pixel's reflection takes)
    float maxDistance;           // the longest particle ray (misses reach this far)
    // 1: the SSLR outputs are bound (else dummies); 2: bound, but hybrid
    // pixels take the ray tracer's hit (integrate's sslrCountsOnly).
    uint sslrBound;
    uint rtBound;                // 1: the RT outputs are bound (else dummies)
    // 1: SSLR sampled a lit colour with the particles drawn in, so rays
    // whose reflection integrate takes from SSLR carry them already and
    // are not traced here (ParticleTraceSettings::sslrSeesParticles).
    uint sslrSeesParticles;
    uint rtMissesTrusted;        // integrate's (ParticleTraceSettings::rtMissesTrusted)
    // Every particle's quads lie in this world box (xyz; BvhUpdateOutputs'
    // particle bounds): a segment that misses it traces nothing.
    vec4 boundsMin;
    vec4 boundsMax;
};

// Push constants of the particle trace: which ray list a launch walks
// (kParticleList*). The trace runs once over each list the frame has
// (ray query: kRayListGroupSize invocations per group, as the lists'
// dispatch args count them); the RT list's hybrid entries are SSLR's
// failures, whose leaders the SSLR list's launch traced already.
GLINT_CONST uint kParticleListSslr = 0u;
GLINT_CONST uint kParticleListRt = 1u;
struct ParticleTracePush {
    uint list;
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::ParticleData) == 32);
static_assert(sizeof(glint::shader::ParticleBillboardParams) == 48);
static_assert(sizeof(glint::shader::ParticleTraceConstants) == 192);
static_assert(sizeof(glint::shader::ParticleTracePush) == 4);
#endif

#endif
