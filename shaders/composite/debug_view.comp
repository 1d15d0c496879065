#version 460
// Debug view of a float, normalised-integer, sRGB or depth texture
// (passes/composite.h); the logic is in debug_view.glsl.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/composite_shared.h"
#include "glint/packing.h"
#include "tonemap.glsl"

layout(set = 0, binding = 0) uniform sampler2D sourceTexture;

vec4 fetchSource(ivec2 p) { return texelFetch(sourceTexture, p, 0); }

#include "debug_view.glsl"
