#version 460
// Environment prefilter, step 3 (passes/environment.h): one level of the
// prefiltered radiance. Roughness 0 copies a mip of the source chain; above
// it each texel integrates the source over the GGX lobe of its roughness
// around its own direction with N = V = R, weighted by N.L (Karis, "Real
// Shading in Unreal Engine 4", 2013), from `samples` Hammersley samples of
// D(h) (N.h). Each sample reads the source chain at the mip whose texels
// cover the sample's solid angle (filtered importance sampling: Krivanek
// and Colbert, "Real-time Shading with Filtered Importance Sampling",
// EGSR 2008, eq. 13), so few samples give a smooth result and a bright
// texel cannot become a firefly. No mip narrower than the pass allows
// (sourceMaxLod) is read, and their +1 bias is left out: both blurred a
// horizon by 6-15% beyond the lobe at roughness 0.8-1
// (tests/gpu/environment_test.cpp).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/environment_shared.h"
#include "glint/sampling.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D sourceTexture;  // the source chain, trilinear
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D levelImage;
layout(push_constant, scalar) uniform Push { EnvironmentPrefilterConstants pc; };

const float kPi = 3.14159265358979;
const float kLodBias = 0.0;

vec2 hammersley(uint i, uint n) {
    return vec2((float(i) + 0.5) / float(n), float(bitfieldReverse(i)) * 2.3283064365386963e-10);
}

void main() {
    const uvec2 texel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(texel, pc.size))) {
        return;
    }
    if (pc.roughness <= 0.0) {
        const vec3 c = texelFetch(sourceTexture, ivec2(texel), int(pc.sourceLevel)).rgb;
        imageStore(levelImage, ivec2(texel), vec4(environmentSanitize(c, pc.maxValue), 1.0));
        return;
    }
    const vec3 N = environmentEquirectDirection((vec2(texel) + 0.5) / vec2(pc.size));
    const vec3 T = basisTangent(N);
    const vec3 B = basisBitangent(N);
    const float alpha = pc.roughness * pc.roughness;
    const float a2 = alpha * alpha;
    // Solid angle of a source texel at the equator, mip 0; sin(theta) times
    // that elsewhere.
    const float texelSolidAngle = 2.0 * kPi * kPi / float(pc.sourceSize.x * pc.sourceSize.y);

    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = 0u; i < pc.samples; ++i) {
        const vec2 u = hammersley(i, pc.samples);
        // GGX half vector, pdf D(h) (N.h) (Walter et al. 2007, eq. 35-36).
        const float cosH = sqrt((1.0 - u.x) / (1.0 + (a2 - 1.0) * u.x));
        const float sinH = sqrt(max(0.0, 1.0 - cosH * cosH));
        const float phi = 2.0 * kPi * u.y;
        const vec3 H = T * (sinH * cos(phi)) + B * (sinH * sin(phi)) + N * cosH;
        const vec3 L = 2.0 * cosH * H - N;
        const float NoL = dot(N, L);
        if (NoL <= 0.0) {
            continue;
        }
        // pdf of L: D (N.h) / (4 V.h) = D / 4 with V = N.
        const float d = (cosH * a2 - cosH) * cosH + 1.0;
        const float pdf = a2 / (kPi * d * d) * 0.25;
        const float sampleSolidAngle = 1.0 / (float(pc.samples) * pdf);
        const float sinTheta = max(sqrt(max(0.0, 1.0 - L.y * L.y)), 1e-3);
        const float lod = clamp(0.5 * log2(sampleSolidAngle / (texelSolidAngle * sinTheta)) + kLodBias, 0.0,
                                pc.sourceMaxLod);
        sum += textureLod(sourceTexture, environmentEquirectUv(L), lod).rgb * NoL;
        weight += NoL;
    }
    const vec3 c = weight > 0.0 ? sum / weight : vec3(0.0);
    imageStore(levelImage, ivec2(texel), vec4(environmentSanitize(c, pc.maxValue), 1.0));
}
