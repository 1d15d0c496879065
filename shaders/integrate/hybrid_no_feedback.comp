#version 460
// Integrate with SSLR and RT (the hybrid frame), without the feedback counters.
// The body and what the defines mean: integrate.glsl (passes/integrate.h).
#extension GL_GOOGLE_include_directive : require
#define GLINT_INTEGRATE_SSLR 1
#define GLINT_INTEGRATE_RT 1
#define GLINT_INTEGRATE_FEEDBACK 0
#include "integrate.glsl"
