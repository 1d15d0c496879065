#version 460
// Compiles glint/packing.h as GLSL (the C++ suites compile it as C++), using
// every function the hit and packing shaders will call.
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/packing.h"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, scalar) buffer Pool { PackedPrimitive pool[]; };
layout(set = 0, binding = 1, scalar) readonly buffer Offsets { uint primitiveOffsets[]; };

void main() {
    SurfaceVertex s;
    s.albedo = vec3(0.5, 0.25, 0.125);
    s.roughness = 0.3;
    s.normal = normalize(vec3(gl_GlobalInvocationID) + vec3(1.0));
    s.metallic = 1.0;
    s.reflectance = kDefaultReflectance;
    const uint slot = primitiveOffsets[primitiveOffsetSlot(gl_GlobalInvocationID.x, 1u)] + 2u;
    pool[slot].vertices[0] = packVertex(s);
    const SurfaceVertex hit = interpolateSurface(pool[slot], vec2(0.25, 0.5));
    pool[slot].vertices[1].albedoSmoothness = packOctNormal(hit.normal) ^ encodeSnorm8(hit.roughness);
    pool[slot].vertices[2].albedoSmoothness = uint(reflectanceToF0(hit.reflectance) * 255.0);
}
