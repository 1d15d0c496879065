#version 460
// Environment prefilter, step 1 (passes/environment.h): the uploaded
// RGBA32F source -> mip 0 of the source chain, every channel finite and in
// [0, maxValue], so a NaN or Inf texel of the file cannot spread through
// the filters (it becomes black).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/environment_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, scalar) readonly buffer Source { vec4 texels[]; };
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D chainImage;
layout(push_constant, scalar) uniform Push { EnvironmentPrefilterConstants pc; };

void main() {
    const uvec2 texel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(texel, pc.size))) {
        return;
    }
    const vec4 c = texels[texel.y * pc.size.x + texel.x];
    imageStore(chainImage, ivec2(texel), vec4(environmentSanitize(c.rgb, pc.maxValue), 1.0));
}
