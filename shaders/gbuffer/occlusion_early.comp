#version 460
// The early phase of the G-buffer's occlusion cull (passes/gbuffer_occlusion.cpp):
// last frame's visible instances are drawn first. The body: occlusion_cull.glsl.
#extension GL_GOOGLE_include_directive : require
#define GLINT_OCCLUSION_LATE 0
#include "occlusion_cull.glsl"
