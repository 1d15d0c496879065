// The sun's visibility from the shadow map (glint/gbuffer_shared.h's
// GBufferShadow; passes/gbuffer.cpp renders and fits the map), filtered as
// the G-buffer filters it. Shared by the G-buffer's fragment shaders
// (shaders/gbuffer/shadow.glsl, which adds the fade with camera distance)
// and the ray-traced hits (glint/rt_trace.glsl, where the map covers the
// hit). Needs glint/gbuffer_shared.h first.
#ifndef GLINT_SUN_SHADOW_GLSL
#define GLINT_SUN_SHADOW_GLSL

// Fraction of the sun reaching `position` (world) on a surface of unit
// normal `n` facing it (NoL = dot(n, toSun) > 0): 1 lit, 0 shadowed; -1
// where the map does not cover the point (nothing was rendered there to
// cast). The map is read texel by texel (reversed depth): the comparisons
// are done here, so no comparison sampler is needed and lavapipe and
// NVIDIA filter alike.
//
// Acne: a lit surface compares its own depth with the map's samples of
// itself, taken at texel centres up to two texels away (the filter's
// reach). Across a texel a surface tilted by `angle` from the sun changes
// depth by tan(angle) texels, so the receiver moves towards the sun by a
// constant plus a slope-scaled bias, and along its normal by the normal
// offset (sin(angle) texels of it buys tan(angle) texels of depth while
// moving the lookup less than a texel sideways).
//
// Filter: the mean of a 3x3 grid of bilinearly weighted comparisons one
// texel apart, which is 4x4 texels with per-axis weights
// (1 - f, 1, 1, f) / 3: a tent three texels wide that moves smoothly with
// the sub-texel position f, so edges neither stair-step nor swim.
float sunShadowMapVisibility(sampler2D map, GBufferShadow sh, float NoL, vec3 position, vec3 n) {
    const float sinAngle = sqrt(max(1.0 - NoL * NoL, 0.0));
    const float tanAngle = min(sinAngle / NoL, sh.maxSlope);

    const vec3 offsetPosition = position + n * (sh.normalOffset * sh.texelWorldSize * sinAngle);
    const vec4 clip = sh.viewProjection * vec4(offsetPosition, 1.0);
    const vec2 uv = clip.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        return -1.0;
    }
    // Reversed depth: towards the sun is larger.
    const float bias = (sh.constantBias + sh.slopeBias * tanAngle) * sh.texelWorldSize / sh.depthRange;
    const float receiver = clip.z + bias;

    const float size = float(sh.resolution);
    const vec2 texelPosition = uv * size - 0.5;  // texel centres at integers
    const vec2 base = floor(texelPosition);
    const vec2 f = texelPosition - base;
    const vec4 wx = vec4(1.0 - f.x, 1.0, 1.0, f.x) * (1.0 / 3.0);
    const vec4 wy = vec4(1.0 - f.y, 1.0, 1.0, f.y) * (1.0 / 3.0);
    const ivec2 last = ivec2(sh.resolution) - 1;
    float visibility = 0.0;
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            const ivec2 texel = clamp(ivec2(base) + ivec2(i - 1, j - 1), ivec2(0), last);
            const float occluder = texelFetch(map, texel, 0).x;
            visibility += receiver >= occluder ? wx[i] * wy[j] : 0.0;
        }
    }
    return visibility;
}

#endif
