#version 460
// A stand-in for graphics-queue work that does not touch the BVH
// (glint-bvh-bench --overlap): dst[i] = f^iterations(src[i] or a seed), a
// dependent chain of multiply-adds per element, so the cost scales with
// `iterations` (arithmetic) and `count` (bandwidth).

layout(local_size_x = 256) in;
layout(set = 0, binding = 0, std430) readonly buffer Src { vec4 src[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Dst { vec4 dst[]; };
layout(push_constant, std430) uniform Push {
    uint count;
    uint iterations;
    uint useSrc;
};

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= count) {
        return;
    }
    vec4 v = useSrc != 0u ? src[i] : vec4(float(i & 1023u) * 1.0e-3, 0.25, 0.5, 0.75);
    for (uint k = 0u; k < iterations; ++k) {
        // Stays in [0, 1): no overflow, nothing the compiler can fold.
        v = fract(v * v * 0.75 + v * 0.5 + 0.125);
    }
    dst[i] = v;
}
