// The G-buffer pass (passes/gbuffer.cpp, shaders/gbuffer/*): structs shared
// by GLSL and C++. Buffers use scalar layout.
//
// Conventions of the outputs:
//   depth          reversed Z (near 1, far or infinity 0), cleared to 0
//   normal         world-space unit normal in xyz, w = 1 where geometry was drawn
//   albedo         linear base colour, stored sRGB-encoded (R8G8B8A8_SRGB), a = 1
//   roughnessMetal r = perceptual roughness, g = metallic, b = reflectance, a = 1
//   motion         pixels from this frame's position back to last frame's, both
//                  unjittered: history lookup = pixel + motion
//   lit            radiance of the opaque scene (sun + diffuse ambient +
//                  emission, which is neither lit nor shadowed; no
//                  specular ambient: the reflection passes add that), a =
//                  the sun's visibility there (0 shadowed to 1 lit), with
//                  which SSLR re-lights its hits for the ray's direction;
//                  the sky's radiance with a = 0 where nothing was drawn.
//                  The sun term is shadowed by the shadow map below; the
//                  ambient term never is (the ray-traced hits light the same
//                  way, their sun visibility from this map where it covers
//                  them, else from a shadow ray).
//   shadowMap      the sun's shadow map (its own pass before the G-buffer):
//                  D32_SFLOAT, square, an orthographic view along the sun's
//                  rays. Reversed like the camera's depth: 1 at the side
//                  facing the sun, 0 at the far side, cleared to 0 (nothing
//                  casts there); each texel keeps the occluder nearest the
//                  sun (GREATER_OR_EQUAL). Its world -> clip matrix and
//                  scale are GBufferShadow below. With shadows off it is
//                  one texel, cleared, and no pixel reads it.
#ifndef GLINT_GBUFFER_SHARED_H
#define GLINT_GBUFFER_SHARED_H

#include "glint/shared.h"
#include "glint/texture_transform.h"

GLINT_BEGIN

// One vertex of a LOD-0 geometry, uploaded once (116 bytes). The material
// is evaluated at the vertex on the CPU (scene::surfaceAtVertex, as the BVH
// manager does for the packed primitives), except for the textures the
// G-buffer samples per pixel (base colour, metallic-roughness, normal; see
// GBufferDraw): for those the vertex holds only the factors (and COLOR_0),
// and the fragment shader multiplies in the texel at the texture
// coordinates below.
struct GBufferVertex {
    vec3 position;  // object space, bind pose for skinned geometry
    vec3 normal;
    vec3 albedo;    // linear; without the base colour texture when it is sampled per pixel
    float roughness;  // likewise without the metallic-roughness texture
    float metallic;
    float reflectance;
    uvec2 joints;   // four 16-bit joint indices: x = j0 | j1 << 16, y = j2 | j3 << 16
    vec4 weights;   // zero for rigid geometry
    vec4 tangent;   // object space xyz, w = bitangent sign (glTF: B = cross(N, T) * w)
    vec2 uv0;       // TEXCOORD_0 (zero when absent)
    vec2 uv1;       // TEXCOORD_1
    // Emitted radiance in glTF units (emissiveFactor x strength; x the
    // emissive texture at the vertex where it is not sampled per pixel),
    // times SceneLighting's emissive scale in the shader.
    vec3 emissive;
    // Coverage: baseColorFactor.a x COLOR_0.a (the base colour texture's
    // alpha multiplies it per pixel); alpha-tested draws compare it with
    // GBufferDraw::alphaCutoff.
    float alpha;
};

// One scene instance this frame and last (144 bytes).
struct GBufferInstance {
    mat4 transform;
    mat4 previousTransform;
    uint jointOffset;  // first matrix in the joint palettes
    uint jointCount;   // 0: rigid
    // Morphing instances whose weights changed since last frame: last
    // frame's morphed copy of a vertex lies this many vertices after this
    // frame's (0: the vertex did not move in object space).
    uint previousVertexDelta;
    uint pad1;
};

