#version 460
// Environment prefilter, step 4 (passes/environment.h): the source chain's
// mip `sourceLevel` (a few thousand texels) projected onto the nine
// spherical harmonics of glint/environment_shared.h, each texel weighted by
// its solid angle. One workgroup; the CPU reads the coefficients back once
// and scales them by the cosine's band factors.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/environment_shared.h"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0) uniform sampler2D sourceTexture;
layout(set = 0, binding = 1, scalar) writeonly buffer Coefficients { vec4 coefficients[kEnvironmentShCount]; };
layout(push_constant, scalar) uniform Push { EnvironmentPrefilterConstants pc; };

const float kPi = 3.14159265358979;

shared vec3 partial[64][kEnvironmentShCount];

void main() {
    const uint thread = gl_LocalInvocationIndex;
    vec3 sum[kEnvironmentShCount];
    for (uint j = 0u; j < kEnvironmentShCount; ++j) {
        sum[j] = vec3(0.0);
    }
    const uint count = pc.size.x * pc.size.y;
    const float texelArea = 2.0 * kPi * kPi / float(count);
    for (uint t = thread; t < count; t += 64u) {
        const uvec2 texel = uvec2(t % pc.size.x, t / pc.size.x);
        const vec2 uv = (vec2(texel) + 0.5) / vec2(pc.size);
        const vec3 d = environmentEquirectDirection(uv);
        const float solidAngle = texelArea * sin(uv.y * kPi);
        const vec3 radiance = texelFetch(sourceTexture, ivec2(texel), int(pc.sourceLevel)).rgb;
        for (uint j = 0u; j < kEnvironmentShCount; ++j) {
            sum[j] += radiance * (environmentShBasis(j, d) * solidAngle);
        }
    }
    for (uint j = 0u; j < kEnvironmentShCount; ++j) {
        partial[thread][j] = sum[j];
    }
    barrier();
    if (thread == 0u) {
        for (uint j = 0u; j < kEnvironmentShCount; ++j) {
            vec3 total = vec3(0.0);
            for (uint i = 0u; i < 64u; ++i) {
                total += partial[i][j];
            }
            coefficients[j] = vec4(total, 0.0);
        }
    }
}
