#version 460
// Composite (passes/composite.h): the lit colour plus the resolved
// reflections weighted by the split-sum environment BRDF of GGX, under the
// blended surfaces' premultiplied layer when there is one, exposed,
// tonemapped and sRGB-encoded into an RGBA8 image.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/composite_shared.h"
#include "glint/gbuffer_shared.h"
#include "glint/brdf.glsl"
#include "glint/packing.h"
#include "tonemap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D litTexture;
layout(set = 0, binding = 1) uniform sampler2D albedoTexture;
layout(set = 0, binding = 2) uniform sampler2D normalTexture;
layout(set = 0, binding = 3) uniform sampler2D roughnessMetalTexture;
layout(set = 0, binding = 4) uniform sampler2D depthTexture;
layout(set = 0, binding = 5) uniform sampler2D reflectionTexture;
// Premultiplied blended surfaces (passes/transparent.h), a = coverage.
layout(set = 0, binding = 6) uniform sampler2D transparencyTexture;
layout(set = 0, binding = 7, rgba8) uniform writeonly image2D outputImage;

layout(push_constant, scalar) uniform Constants { CompositeConstants pc; };

// On the bits (an all-ones exponent), not isnan/isinf, which a compiler
// assuming no NaN may fold away.
bool isFinite(vec3 v) { return all(notEqual(floatBitsToUint(v) & 0x7F800000u, uvec3(0x7F800000u))); }

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.size.x) || p.y >= int(pc.size.y)) {
        return;
    }
    vec3 color = texelFetch(litTexture, p, 0).rgb;
    if (!isFinite(color)) {
        color = vec3(0.0);
    }
    const float depth = texelFetch(depthTexture, p, 0).x;
    const vec4 normal = texelFetch(normalTexture, p, 0);
    if (pc.hasReflections != 0u && depth > 0.0 && normal.w > 0.0) {
        const vec4 reflection = texelFetch(reflectionTexture, p, 0);
        if (reflection.a > 0.0 && isFinite(reflection.rgb)) {
            const vec2 ndc = (vec2(p) + 0.5) / vec2(pc.size) * 2.0 - 1.0;
            const vec4 world = pc.inverseViewProjection * vec4(ndc, depth, 1.0);
            const vec3 toViewer = normalize(pc.cameraPosition.xyz - world.xyz / world.w);
            const vec4 rm = texelFetch(roughnessMetalTexture, p, 0);
            Surface s;
            s.position = world.xyz / world.w;
            s.normal = normalize(normal.xyz);
            s.albedo = texelFetch(albedoTexture, p, 0).rgb;
            s.roughness = rm.r;
            s.metallic = rm.g;
            s.reflectance = rm.b;
            const float NoV = clamp(dot(s.normal, toViewer), 0.0, 1.0);
            color += max(reflection.rgb, vec3(0.0)) * envBrdfApprox(surfaceF0(s), s.roughness, NoV);
        }
    }
    if (pc.hasTransparency != 0u) {
        const vec4 layer = texelFetch(transparencyTexture, p, 0);
        if (isFinite(layer.rgb) && isFinite(vec3(layer.a))) {
            color = max(layer.rgb, vec3(0.0)) + (1.0 - clamp(layer.a, 0.0, 1.0)) * color;
        }
    }
    imageStore(outputImage, p, encodeSrgb(tonemap(color * pc.exposure, pc.tonemap)));
}
