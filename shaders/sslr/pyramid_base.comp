#version 460
// Level 0 of the SSLR colour pyramid (passes/sslr.h): the lit colour
// copied into the mipped image the cone trace samples.
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D litTexture;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D level0;

layout(push_constant, scalar) uniform Constants { uvec2 size; } pc;

void main() {
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x < pc.size.x && pixel.y < pc.size.y) {
        imageStore(level0, ivec2(pixel), vec4(texelFetch(litTexture, ivec2(pixel), 0).rgb, 1.0));
    }
}