// The sun and the environment in the units of the lit output (see
// GBufferSettings in passes/gbuffer.h). Shared with the hit shaders that
// light reflections the same way; glint/environment.glsl looks the
// environment up (240 bytes).
struct SceneLighting {
    // xyz: unit, towards the sun; w: the emissive scale (glTF emissive
    // radiance -> lit-colour units, LightingSettings::emissiveScale).
    vec4 sunDirection;
    vec4 sunIrradiance;  // rgb: at normal incidence
    vec4 skyZenith;      // rgb radiance of the procedural sky (an image's mean, unused by the shaders)
    vec4 skyHorizon;
    vec4 skyGround;
    // x: 1 = the prefiltered image (passes/environment.h) is bound and
    // looked up, 0 = the procedural sky above; y: the image's scale
    // (intensity times the ambient scale); z: the image's last level
    // (glint/environment_shared.h); w: its rotation about +Y, radians.
    vec4 environment;
    // rgb: the image's irradiance as nine SH coefficients, cosine-convolved
    // and unscaled (glint/environment_shared.h); zero for the procedural sky.
    vec4 irradianceSh[9];
};

// The sun's shadow map this frame (passes/gbuffer.cpp fits it; the
// fragment shader filters it, shaders/gbuffer/shadow.glsl). 112 bytes.
// Biases are in shadow texels (texelWorldSize world units each), so they
// hold whatever resolution and fit the map has.
struct GBufferShadow {
    // World -> shadow clip: x, y in [-1, 1] across the map (texel centres
    // on a world-fixed grid: the centre is snapped to whole texels), z the
    // reversed depth (1 nearest the sun), w = 1.
    mat4 viewProjection;
    float texelWorldSize;  // world units per texel, both axes
    float depthRange;      // world units along the sun's rays per unit of depth
    float constantBias;    // texels along the sun's rays
    float slopeBias;       // texels times tan(angle between normal and sun)
    float normalOffset;    // texels along the normal, times sin(that angle)
    float maxSlope;        // clamp of that tangent
    float fadeStart;       // camera distance where shadows start fading out
    float fadeEnd;         // and where they are gone; not above fadeStart: no fade
    uint resolution;       // texels per side
    uint enabled;          // 0: the sun is unshadowed, the map is not read
    uint pad0;
    uint pad1;
};

// Per-frame constants (binding 0).
struct GBufferFrame {
    mat4 jitteredViewProjection;   // rasterisation
    mat4 viewProjection;           // unjittered, for motion
    mat4 previousViewProjection;   // unjittered, last frame
    mat4 inverseViewProjection;    // unjittered: the sky's view rays
    vec4 cameraPosition;
    vec2 size;                     // pixels
    vec2 pad;
    SceneLighting lighting;
    GBufferShadow shadow;
};

// Push constants of a run of draws that share a material (124 bytes,
// within the 128 Vulkan guarantees). The instance is not among them: each
// draw's firstInstance is its GBufferInstance index (gl_InstanceIndex), so
// one multi-draw covers many instances. Per material texture the draw
// samples per pixel, its flag holds the texture coordinate set plus one
// (1: GBufferVertex::uv0, 2: uv1); 0: the slot is not sampled (its 1x1
// fallback stays bound, the vertex holds the whole value). The branches on
// the flags are uniform per draw.
struct GBufferDraw {
    uint doubleSided;     // 1: back faces are lit with the flipped normal
    float normalScale;    // glTF normalTexture.scale
    // Perturb the normal with the normal map (binding 7).
    uint normalMap;
    // Multiply the vertex albedo (factor times COLOR_0) by the base colour
    // texture (binding 8, sRGB-decoded by the sampler).
    uint baseColorMap;
    // Multiply the vertex roughness and metallic (the factors) by the
    // metallic-roughness texture's G and B (binding 9, linear).
    uint metalRoughMap;
    // Multiply the vertex emission (factor times strength) by the emissive
    // texture (binding 10, sRGB-decoded by the sampler).
    uint emissiveMap;
    UvTransform normalUvTransform;  // each texture's KHR_texture_transform
    UvTransform baseColorUvTransform;
    UvTransform metalRoughUvTransform;
    UvTransform emissiveUvTransform;
    // glTF alphaMode MASK: fragments whose alpha (the vertex's times the
    // base colour texel's) is below it are discarded, in the G-buffer and
    // in the shadow map; only the alpha-tested pipelines read it (opaque
    // draws keep early depth testing).
    float alphaCutoff;
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::GBufferVertex) == 120);
static_assert(sizeof(glint::shader::GBufferInstance) == 144);
static_assert(sizeof(glint::shader::GBufferDraw) <= 128);  // Vulkan's guaranteed push constant space
static_assert(sizeof(glint::shader::GBufferShadow) == 112);
static_assert(sizeof(glint::shader::SceneLighting) == 240);
#endif

#endif
