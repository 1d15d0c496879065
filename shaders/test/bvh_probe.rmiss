#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/bvh_shared.h"

layout(location = 0) rayPayloadInEXT BvhProbeHit payload;

void main() {
    payload.hit = 0u;
}
