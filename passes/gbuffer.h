#pragma once
// Pass 1 of the reflection pipeline (issue 5): the G-buffer. One raster
// pass on the graphics queue draws every instance of a scene::Scene (mesh
// LOD 0) into reversed-Z depth, world normal, albedo, roughness/metallic,
// motion (camera, rigid and skinned motion) and the lit colour of the
// opaque scene that SSLR samples; a sky triangle fills what no geometry
// covers. Output conventions: glint/gbuffer_shared.h.
//
//   passes::GBufferRenderer renderer(ctx, scene);
//   each frame (after scene::advanceScene and camera.advance):
//     rg::Graph graph(executor.queueCaps());
//     const auto gbuf = passes::addGBufferPass(graph, renderer, {camera}, {});
//     ... passes reading gbuf.depth, gbuf.lit, ... ...
//     executor.run(graph.compile(executor.compileOptions()));
//
// Lighting in this step: the sun without shadows (the shadow ray arrives
// with the ray-traced hit pass, which shares glint/brdf.glsl) plus diffuse
// light from the procedural sky. Materials are sampled at the vertices on
// the CPU (scene::surfaceAtVertex, as the BVH's packed primitives are), so
// textures contribute at vertex rate and normal maps not at all.

#include "gpu/context.h"
#include "gpu/pipeline.h"
#include "gpu/resources.h"
#include "graph/graph.h"
#include "passes/lighting.h"
#include "scene/camera.h"
#include "scene/scene.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace glint::passes {

inline constexpr VkFormat kGBufferDepthFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr VkFormat kGBufferNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
// sRGB storage spends the 8 bits where dark albedo needs them.
inline constexpr VkFormat kGBufferAlbedoFormat = VK_FORMAT_R8G8B8A8_SRGB;
inline constexpr VkFormat kGBufferRoughnessMetalFormat = VK_FORMAT_R8G8B8A8_UNORM;
inline constexpr VkFormat kGBufferMotionFormat = VK_FORMAT_R16G16_SFLOAT;
inline constexpr VkFormat kGBufferLitFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

struct GBufferInputs {
    // This and last frame's matrices; its resolution is the G-buffer's size.
    scene::Camera camera;
};

struct GBufferSettings {
    // The sun's and the sky's scale (passes/lighting.h); the hit shaders of
    // the reflections must light with the same values.
    LightingSettings lighting;
    // Fill uncovered pixels with the sky's radiance in the lit colour; off,
    // they keep the clear value (zero).
    bool drawSky = true;
};

struct GBufferOutputs {
    rg::Texture depth;           // kGBufferDepthFormat
    rg::Texture normal;          // kGBufferNormalFormat
    rg::Texture albedo;          // kGBufferAlbedoFormat
    rg::Texture roughnessMetal;  // kGBufferRoughnessMetalFormat
    rg::Texture motion;          // kGBufferMotionFormat
    rg::Texture lit;             // kGBufferLitFormat
    uint32_t width = 0;
    uint32_t height = 0;
};

struct GBufferStats {
    uint64_t frame = 0;           // addGBufferPass calls so far
    uint32_t draws = 0;           // this frame: vkCmdDrawIndexed calls
    uint64_t triangles = 0;       // this frame
    uint64_t geometryBytes = 0;   // the uploaded vertex and index buffers
};

// Owns the scene's GPU geometry (every mesh's LOD 0, uploaded once into one
// vertex and one index buffer) and the per-frame host-visible buffers
// (frame constants, instance transforms of this and last frame, joint
// palettes), one set per frame in flight.
class GBufferRenderer {
public:
    // `scene` must outlive the renderer; its meshes and materials must not
    // change, its instances, joint palettes, sun and sky may.
    // `framesInFlight` must be at least the executor's.
    GBufferRenderer(gpu::Context& ctx, const scene::Scene& scene, uint32_t framesInFlight = 2);
    ~GBufferRenderer();
    GBufferRenderer(const GBufferRenderer&) = delete;
    GBufferRenderer& operator=(const GBufferRenderer&) = delete;

    const GBufferStats& stats() const { return stats_; }

private:
    friend GBufferOutputs addGBufferPass(rg::Graph&, GBufferRenderer&, const GBufferInputs&, const GBufferSettings&);
    struct DrawRange;
    struct FrameSlot;
    struct FrameWork;

    std::shared_ptr<FrameWork> prepare(const GBufferInputs& inputs, const GBufferSettings& settings);
    void record(const FrameWork& work, rg::PassContext& pc, const GBufferOutputs& targets);
    void ensureCapacity(gpu::Buffer& buffer, VkDeviceSize bytes, const char* name);

    gpu::Context& ctx_;
    const scene::Scene& scene_;
    uint32_t framesInFlight_;
    uint64_t frame_ = 0;
    gpu::Pipeline surfacePipeline_;
    gpu::Pipeline skyPipeline_;
    gpu::Buffer vertices_;  // GBufferVertex, every geometry of every mesh's LOD 0
    gpu::Buffer indices_;
    std::vector<std::vector<DrawRange>> meshDraws_;  // per mesh: its LOD-0 geometries
    std::vector<std::unique_ptr<FrameSlot>> slots_;
    GBufferStats stats_;
};

// Declares the G-buffer pass (see the top of this file). Frames are declared
// and run one at a time, once each: the renderer's per-frame host buffers
// count frames by these calls.
GBufferOutputs addGBufferPass(rg::Graph& graph, GBufferRenderer& renderer, const GBufferInputs& inputs,
                              const GBufferSettings& settings = {});

} // namespace glint::passes
