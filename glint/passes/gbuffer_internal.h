#pragma once
// What passes/gbuffer*.cpp (the G-buffer, its assets, occlusion cull and
// shadow map) and passes/transparent.cpp (the blended surfaces, drawn
// forward with the same geometry, skinning and material textures) share of
// GBufferRenderer's insides: the pipelines' bindings, and the per-geometry
// draw ranges and per-frame work. Not part of the passes' interface.

#include "glint/passes/gbuffer.h"

#include "glint/gpu/pipeline.h"
#include "glint/scene/facets.h"
#include "glint/scene/scene.h"

#include "glint/gbuffer_shared.h"
#include "glint/occlusion_shared.h"

#include <array>
#include <cstdint>
#include <limits>
#include <mutex>
#include <vector>

namespace glint::passes::gbuffer_detail {

inline constexpr VkShaderStageFlags kRasterStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Bindings of shaders/gbuffer/gbuffer_common.glsl, shared by every pipeline.
inline std::vector<gpu::Binding> geometryBindings() {
    std::vector<gpu::Binding> bindings;
    for (uint32_t b = 0; b < 5; ++b) {
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kRasterStages});
    }
    return bindings;
}

// The pipelines that light add the shadow map (shaders/gbuffer/shadow.glsl;
// the shadow map's own pipeline cannot bind what it renders) and the
// prefiltered environment (glint/environment.glsl).
inline constexpr uint32_t kShadowMapBinding = 5;
inline constexpr uint32_t kEnvironmentBinding = 6;
// The material textures a draw samples per pixel, at bindings 7 to 10
// (gbuffer_surface.glsl), in MaterialSlot order.
inline constexpr uint32_t kFirstMaterialTextureBinding = 7;
enum MaterialSlot : size_t { kNormalSlot, kBaseColorSlot, kMetalRoughSlot, kEmissiveSlot, kMaterialSlots };
inline std::vector<gpu::Binding> surfaceBindings() {
    std::vector<gpu::Binding> bindings = geometryBindings();
    bindings.push_back({kShadowMapBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_SHADER_STAGE_FRAGMENT_BIT});
    bindings.push_back({kEnvironmentBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_SHADER_STAGE_FRAGMENT_BIT});
    for (uint32_t slot = 0; slot < kMaterialSlots; ++slot) {
        bindings.push_back({kFirstMaterialTextureBinding + slot, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                            VK_SHADER_STAGE_FRAGMENT_BIT});
    }
    return bindings;
}

// A material texture the G-buffer does not sample per pixel (none, or not
// 8-bit): the draw binds its slot's fallback.
inline constexpr size_t kNoImage = std::numeric_limits<size_t>::max();

// glTF's three wrap modes for S and T: nine samplers, this one's index.
inline constexpr size_t kWrapModes = 3;
inline size_t samplerIndex(const scene::TextureRef& ref) {
    return size_t(ref.wrapS) * kWrapModes + size_t(ref.wrapT);
}

// How a geometry's material covers what lies behind it (glTF alphaMode):
// the pipelines that draw it, and whether it is in the G-buffer at all.
enum class Coverage : uint8_t {
    Opaque,   // the G-buffer and the shadow map
    Masked,   // MASK: the same, with the alpha test
    Blended,  // BLEND: only the transparent pass (passes/transparent.h)
};

// The dynamic facing state of a command buffer, set per draw only where it
// changes. glTF: front faces wind counter-clockwise on screen (the
// projection flips Y with the framebuffer), clockwise under a mirroring
// transform; single-sided materials cull back faces, double-sided ones
// cull nothing.
struct Facing {
    VkCullModeFlags cull = VK_CULL_MODE_NONE;
    VkFrontFace front = VK_FRONT_FACE_COUNTER_CLOCKWISE;

    // After a pipeline bind: the state as it stands.
    void bind(VkCommandBuffer cmd) const {
        vkCmdSetCullMode(cmd, cull);
        vkCmdSetFrontFace(cmd, front);
    }
    void set(VkCommandBuffer cmd, bool mirrored, bool doubleSided) {
        const VkFrontFace f = mirrored ? VK_FRONT_FACE_CLOCKWISE : VK_FRONT_FACE_COUNTER_CLOCKWISE;
        if (f != front) {
            front = f;
            vkCmdSetFrontFace(cmd, front);
        }
        const VkCullModeFlags c = doubleSided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT;
        if (c != cull) {
            cull = c;
            vkCmdSetCullMode(cmd, cull);
        }
    }
};

// The occlusion cull's command buffers (glint/occlusion_shared.h): the
// command slots of `chunks` chunks, then one count per chunk.
inline uint64_t occlusionCountsOffset(uint32_t chunks) {
    return uint64_t(chunks) * shader::kOcclusionGroupSize * sizeof(VkDrawIndexedIndirectCommand);
}
inline uint64_t occlusionArgsBytes(uint32_t chunks) {
    return occlusionCountsOffset(chunks) + uint64_t(chunks) * sizeof(uint32_t);
}

} // namespace glint::passes::gbuffer_detail

