#version 460
// Levels 6 and on of the SSLR colour pyramid from level 5 (passes/sslr.h).
// The body and what the define means: pyramid.glsl.
#extension GL_GOOGLE_include_directive : require
#define GLINT_PYRAMID_BASE 0
#include "pyramid.glsl"
