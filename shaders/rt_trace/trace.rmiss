#version 460
// The miss shader of the ray-traced reflections (passes/rt_trace.h): the
// payload says "no hit". A reflection ray's payload starts so already; a
// shadow ray's starts as occluded (trace.rgen's rtTraceOccluded), and this
// is what clears it.
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require

#include "glint/rt_hit.glsl"

layout(location = 0) rayPayloadInEXT RtHit payload;

void main() {
    payload.hit = 0u;
}
