// The occlusion cull's depth pyramid (glint/occlusion_shared.h), the body
// of hiz_base.comp and hiz_down.comp: one 16 x 16 workgroup per 32 x 32
// texels of the source writes the five levels below it. Each texel is the
// minimum (reversed Z: the farthest depth) of its 2 x 2 texels in the level
// above; source texels beyond `sourceValid` (beyond the screen) read as 1,
// the nearest depth, which no minimum keeps.
//
// GLINT_HIZ_BASE: 1 reads the G-buffer's depth (a sampler); 0 reads level 4
// (a storage image), and outputs 0-4 are levels 5-9.
#extension GL_EXT_scalar_block_layout : require

#include "glint/occlusion_shared.h"

layout(local_size_x = 16, local_size_y = 16) in;

#if GLINT_HIZ_BASE
layout(set = 0, binding = 0) uniform sampler2D source;
float fetch(ivec2 p) { return texelFetch(source, p, 0).r; }
#else
layout(set = 0, binding = 0, r32f) uniform readonly image2D source;
float fetch(ivec2 p) { return imageLoad(source, p).r; }
#endif
layout(set = 0, binding = 1, r32f) uniform writeonly image2D output0;
layout(set = 0, binding = 2, r32f) uniform writeonly image2D output1;
layout(set = 0, binding = 3, r32f) uniform writeonly image2D output2;
layout(set = 0, binding = 4, r32f) uniform writeonly image2D output3;
layout(set = 0, binding = 5, r32f) uniform writeonly image2D output4;

layout(push_constant, scalar) uniform Constants { HizConstants pc; };

shared float tile[16][16];

float load(uvec2 p) {
    return p.x < pc.sourceValid.x && p.y < pc.sourceValid.y ? fetch(ivec2(p)) : 1.0;
}

void store(uint index, uvec2 texel, float depth) {
    if (index >= pc.outputs || texel.x >= pc.outputSize[index].x || texel.y >= pc.outputSize[index].y) return;
    const ivec2 p = ivec2(texel);
    const vec4 value = vec4(depth, 0.0, 0.0, 0.0);
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

    const uvec2 corner = group * kHizGroupTexels + local * 2u;
    float depth = min(min(load(corner), load(corner + uvec2(1u, 0u))),
                      min(load(corner + uvec2(0u, 1u)), load(corner + uvec2(1u, 1u))));
    store(0u, group * 16u + local, depth);
    tile[local.y][local.x] = depth;

    // Four more in shared memory: 8, 4, 2, 1 texels a side. Every level
    // halves exactly, so a texel's children are the 2 x 2 below it.
    for (uint step = 1u; step < kHizLevelsPerPass; ++step) {
        barrier();
        const uint side = 16u >> step;
        const bool reduces = local.x < side && local.y < side;
        if (reduces) {
            const uvec2 c = local * 2u;
            depth = min(min(tile[c.y][c.x], tile[c.y][c.x + 1u]), min(tile[c.y + 1u][c.x], tile[c.y + 1u][c.x + 1u]));
        }
        barrier();
        if (reduces) {
            tile[local.y][local.x] = depth;
            store(step, group * side + local, depth);
        }
    }
}
