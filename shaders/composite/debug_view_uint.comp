#version 460
// Debug view of an unsigned-integer texture (ids, counters, classes;
// passes/composite.h): the values as floats; the logic is in
// debug_view.glsl.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/composite_shared.h"
#include "glint/packing.h"
#include "tonemap.glsl"

layout(set = 0, binding = 0) uniform usampler2D sourceTexture;

vec4 fetchSource(ivec2 p) { return vec4(texelFetch(sourceTexture, p, 0)); }

#include "debug_view.glsl"
