// Tonemap operators and the sRGB output encoding of the composite and the
// debug views (passes/composite.h). Needs glint/composite_shared.h and
// glint/packing.h (linearToSrgb) first.
#ifndef GLINT_TONEMAP_GLSL
#define GLINT_TONEMAP_GLSL

// Khronos PBR Neutral (Khronos 3D Formats Working Group, 2024): identity
// below 0.76 apart from a small offset that lifts near-blacks, then a
// hyperbolic compression of the largest channel towards 1 with a slight
// desaturation, so base colours under bright light keep their hue.
vec3 tonemapKhronosPbrNeutral(vec3 color) {
    const float startCompression = 0.8 - 0.04;
    const float desaturation = 0.15;
    const float x = min(color.r, min(color.g, color.b));
    const float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    color -= offset;
    const float peak = max(color.r, max(color.g, color.b));
    if (peak < startCompression) {
        return color;
    }
    const float d = 1.0 - startCompression;
    const float newPeak = 1.0 - d * d / (peak + d - startCompression);
    color *= newPeak / peak;
    const float g = 1.0 - 1.0 / (desaturation * (peak - newPeak) + 1.0);
    return mix(color, vec3(newPeak), g);
}

// Narkowicz, "ACES Filmic Tone Mapping Curve" (2016): a rational fit of the
// ACES reference rendering and output transforms, per channel.
vec3 tonemapAcesFitted(vec3 x) {
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), vec3(0.0), vec3(1.0));
}

// Linear HDR colour (already exposed) -> display-referred [0, 1].
vec3 tonemap(vec3 color, uint op) {
    color = max(color, vec3(0.0));
    if (op == kTonemapAcesFitted) {
        return tonemapAcesFitted(color);
    }
    if (op == kTonemapClamp) {
        return clamp(color, vec3(0.0), vec3(1.0));
    }
    return clamp(tonemapKhronosPbrNeutral(color), vec3(0.0), vec3(1.0));
}

// Display-referred linear -> the sRGB-encoded values the RGBA8_UNORM
// output stores (IEC 61966-2-1).
vec4 encodeSrgb(vec3 c) {
    return vec4(linearToSrgb(c.r), linearToSrgb(c.g), linearToSrgb(c.b), 1.0);
}

#endif
