#version 460
// The surface shader for opaque materials: gbuffer_surface.glsl.
#extension GL_GOOGLE_include_directive : require

#define GLINT_ALPHA_TEST 0
#define GLINT_BLEND 0
#include "gbuffer_surface.glsl"
