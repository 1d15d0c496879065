// What the ray-traced reflection pass needs to know about a traced ray's
// closest hit (passes/rt_trace.h). Both backends fill it from the traversal
// alone - the ray query from its committed intersection, the ray tracing
// pipeline's one closest-hit shader from its built-ins (it is the payload) -
// and glint/rt_trace.glsl does everything else, so the two backends run the
// same shading code on the same bits.
#ifndef GLINT_RT_HIT_GLSL
#define GLINT_RT_HIT_GLSL

struct RtHit {
    uint hit;             // 1: a triangle was hit; 0: the ray missed
    uint customIndex;     // the TLAS instance's custom index
    uint geometry;        // geometry index in its BLAS
    uint primitive;       // triangle index in that geometry
    vec2 barycentrics;    // of vertices 1 and 2
    float t;              // along the unit direction, from the origin
    mat3 worldToObject;   // the instance's linear part, inverted: normals go
                          // to world space by its transpose
};

#endif
