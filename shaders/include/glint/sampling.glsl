// Random numbers and GGX importance sampling, shared by GLSL and C++ (the
// same dialect as glint/packing.h: no swizzles, `f` literals), so the C++
// tests run exactly the maths the shaders run.
//
// Noise: every sequence is a pure function of (pixel, frame index), so the
// same command gives the same image (the reference and the goldens rely on it).
#ifndef GLINT_SAMPLING_GLSL
#define GLINT_SAMPLING_GLSL

#include "glint/shared.h"

#ifdef __cplusplus
#include <cmath>
#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
namespace glint::shader {
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::max;
using glm::min;
using glm::normalize;
using std::cos;
using std::sin;
using std::sqrt;
} // namespace glint::shader
#ifndef GLINT_FUNC
#define GLINT_FUNC inline
#endif
#else
#ifndef GLINT_FUNC
#define GLINT_FUNC
#endif
#endif

GLINT_BEGIN

GLINT_CONST float kSamplingPi = 3.14159265358979f;

// ---------------------------------------------------------------------------
// Hashing and low-discrepancy noise
// ---------------------------------------------------------------------------

// Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020:
// PCG's output permutation is the best quality per cost of the hashes they
// compare.
GLINT_FUNC uint pcgHash(uint v) {
    const uint state = v * 747796405u + 2891336453u;
    const uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Top 24 bits of a 32-bit fixed-point fraction -> float in [0, 1), exact.
GLINT_FUNC float unitFromBits(uint bits) {
    return float(bits >> 8u) * (1.0f / 16777216.0f);
}

// Each use of random numbers in a frame draws its own dimension, so that
// no two uses see the same number, or a shifted copy of it: the GGX
// sample (two dimensions), SSLR's start offset, and which pixels of an RT
// tile stay hybrid. Were two uses to share a dimension, the SSLR offset
// would follow the GGX sample's u.x, and the pixels kept hybrid would all
// draw GGX samples from one band of u.x.
GLINT_CONST uint kNoiseSslrOffset = 0u;
GLINT_CONST uint kNoiseRtToHybrid = 1u;
GLINT_CONST uint kNoiseHistoryRounding = 2u;

// Roberts' R2 sequence ("The Unreasonable Effectiveness of Quasirandom
// Sequences", 2018): x_n = frac(n / g, n / g^2), g = 1.3247179572 (the
// plastic number), here in 32-bit fixed point (2^32 / g, 2^32 / g^2) so
// it wraps exactly instead of losing precision as n grows. Each pixel
// offsets it by its own hash (a Cranley-Patterson rotation), so pixels are
// decorrelated and every pixel still walks a low-discrepancy sequence over
// frames. The GGX sample's two dimensions.
GLINT_FUNC vec2 ggxNoise(uvec2 pixel, uint frame) {
    const uint h = pcgHash(pixel.x + pcgHash(pixel.y));
    const uint seedX = h;
    const uint seedY = pcgHash(h);
    return vec2(unitFromBits(seedX + frame * 3242174889u), unitFromBits(seedY + frame * 2447445413u));
}

// One more dimension, kNoise*: a Weyl sequence frac(seed + n alpha) per
// pixel, its seed hashed from the pixel and the dimension, its step an
// irrational of its own: 2^32 / golden ratio for the SSLR offset, 2^32
// (sqrt 2 - 1) for the hybrid share, 2^32 (sqrt 3 - 1) for the history's
// rounding. 1, 1/g, 1/g^2, 1/phi, sqrt 2 and sqrt 3 are linearly
// independent over the rationals (the fields Q(g) and
// Q(sqrt 5, sqrt 2, sqrt 3) meet only in Q), so over frames each pixel's
// GGX sample and these dimensions are jointly equidistributed (Weyl), and
// across pixels their seeds are independent hashes.
GLINT_FUNC float scalarNoise(uvec2 pixel, uint frame, uint dimension) {
    const uint seed = pcgHash(pixel.x + pcgHash(pixel.y + pcgHash(dimension + 0x51ED27u)));
    const uint step = dimension == kNoiseSslrOffset   ? 2654435769u
                      : dimension == kNoiseRtToHybrid ? 1779033703u
                                                      : 3144134277u;
    return unitFromBits(seed + frame * step);
}

// Spatiotemporal blue noise (glint/sampling/blue_noise.h, generated at
// build time): the same four uses from a 64 x 64 x 32 volume, one channel
// each, the volume tiling the screen and frame t reading slice t mod 32.
// Each pass through the 32 slices shifts the volume by an R2 step, so the
// pattern does not repeat every 32 frames. The shaders read it as a
// storage buffer of uvec2 per texel (four 16-bit channels); the passes
// check that the file has this size and these channels.
GLINT_CONST uint kBlueNoiseWidth = 64u;
GLINT_CONST uint kBlueNoiseHeight = 64u;
GLINT_CONST uint kBlueNoiseDepth = 32u;
GLINT_CONST uint kBlueNoiseChannels = 4u;
GLINT_CONST uint kBlueNoiseGgxX = 0u;
GLINT_CONST uint kBlueNoiseGgxY = 1u;
GLINT_CONST uint kBlueNoiseSslrOffset = 2u;
GLINT_CONST uint kBlueNoiseRtToHybrid = 3u;

// The texel pixel `pixel` reads in frame `frame`.
GLINT_FUNC uint blueNoiseTexel(uvec2 pixel, uint frame) {
    const uint cycle = frame / kBlueNoiseDepth;
    const uint x = (pixel.x + ((cycle * 3242174889u) >> 26u)) % kBlueNoiseWidth;
    const uint y = (pixel.y + ((cycle * 2447445413u) >> 26u)) % kBlueNoiseHeight;
    return ((frame % kBlueNoiseDepth) * kBlueNoiseHeight + y) * kBlueNoiseWidth + x;
}

// Channel `channel` of a texel's two words, as a number in (0, 1).
GLINT_FUNC float blueNoiseChannel(uvec2 texel, uint channel) {
    const uint word = channel < 2u ? texel.x : texel.y;
    const uint value = (word >> (16u * (channel & 1u))) & 0xFFFFu;
    return (float(value) + 0.5f) * (1.0f / 65536.0f);
}

// ---------------------------------------------------------------------------
// Tangent frames
// ---------------------------------------------------------------------------

// Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, "Building an
// Orthonormal Basis, Revisited", JCGT 6(1), 2017: branch-free except for
// the sign, no singularity at n.z = -1.
GLINT_FUNC vec3 basisTangent(vec3 n) {
    const float s = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (s + n.z);
    const float b = n.x * n.y * a;
    return vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
}

GLINT_FUNC vec3 basisBitangent(vec3 n) {
    const float s = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (s + n.z);
    const float b = n.x * n.y * a;
    return vec3(b, s + n.y * n.y * a, -n.y);
}

// ---------------------------------------------------------------------------
// GGX visible normals
// ---------------------------------------------------------------------------

// Below this alpha the GGX lobe is narrower than a 16-bit octahedral
// direction can resolve, and Heitz's warp divides by ~0 in its last
// normalisation; the microfacet normal is the macro normal (a mirror).
GLINT_CONST float kMirrorAlpha = 1e-4f;

// Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4),
// 2018, listing 1, isotropic. `v` is the view direction in the tangent
// frame (z = normal) with v.z > 0; u in [0, 1)^2. Returns a microfacet
// normal distributed as D_v(h) = G1(v) max(0, v.h) D(h) / v.z.
GLINT_FUNC vec3 sampleGgxVndf(vec3 v, float alpha, vec2 u) {
    if (alpha < kMirrorAlpha) {
        return vec3(0.0f, 0.0f, 1.0f);
    }
    // Stretch the view into the hemisphere configuration (alpha = 1).
    const vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * (1.0f / sqrt(lensq)) : vec3(1.0f, 0.0f, 0.0f);
    const vec3 t2 = cross(vh, t1);
    // A point on the projected disk, warped onto the visible half.
    const float r = sqrt(u.x);
    const float phi = 2.0f * kSamplingPi * u.y;
    const float p1 = r * cos(phi);
    const float s = 0.5f * (1.0f + vh.z);
    const float p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * (r * sin(phi));
    const vec3 nh = t1 * p1 + t2 * p2 + vh * sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2));
    // Unstretch; the max keeps the normal in the upper hemisphere.
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-6f, nh.z)));
}

