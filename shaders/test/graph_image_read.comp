#version 460
// dst[i] = image(i % width, i / width).
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D image;
layout(set = 0, binding = 1, scalar) writeonly buffer Dst { uint dst[]; };
layout(push_constant, scalar) uniform Push {
    uint count;
    uint width;
    uint unused0;
    uint unused1;
};

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i < count) {
        dst[i] = imageLoad(image, ivec2(i % width, i / width)).x;
    }
}
