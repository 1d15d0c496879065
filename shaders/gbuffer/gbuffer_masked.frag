#version 460
// The surface shader for alpha-tested materials (glTF alphaMode
// MASK): gbuffer_surface.glsl.
#extension GL_GOOGLE_include_directive : require

#define GLINT_ALPHA_TEST 1
#define GLINT_BLEND 0
#include "gbuffer_surface.glsl"