namespace glint::passes {

// One LOD-0 geometry in the shared vertex and index buffers.
struct GBufferRenderer::DrawRange {
    uint32_t firstIndex = 0;
    uint32_t indexCount = 0;
    int32_t vertexOffset = 0;
    bool doubleSided = false;
    gbuffer_detail::Coverage coverage = gbuffer_detail::Coverage::Opaque;
    // The geometry's bounds in its mesh's space (the transparent pass sorts
    // by their centres).
    scene::Aabb bounds;
    // The draw's push constants; per MaterialSlot the image (kNoImage: the
    // slot's fallback) and sampler it binds.
    shader::GBufferDraw material{};
    std::array<size_t, gbuffer_detail::kMaterialSlots> image{gbuffer_detail::kNoImage, gbuffer_detail::kNoImage,
                                                             gbuffer_detail::kNoImage, gbuffer_detail::kNoImage};
    std::array<size_t, gbuffer_detail::kMaterialSlots> sampler{};
    static_assert(gbuffer_detail::kMaterialSlots == kMaterialTextureSlots);
    // Ranges with equal coverage, material and textures share the number:
    // the scene's distinct binding states, counted from 0.
    uint32_t state = 0;
    // Its triangles grouped by facing (scene/facets.h), firstIndex into the
    // shared index buffer, where the range's indices are stored in the
    // facets' order; empty: one group, never skipped (double-sided,
    // blended, skinned or morphed geometry, or none faces one way enough).
    std::vector<scene::Facet> facets;
};

// A blended geometry of one instance, with its distance from the camera
// (to its bounds centre, squared): the transparent pass draws them farthest
// first.
struct GBufferRenderer::TransparentDraw {
    float distanceSq = 0.0f;
    uint32_t instance = 0;
    const DrawRange* range = nullptr;
};

// Host-visible buffers of one frame in flight, written when the frame
// records (the executor has waited for the slot's previous frame by then).
struct GBufferRenderer::FrameSlot {
    gpu::Buffer frame;
    gpu::Buffer morphedVertices;  // this frame's morphing instances (FrameWork::morphedVertices)
    gpu::Buffer instances;
    gpu::Buffer joints;
    gpu::Buffer previousJoints;
    // The occlusion cull's inputs (FrameWork::occlusionInstances, ::draws).
    gpu::Buffer occlusionInstances;
    gpu::Buffer occlusionDraws;
};

// One draw of the G-buffer: an opaque or alpha-tested geometry of an
// instance in the frustum. FrameWork::draws holds them sorted by `run`, the
// key of what they bind (gbuffer.cpp, runKey: pipeline, material and
// textures, vertex buffer, winding), opaque ones first; draws of one key are
// one run. With occlusion culling its place is also the index of its
// indirect command, so a run's commands are contiguous: one multi-draw.
struct GBufferRenderer::SurfaceDraw {
    uint32_t instance = 0;
    const DrawRange* range = nullptr;
    // The indices drawn: the range's, or those of its facets that face the
    // camera (consecutive ones in one draw).
    uint32_t firstIndex = 0;
    uint32_t indexCount = 0;
    bool masked = false;
    uint64_t run = 0;
};

// What one frame draws, copied from the scene and camera at declaration.
struct GBufferRenderer::FrameWork {
    uint32_t slot = 0;
    bool drawSky = true;
    shader::GBufferFrame frame{};
    std::vector<shader::GBufferInstance> instances;
    std::vector<uint32_t> meshes;  // per instance
    // Per instance: drawn into the G-buffer (its bounds meet the camera's
    // frustum) and into the shadow map (they meet the map's box).
    std::vector<uint8_t> visible;
    // Per instance its world bounds, where frustum or occlusion culling
    // asked for them (else empty).
    std::vector<scene::Aabb> bounds;
    std::vector<uint8_t> castsShadow;
    // Per instance: its transform mirrors (a negative determinant), so its
    // front faces wind clockwise on screen (glTF: the determinant sets the
    // winding).
    std::vector<uint8_t> mirrored;
    std::vector<glm::mat4> joints;
    std::vector<glm::mat4> previousJoints;
    // Morphing instances: the mesh's vertices with the instance's weights
    // applied, end to end; per instance the first of them, or -1 (the
    // shared vertex buffer).
    std::vector<shader::GBufferVertex> morphedVertices;
    std::vector<int64_t> morphedFirstVertex;
    // What the G-buffer draws, in order (SurfaceDraw: by run).
    std::vector<SurfaceDraw> draws;
    // Occlusion culling (GBufferSettings::occlusionCulling): per instance
    // its grown bounds and whether it has draws; per draw its index range.
    bool occlusionCulling = false;
    // Draws the scene would have with every instance in the frustum: what
    // sizes the cull's command buffers, the same every frame.
    uint32_t drawCapacity = 0;
    std::vector<shader::OcclusionInstance> occlusionInstances;
    // Per command slot (glint/occlusion_shared.h: each run of draws takes
    // whole chunks of slots), and per run its first slot.
    std::vector<shader::OcclusionDraw> occlusionDraws;
    std::vector<uint32_t> runFirstSlot;
    // The command buffers' chunks, enough for any frame of this scene (so
    // their size stays; occlusionArgsBytes).
    uint32_t argsChunks = 0;
    // The first pass to record uploads the host buffers (upload()).
    mutable std::once_flag uploaded;
};

} // namespace glint::passes
