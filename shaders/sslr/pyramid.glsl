// The SSLR colour pyramid (passes/sslr.h, glint/sslr_shared.h), the body of
// pyramid_base.comp and pyramid_down.comp: one 16 x 16 workgroup per 32 x 32
// texels of the source level writes the five levels below it. Each texel
// is the mean of its 2 x 2 texels in the level above, so a level-m texel is
// the lit colour box-filtered over 2^m x 2^m pixels: the prefiltered colour
// a cone of that footprint sees. Children are clamped to the level above
// (a one-texel-wide level halves to itself); of an odd level the last row
// or column is left out of the level below, whose size Vulkan rounds down.
//
// The variant defines GLINT_PYRAMID_BASE: 1 reads the lit colour (level 0,
// a sampler), and outputs 0-4 are levels 1-5; 0 reads level 5 (a storage
// image), and outputs 0-4 are levels 6-10. (The pyramid image holds level
// m as its mip m - 1: level 0 is the lit colour itself.)
#extension GL_EXT_scalar_block_layout : require

#include "glint/sslr_shared.h"

layout(local_size_x = 16, local_size_y = 16) in;

#if GLINT_PYRAMID_BASE
layout(set = 0, binding = 0) uniform sampler2D source;
vec3 load(ivec2 p) { return texelFetch(source, p, 0).rgb; }
#else
layout(set = 0, binding = 0, rgba16f) uniform readonly image2D source;
vec3 load(ivec2 p) { return imageLoad(source, p).rgb; }
#endif
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D output0;
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2D output1;
layout(set = 0, binding = 3, rgba16f) uniform writeonly image2D output2;
layout(set = 0, binding = 4, rgba16f) uniform writeonly image2D output3;
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D output4;

layout(push_constant, scalar) uniform Constants { SslrPyramidConstants pc; };

shared vec3 tile[16][16];

void store(uint index, uvec2 texel, vec3 colour) {
    if (index >= pc.outputs || texel.x >= pc.outputSize[index].x || texel.y >= pc.outputSize[index].y) {
        return;
    }
    const ivec2 p = ivec2(texel);
    const vec4 value = vec4(colour, 1.0);
    switch (index) {
        case 0u: imageStore(output0, p, value); break;
        case 1u: imageStore(output1, p, value); break;
        case 2u: imageStore(output2, p, value); break;
        case 3u: imageStore(output3, p, value); break;
        default: imageStore(output4, p, value); break;
    }
}

void main() {
    const uvec2 group = gl_WorkGroupID.xy;
    const uvec2 local = gl_LocalInvocationID.xy;

    // The first reduction from the source: this invocation's 2 x 2 texels.
    const ivec2 last = ivec2(pc.sourceSize) - 1;
    const ivec2 corner = ivec2(group * kSslrPyramidGroupTexels + local * 2u);
    vec3 sum = vec3(0.0);
    for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
            sum += load(min(corner + ivec2(dx, dy), last));
        }
    }
    vec3 colour = 0.25 * sum;
    store(0u, group * 16u + local, colour);
    tile[local.y][local.x] = colour;

    // Four more in shared memory: 8, 4, 2, 1 texels a side. Children are
    // clamped to the level above as the source was (their global position,
    // then back into this group's square).
    uvec2 parentSize = sslrMipSize(pc.sourceSize, 1u);
    for (uint step = 2u; step <= kSslrPyramidLevelsPerPass; ++step) {
        barrier();
        const uint side = kSslrPyramidGroupTexels >> step;
        const bool reduces = local.x < side && local.y < side;
        if (reduces) {
            const uvec2 texel = group * side + local;
            const ivec2 parentOrigin = ivec2(group * side * 2u);
            sum = vec3(0.0);
            for (int dy = 0; dy < 2; ++dy) {
                for (int dx = 0; dx < 2; ++dx) {
                    const ivec2 child = min(ivec2(texel * 2u) + ivec2(dx, dy), ivec2(parentSize) - 1);
                    const ivec2 inTile = clamp(child - parentOrigin, ivec2(0), ivec2(int(side * 2u) - 1));
                    sum += tile[inTile.y][inTile.x];
                }
            }
            colour = 0.25 * sum;
        }
        barrier();
        if (reduces) {
            tile[local.y][local.x] = colour;
            store(step - 1u, group * side + local, colour);
        }
        parentSize = sslrMipSize(pc.sourceSize, step);
    }
}
