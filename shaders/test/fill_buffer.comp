#version 460
// Writes value + index into every word of a buffer. Used by the GPU-layer
// tests (validation harness, memory aliasing).
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, scalar) writeonly buffer Words { uint words[]; };
layout(push_constant, scalar) uniform Push {
    uint count;
    uint value;
};

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i < count) {
        words[i] = value + i;
    }
}
