#version 460
// Environment prefilter, step 2 (passes/environment.h): one mip of the
// source chain from the one above, a 2x2 box (the filtered importance
// sampling of step 3 reads these mips).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/environment_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) uniform readonly image2D aboveImage;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D mipImage;
layout(push_constant, scalar) uniform Push { EnvironmentPrefilterConstants pc; };

void main() {
    const ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(texel), pc.size))) {
        return;
    }
    // Odd sizes: the last row or column of the mip above is clamped to.
    const ivec2 last = imageSize(aboveImage) - 1;
    vec3 sum = vec3(0.0);
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 2; ++x) {
            sum += imageLoad(aboveImage, min(texel * 2 + ivec2(x, y), last)).rgb;
        }
    }
    imageStore(mipImage, texel, vec4(sum * 0.25, 1.0));
}
