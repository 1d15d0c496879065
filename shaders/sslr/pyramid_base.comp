#version 460
// Levels 1-5 of the SSLR colour pyramid from the lit colour (passes/sslr.h).
// The body and what the define means: pyramid.glsl.
#extension GL_GOOGLE_include_directive : require
#define GLINT_PYRAMID_BASE 1
#include "pyramid.glsl"
