#version 460
// Fills a storage image with one value (passes/image_clear.h): a compute
// clear, because vkCmdClearColorImage runs on the graphics engine, which
// compute-class GPUs (H100/H200) have little of: it cleared 2 bytes per
// microsecond-megapixel there, 30x slower than this dispatch.
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 8, local_size_y = 8) in;

// No format qualifier: one shader for every colour format
// (shaderStorageImageWriteWithoutFormat).
layout(set = 0, binding = 0) uniform writeonly image2D target;

layout(push_constant, scalar) uniform Constants {
    vec4 value;
    uvec2 size;
} pc;

void main() {
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x < pc.size.x && pixel.y < pc.size.y) {
        imageStore(target, ivec2(pixel), pc.value);
    }
}