// Smith G1 of GGX (Heitz 2014, "Understanding the Masking-Shadowing
// Function", eq. 72) and the GGX distribution; the tests use them as the
// analytic answer.
GLINT_FUNC float ggxSmithG1(float cosTheta, float alpha) {
    const float c2 = cosTheta * cosTheta;
    const float tan2 = max(0.0f, 1.0f - c2) / max(c2, 1e-12f);
    return 2.0f / (1.0f + sqrt(1.0f + alpha * alpha * tan2));
}

GLINT_FUNC float ggxD(float cosTheta, float alpha) {
    const float a2 = alpha * alpha;
    const float d = (cosTheta * a2 - cosTheta) * cosTheta + 1.0f;
    return a2 / (kSamplingPi * d * d);
}

// Smallest cosine between a reflection ray and the surface: rays are kept
// at least this far above the tangent plane, so after 16-bit octahedral
// packing (error ~5e-5 rad) they still leave the surface.
GLINT_CONST float kMinRayCosine = 1e-3f;

// Smallest cosine of the view direction with the shading normal: at
// grazing angles (and where interpolated normals face away from the eye)
// the view is bent up to this so the sampler's v.z > 0 holds.
GLINT_CONST float kMinViewCosine = 1e-3f;

// One reflection direction in world space for a surface with unit normal n
// seen along unit `toEye` (surface -> eye), perceptual roughness
// `roughness` (alpha = roughness^2, as glint/brdf.glsl). Never below the
// surface: a sample that reflects under it (possible for visible normals
// at grazing view) is mirrored about the tangent plane, then lifted to
// kMinRayCosine.
GLINT_FUNC vec3 sampleReflection(vec3 n, vec3 toEye, float roughness, vec2 u) {
    const float nov = dot(n, toEye);
    vec3 v = toEye;
    if (nov < kMinViewCosine) {
        v = normalize(toEye + n * (kMinViewCosine - nov));
    }
    const vec3 t = basisTangent(n);
    const vec3 b = basisBitangent(n);
    const vec3 vt = vec3(dot(v, t), dot(v, b), dot(v, n));
    const vec3 ht = sampleGgxVndf(vt, roughness * roughness, u);
    const vec3 h = t * ht.x + b * ht.y + n * ht.z;
    vec3 l = h * (2.0f * dot(v, h)) - v;
    const float lon = dot(l, n);
    if (lon < kMinRayCosine) {
        l = l - n * (2.0f * min(lon, 0.0f));
        l = normalize(l + n * max(0.0f, kMinRayCosine - dot(l, n)));
    }
    return l;
}

GLINT_END

#endif
