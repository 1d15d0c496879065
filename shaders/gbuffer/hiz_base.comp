#version 460
// Levels 0-4 of the occlusion cull's depth pyramid from the G-buffer's depth
// (passes/gbuffer_occlusion.cpp). The body and what the define means: hiz.glsl.
#extension GL_GOOGLE_include_directive : require
#define GLINT_HIZ_BASE 1
#include "hiz.glsl"
