#version 460
// Levels 5-9 of the occlusion cull's depth pyramid from level 4
// (passes/gbuffer_occlusion.cpp). The body and what the define means: hiz.glsl.
#extension GL_GOOGLE_include_directive : require
#define GLINT_HIZ_BASE 0
#include "hiz.glsl"
