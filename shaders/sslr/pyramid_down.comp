#version 460
// One level of the SSLR colour pyramid (passes/sslr.h): each texel is the
// mean of the 2x2 texels of the level above (an odd last row or column is
// folded into its neighbour's texel), so a level-m texel is the box-filtered
// lit colour over 2^m x 2^m pixels: the prefiltered colour a cone of that
// footprint sees.
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) uniform readonly image2D source;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D target;

layout(push_constant, scalar) uniform Constants {
    uvec2 sourceSize;
    uvec2 targetSize;
} pc;

void main() {
    const uvec2 texel = gl_GlobalInvocationID.xy;
    if (texel.x >= pc.targetSize.x || texel.y >= pc.targetSize.y) {
        return;
    }
    // Source texels covered: 2x2, plus the odd remainder at the far edge.
    const uvec2 first = texel * 2u;
    const uvec2 last = min(uvec2(texel.x == pc.targetSize.x - 1u ? pc.sourceSize.x - 1u : first.x + 1u,
                                 texel.y == pc.targetSize.y - 1u ? pc.sourceSize.y - 1u : first.y + 1u),
                           pc.sourceSize - 1u);
    vec3 sum = vec3(0.0);
    for (uint y = first.y; y <= last.y; ++y) {
        for (uint x = first.x; x <= last.x; ++x) {
            sum += imageLoad(source, ivec2(x, y)).rgb;
        }
    }
    const uvec2 n = last - first + 1u;
    imageStore(target, ivec2(texel), vec4(sum / float(n.x * n.y), 1.0));
}
