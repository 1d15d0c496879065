// The prefiltered environment (passes/environment.h, shaders/environment/*):
// what its prefilter and every lookup (glint/environment.glsl) share, in the
// dialect GLSL and C++ both read (as glint/sampling.glsl), so the C++ tests
// run the same maths.
//
// The prefiltered radiance is one equirectangular image (glint's
// equirectUv: u grows with atan2(x, -z), v = 0 at +Y) with a mip chain:
// level 0 is the source (halved until at most EnvironmentSettings::maxWidth
// wide), level k holds the GGX lobe of perceptual roughness
// environmentRoughnessOfLevel(k) around each texel's direction, split-sum
// style (N = V = R; Karis, "Real Shading in Unreal Engine 4", SIGGRAPH
// 2013), down to a level kEnvironmentMinWidth texels wide. A lookup for
// roughness r reads level r * maxLod with trilinear filtering, so levels
// are evenly spaced in perceptual roughness.
//
// Diffuse irradiance is nine spherical-harmonic coefficients per channel,
// already convolved with the clamped cosine (Ramamoorthi and Hanrahan, "An
// Efficient Representation for Irradiance Environment Maps", SIGGRAPH
// 2001): E(n) = sum_j sh[j] * environmentShBasis(j, n); a constant
// radiance L gives E = pi * L, glint/brdf.glsl's convention.
#ifndef GLINT_ENVIRONMENT_SHARED_H
#define GLINT_ENVIRONMENT_SHARED_H

#include "glint/shared.h"

#ifndef GLINT_FUNC
#ifdef __cplusplus
#define GLINT_FUNC inline
#else
#define GLINT_FUNC
#endif
#endif

GLINT_BEGIN

// The roughest level is this many texels wide (4 high): a GGX lobe of
// roughness 1 spans a hemisphere, which 8x4 texels hold.
GLINT_CONST uint kEnvironmentMinWidth = 8u;
// Spherical-harmonic coefficients of the irradiance (bands 0-2).
GLINT_CONST uint kEnvironmentShCount = 9u;

// Perceptual roughness -> level of the prefiltered chain (fractional:
// trilinear between levels).
GLINT_FUNC float environmentLevelOfRoughness(float roughness, float maxLod) {
    return roughness * maxLod;
}

// The roughness level `level` was prefiltered for.
GLINT_FUNC float environmentRoughnessOfLevel(float level, float maxLod) {
    return maxLod > 0.0f ? level / maxLod : 0.0f;
}

// Real spherical harmonics, bands 0-2 (Sloan, "Stupid Spherical Harmonics
// Tricks", GDC 2008, appendix), of the unit direction d.
GLINT_FUNC float environmentShBasis(uint j, vec3 d) {
    if (j == 0u) return 0.282095f;
    if (j == 1u) return 0.488603f * d.y;
    if (j == 2u) return 0.488603f * d.z;
    if (j == 3u) return 0.488603f * d.x;
    if (j == 4u) return 1.092548f * d.x * d.y;
    if (j == 5u) return 1.092548f * d.y * d.z;
    if (j == 6u) return 0.315392f * (3.0f * d.z * d.z - 1.0f);
    if (j == 7u) return 1.092548f * d.x * d.z;
    return 0.546274f * (d.x * d.x - d.y * d.y);
}

// The clamped cosine's convolution factor of coefficient j's band:
// pi, 2 pi / 3, pi / 4 (Ramamoorthi and Hanrahan, eq. 8).
GLINT_FUNC float environmentShCosineFactor(uint j) {
    if (j == 0u) return 3.14159265358979f;
    if (j < 4u) return 2.09439510239320f;
    return 0.785398163397448f;
}

// Push constants of the prefilter's passes (shaders/environment/*.comp; 48 bytes).
struct EnvironmentPrefilterConstants {
    uvec2 size;            // texels of the mip written (source, downsample, prefilter)
    uvec2 sourceSize;      // texels of the source's mip 0
    float roughness;       // prefilter: perceptual roughness of this level; 0 copies sourceLevel
    uint samples;          // prefilter: GGX samples per texel
    uint sourceLevel;      // prefilter at roughness 0, irradiance: the source mip read
    float sourceMaxLod;    // prefilter: the source chain's last mip
    float maxValue;        // every value written is clamped to [0, maxValue] (non-finite -> 0)
    uint pad0;
    uint pad1;
    uint pad2;
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::EnvironmentPrefilterConstants) == 48);
#else

// Direction (unit) -> equirectangular uv, as scene::equirectUv; the poles
// (where atan is undefined) take u = 0.5. The polar angle is an atan too:
// acos loses precision near the poles (lavapipe's by a hundredth of a
// texel of a 64x32 image).
vec2 environmentEquirectUv(vec3 d) {
    const float horizontal = length(vec2(d.x, d.z));
    const float u = horizontal > 0.0 ? atan(d.x, -d.z) * (0.5 / 3.14159265358979) + 0.5 : 0.5;
    return vec2(u, atan(horizontal, d.y) * (1.0 / 3.14159265358979));
}

// uv -> unit direction, as scene::equirectDirection.
vec3 environmentEquirectDirection(vec2 uv) {
    const float phi = (uv.x - 0.5) * 2.0 * 3.14159265358979;
    const float theta = uv.y * 3.14159265358979;
    const float s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

// By the bits, not isnan/isinf: an implementation may assume floats are
// finite and fold those tests away.
bool environmentIsFinite(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }

// Non-finite channels -> 0, the rest clamped to [0, maxValue].
vec3 environmentSanitize(vec3 c, float maxValue) {
    return vec3(environmentIsFinite(c.x) ? clamp(c.x, 0.0, maxValue) : 0.0,
                environmentIsFinite(c.y) ? clamp(c.y, 0.0, maxValue) : 0.0,
                environmentIsFinite(c.z) ? clamp(c.z, 0.0, maxValue) : 0.0);
}
#endif

#endif
