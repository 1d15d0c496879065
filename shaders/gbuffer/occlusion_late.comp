#version 460
// The late phase of the G-buffer's occlusion cull (passes/gbuffer_occlusion.cpp):
// every instance against the early phase's Hi-Z. The body: occlusion_cull.glsl.
#extension GL_GOOGLE_include_directive : require
#define GLINT_OCCLUSION_LATE 1
#include "occlusion_cull.glsl"
