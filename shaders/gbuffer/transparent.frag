#version 460
// The surface shader of the transparent pass, for blended materials
// (glTF alphaMode BLEND; passes/transparent.h): gbuffer_surface.glsl.
#extension GL_GOOGLE_include_directive : require

#define GLINT_ALPHA_TEST 0
#define GLINT_BLEND 1
#include "gbuffer_surface.glsl"
