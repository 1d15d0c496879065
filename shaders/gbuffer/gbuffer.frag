#version 460
// The G-buffer's surface shader for opaque materials (gbuffer_surface.glsl).
#extension GL_GOOGLE_include_directive : require

#define GLINT_ALPHA_TEST 0
#include "gbuffer_surface.glsl"
