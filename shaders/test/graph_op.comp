#version 460
// dst[i] = (useSrc ? src[i] : i) * mul + add. Render-graph GPU tests chain
// passes of this to check ordering, aliasing and history.
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, scalar) readonly buffer Src { uint src[]; };
layout(set = 0, binding = 1, scalar) writeonly buffer Dst { uint dst[]; };
layout(push_constant, scalar) uniform Push {
    uint count;
    uint mul;
    uint add;
    uint useSrc;
};

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i < count) {
        dst[i] = (useSrc != 0 ? src[i] : i) * mul + add;
    }
}
