// Bindings of the G-buffer pipelines (passes/gbuffer.cpp declares the same).
#ifndef GLINT_GBUFFER_COMMON_GLSL
#define GLINT_GBUFFER_COMMON_GLSL

#extension GL_EXT_scalar_block_layout : require

#include "glint/gbuffer_shared.h"

layout(set = 0, binding = 0, scalar) readonly buffer Frame { GBufferFrame frame; };
layout(set = 0, binding = 1, scalar) readonly buffer Instances { GBufferInstance instances[]; };
layout(set = 0, binding = 2, scalar) readonly buffer Vertices { GBufferVertex vertices[]; };
layout(set = 0, binding = 3, scalar) readonly buffer Joints { mat4 joints[]; };
layout(set = 0, binding = 4, scalar) readonly buffer PreviousJoints { mat4 previousJoints[]; };
layout(push_constant, scalar) uniform Push { GBufferDraw draw; };

#endif
