#version 460
// image(i % width, i / width) = src[i] + add.
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, scalar) readonly buffer Src { uint src[]; };
layout(set = 0, binding = 1, r32ui) uniform writeonly uimage2D image;
layout(push_constant, scalar) uniform Push {
    uint count;
    uint width;
    uint add;
    uint unused;
};

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i < count) {
        imageStore(image, ivec2(i % width, i / width), uvec4(src[i] + add));
    }
}
