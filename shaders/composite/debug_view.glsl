// The debug view (passes/composite.h): any texture to the composite's
// RGBA8 sRGB-encoded output. The stage files declare the source binding
// (sourceTexture, a float or unsigned integer sampler) and fetchSource(),
// then include this.
#ifndef GLINT_DEBUG_VIEW_GLSL
#define GLINT_DEBUG_VIEW_GLSL

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 1, rgba8) uniform writeonly image2D outputImage;

layout(push_constant, scalar) uniform Constants { DebugViewConstants pc; };

// NaN and Inf show as magenta, which no ramp colour is.
const vec3 kNotFinite = vec3(1.0, 0.0, 1.0);

// Viridis (van der Walt and Smith, matplotlib, 2015) at 0, 1/4, 1/2, 3/4
// and 1, as the sRGB-encoded bytes #440154 #3B528B #21918C #5EC962 #FDE725,
// interpolated linearly in the encoded values: perceptually ordered and
// readable with colour-vision deficiencies.
const vec3 kRamp[5] = vec3[5](vec3(68.0, 1.0, 84.0) / 255.0, vec3(59.0, 82.0, 139.0) / 255.0,
                              vec3(33.0, 145.0, 140.0) / 255.0, vec3(94.0, 201.0, 98.0) / 255.0,
                              vec3(253.0, 231.0, 37.0) / 255.0);

// On the bits (an all-ones exponent), not isnan/isinf, which a compiler
// assuming no NaN may fold away.
bool finiteValue(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }

vec3 rampColor(float t) {
    const float s = clamp(t, 0.0, 1.0) * 4.0;
    const int i = min(int(floor(s)), 3);
    return mix(kRamp[i], kRamp[i + 1], s - float(i));
}

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.size.x) || p.y >= int(pc.size.y)) {
        return;
    }
    // A half-size source of an odd-sized output: its last column or row
    // shows the texel before.
    const vec4 v = fetchSource(min(p >> int(pc.sourceShift), textureSize(sourceTexture, 0) - 1));
    vec4 encoded;
    if (pc.kind == kDebugViewScalar) {
        const float x = v.r;
        if (!finiteValue(x)) {
            encoded = vec4(kNotFinite, 1.0);
        } else {
            const float range = pc.maxValue - pc.minValue;
            const float t = range > 0.0 ? (x - pc.minValue) / range : (x >= pc.maxValue ? 1.0 : 0.0);
            encoded = vec4(rampColor(t), 1.0);
        }
    } else {
        const bool finite = finiteValue(v.r) && finiteValue(v.g) && finiteValue(v.b);
        if (!finite) {
            encoded = vec4(kNotFinite, 1.0);
        } else if (pc.kind == kDebugViewRaw) {
            encoded = vec4(clamp(v.rgb, vec3(0.0), vec3(1.0)), 1.0);
        } else {
            encoded = encodeSrgb(tonemap(v.rgb * pc.exposure, pc.tonemap));
        }
    }
    imageStore(outputImage, p, encoded);
}

#endif
