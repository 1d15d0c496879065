#pragma once
// Pass 1 of the reflection pipeline: the G-buffer. Raster on the graphics
// queue of every instance of a scene::Scene (mesh LOD 0) whose bounds meet
// the view frustum (GBufferSettings::frustumCulling) and are not hidden
// behind what is drawn (GBufferSettings::occlusionCulling: two raster
// passes around a GPU cull, passes/gbuffer_occlusion.cpp), less their
// blended geometries (glTF alphaMode BLEND: the transparent pass
// draws those, passes/transparent.h), into reversed-Z depth, world normal, albedo, roughness/metallic,
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
// Lighting: the sun, shadowed by a shadow map, plus diffuse light from the
// procedural sky, with glint/brdf.glsl as the ray-traced hits light (their
// sun visibility comes from this shadow map where it covers them, else
// from a shadow ray, so a surface seen directly, in SSLR and in an RT
// reflection is shadowed alike; GBufferOutputs::shadow is the map's fit).
// The shadow map is a pass of its own ("shadow_map", graphics queue, before "gbuffer"): an
// orthographic depth-only raster along the sun's rays of every instance's
// LOD 0 that meets the map's box (blended geometry casts no shadow), the G-buffer's own vertex buffer and skinning, fitted to the
// camera's view up to a distance or to the whole scene where that is
// smaller, on a world-fixed texel grid so it does not shimmer as the camera
// moves. It needs no BVH, so every mode and device gets the same shadows.
// Material textures are sampled per pixel: base colour (an sRGB image),
// metallic-roughness (G roughness, B metallic), normal maps (tangent
// space, glTF's TANGENT or generated tangents, normalTexture.scale) and the
// emissive texture (sRGB; uploaded only for materials that emit), each
// uploaded once with its mips and read through the texture coordinate set
// and KHR_texture_transform its reference names, times the factors (and
// COLOR_0) the vertices carry. The rest of the material (reflectance, and
// every texture when it is not 8-bit) is evaluated at the vertices on the
// CPU (scene::surfaceAtVertex). Emission (factor x strength x texel, times
// LightingSettings::emissiveScale) is added to the lit colour unlit and
// unshadowed; the RT hits add their geometry's mean emission
// (passes/bvh_update.h). The packed primitives of the RT hits keep
// sampling every texture at their vertices, and keep the vertex normal. Instances of meshes with
// morph targets draw from a per-frame copy of their vertices with their
// morph weights applied on the CPU (scene::morphedGeometry), with last
// frame's copy beside it when the weights changed, so their motion vectors
// cover the morph as well as transforms and skins.

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/image_clear.h"
#include "glint/passes/lighting.h"
#include "glint/passes/retired_objects.h"
#include "glint/scene/camera.h"
#include "glint/scene/scene.h"

#include "glint/gbuffer_shared.h"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace glint::passes {

inline constexpr VkFormat kGBufferDepthFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr VkFormat kGBufferNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
// sRGB storage spends the 8 bits where dark albedo needs them.
inline constexpr VkFormat kGBufferAlbedoFormat = VK_FORMAT_R8G8B8A8_SRGB;
inline constexpr VkFormat kGBufferRoughnessMetalFormat = VK_FORMAT_R8G8B8A8_UNORM;
inline constexpr VkFormat kGBufferMotionFormat = VK_FORMAT_R16G16_SFLOAT;
inline constexpr VkFormat kGBufferLitFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
// Reversed like the camera's depth; conventions in glint/gbuffer_shared.h.
inline constexpr VkFormat kGBufferShadowMapFormat = VK_FORMAT_D32_SFLOAT;

struct GBufferInputs {
    // This and last frame's matrices; its resolution is the G-buffer's size.
    scene::Camera camera;
    // The sun and the environment the sky pixels and the ambient light use
    // (EnvironmentMap::lighting, passes/environment.h); none:
    // sceneLighting(scene, settings.lighting), the procedural path.
    std::optional<shader::SceneLighting> lighting;
    // The prefiltered environment (importEnvironment); needed when
    // `lighting` says an image is looked up, else left invalid.
    rg::Texture environment;
};

// The sun's shadow map. Biases are in shadow texels (the world size of one
// texel of this frame's fit), so they keep working when the resolution,
// the distance or the scene's size change the texel. The defaults keep the
// tests' floor free of acne under a 10- and a 45-degree sun
// (tests/gpu/gbuffer_test.cpp) with the smallest bias the filter's reach
// asks for (see slopeBias).
struct SunShadowSettings {
    // Off: the sun is unshadowed (the map shrinks to one cleared texel).
    bool enabled = true;
    // Texels per side of the square map. 2048 gives about 6 cm texels over
    // the default 60 m view on a 60-degree 3:2 lens (the view's bounding
    // sphere is 125 m across).
    uint32_t resolution = 2048;
    // The map covers the camera's view up to this distance (or the whole
    // scene where that is smaller); shadows fade out over the last tenth.
    // 60 m reaches the buildings around the plaza from its camera path.
    float maxDistance = 60.0f;
    // Constant receiver bias along the sun's rays: float rounding and
    // curved surfaces between texel centres.
    float constantBias = 0.5f;
    // Times tan(angle between normal and sun): the filter compares texels up
    // to two away, across which a tilted surface's own depth changes by
    // tan(angle) each.
    float slopeBias = 2.0f;
    // Along the normal, times sin(that angle): the surface moves off itself
    // rather than only deeper, which removes acne at grazing sun with less
    // detachment than depth bias alone.
    float normalOffset = 1.0f;
    // The tangent's clamp: 10 is 84 degrees from the normal, beyond which
    // the sun's cosine is below 0.1 and more bias would only detach shadows.
    float maxSlope = 10.0f;
};

struct GBufferSettings {
    // The sun's and the sky's scale (passes/lighting.h); the hit shaders of
    // the reflections must light with the same values.
    LightingSettings lighting;
    // Fill uncovered pixels with the sky's radiance in the lit colour; off,
    // they keep the clear value (zero).
    bool drawSky = true;
    // The sun's shadows in the lit colour.
    SunShadowSettings shadow;
    // Draw only the instances whose world bounds meet the camera's frustum
    // (the G-buffer) or the shadow map's box (the shadow map), tested on
    // the CPU per instance. Off: every instance is drawn in both (the
    // image is the same; only the raster work differs).
    bool frustumCulling = true;
    // Occlusion culling on the GPU, in two phases (glint/occlusion_shared.h):
    // the instances visible last frame are drawn first ("gbuffer"), a depth
    // pyramid of them is built ("gbuffer.hiz"), every instance in the
    // frustum is tested against it ("gbuffer.cull_late") and those newly
    // visible are drawn over ("gbuffer.late"). An instance is skipped only
    // where its bounds lie wholly behind what is drawn, so the image is the
    // same as without; only the raster work differs. It tests what the
    // frustum test leaves (every instance with frustumCulling off), and
    // runs only where that is two instances or more (one cannot hide
    // behind itself); the shadow map is not occlusion culled.
    bool occlusionCulling = true;
    // Skip the groups of an instance's triangles that all face away from
    // the camera (scene/facets.h: large single-sided geometry whose
    // triangles face a few ways, such as walls), tested on the CPU per
    // instance and geometry: the rasterizer would cull each of their
    // triangles, after fetching and transforming its vertices. The image is
    // the same; only the raster work differs. The shadow map draws both
    // faces, so it keeps every triangle.
    bool facetCulling = true;
};

struct GBufferOutputs {
    rg::Texture depth;           // kGBufferDepthFormat
    rg::Texture normal;          // kGBufferNormalFormat
    rg::Texture albedo;          // kGBufferAlbedoFormat
    rg::Texture roughnessMetal;  // kGBufferRoughnessMetalFormat
    rg::Texture motion;          // kGBufferMotionFormat
    rg::Texture lit;             // kGBufferLitFormat
    // kGBufferShadowMapFormat, shadowResolution texels square (1 with
    // shadows off), written by the "shadow_map" pass; for debug views.
    rg::Texture shadowMap;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t shadowResolution = 0;
    // This frame's shadow map fit (enabled = 0 with shadows off): what a
    // later pass that reads shadowMap needs to look it up.
    shader::GBufferShadow shadow{};
    // The sun and the environment the lit colour was lit with (SSLR
    // re-lights its hits with them).
    shader::SceneLighting lighting{};
    // With occlusion culling, the frame's counts (shader::kOcclusionStat*,
    // u32 words, glint/occlusion_shared.h), final after "gbuffer.cull_late";
    // else invalid.
    rg::Buffer occlusionStats;
};

struct GBufferStats {
    uint64_t frame = 0;           // addGBufferPass calls so far
    // this frame: the draws recorded (those of the instances in the
    // frustum; with occlusion culling each is a command slot, in both
    // phases, that the cull keeps or drops: see occlusionStats)
    uint32_t draws = 0;
    // this frame: the runs they were recorded in (draws binding the same
    // pipeline, material, textures, vertices and winding: one multi-draw
    // each with occlusion culling, one push of constants without)
    uint32_t runs = 0;
    uint64_t triangles = 0;       // this frame
    // this frame: of the instances in the frustum, triangles not drawn
    // because their facet faced away (facetCulling)
    uint64_t facetTrianglesSkipped = 0;
    uint32_t shadowDraws = 0;     // this frame, into the shadow map
    uint32_t instancesCulled = 0;        // this frame: outside the camera's frustum, not drawn
    uint32_t shadowInstancesCulled = 0;  // this frame: outside the shadow map's box, not drawn into it
    // This frame's shadow map fit (enabled = 0 with shadows off).
    shader::GBufferShadow shadow{};
    uint64_t geometryBytes = 0;   // the uploaded vertex and index buffers
    uint32_t textureImages = 0;   // material textures uploaded (one per texture and colour space)
    uint64_t textureBytes = 0;    // their bytes, mips included
    uint32_t normalMaps = 0;      // of them, normal textures
    uint32_t facetedGeometries = 0;  // geometries stored by facing (DrawRange::facets)
    uint32_t normalMappedDraws = 0;  // this frame
    uint32_t texturedDraws = 0;   // this frame: draws sampling any material texture
    uint32_t maskedDraws = 0;     // this frame: alpha-tested draws (glTF alphaMode MASK)
    uint32_t transparentDraws = 0;  // this frame: blended draws (glTF alphaMode BLEND; passes/transparent.h)
};

struct TransparentInputs;
struct TransparentOutputs;

// Owns the scene's GPU geometry (every mesh's LOD 0, uploaded into one
// vertex and one index buffer, again only when the scene's assets change)
// and the per-frame host-visible buffers (frame constants, instance
// transforms of this and last frame, joint palettes), one set per frame in
// flight.
class GBufferRenderer {
public:
    // `scene` must outlive the renderer. Its instances, joint palettes, sun
    // and sky may change between frames; edited meshes, materials and
    // textures (scene::Scene::assetRevision) are uploaded again before the
    // next frame (the old ones are released once no frame in flight reads
    // them).
    // `framesInFlight` must be at least the executor's.
    GBufferRenderer(gpu::Context& ctx, const scene::Scene& scene, uint32_t framesInFlight = 2);
    ~GBufferRenderer();
    GBufferRenderer(const GBufferRenderer&) = delete;
    GBufferRenderer& operator=(const GBufferRenderer&) = delete;

    const GBufferStats& stats() const { return stats_; }

private:
    friend GBufferOutputs addGBufferPass(rg::Graph&, GBufferRenderer&, const GBufferInputs&, const GBufferSettings&);
    friend TransparentOutputs addTransparentPass(rg::Graph&, GBufferRenderer&, const TransparentInputs&);
    struct DrawRange;
    struct SurfaceDraw;
    struct FrameSlot;
    struct FrameWork;
    struct TransparentDraw;
    static constexpr size_t kMaterialTextureSlots = 4;  // normal, base colour, metal-rough, emissive
    using MaterialTextures = std::array<std::pair<const gpu::Image*, const gpu::Sampler*>, kMaterialTextureSlots>;

    std::shared_ptr<FrameWork> prepare(const GBufferInputs& inputs, const GBufferSettings& settings);
    // Uploads the scene's meshes (LOD 0) and material textures and makes
    // their draw ranges.
    void loadAssets();
    // Loads them again when the scene's assets changed (scene::assetStamp);
    // releases what earlier reloads retired once no frame reads it.
    void reloadAssetsIfEdited();
    // Writes the frame's host buffers; the shadow map pass, the frame's
    // first, calls it.
    void upload(const FrameWork& work);
    void recordShadowMap(const FrameWork& work, rg::PassContext& pc, rg::Texture shadowMap);
    // Which draws a G-buffer pass records: all of them, direct (no
    // occlusion culling); indirect from the early or the late cull's
    // commands. Early clears the targets, late loads them; the sky comes
    // last (Direct and Late).
    enum class SurfacePhase : uint8_t { Direct, Early, Late };
    void record(const FrameWork& work, rg::PassContext& pc, const GBufferOutputs& targets, rg::Texture environment,
                SurfacePhase phase, rg::Buffer args);
    // passes/gbuffer_occlusion.cpp: the cull's pipelines, the frame's cull
    // inputs (in prepare), and its passes around the G-buffer's.
    void createOcclusionPipelines();
    void prepareOcclusion(FrameWork& work) const;
    struct OcclusionHandles {
        rg::HistoryBuffer visibility;
        rg::Buffer earlyArgs, lateArgs, stats;
    };
    OcclusionHandles addEarlyCull(rg::Graph& graph, const std::shared_ptr<FrameWork>& work);
    rg::Buffer addLateCull(rg::Graph& graph, const std::shared_ptr<FrameWork>& work, const GBufferOutputs& early,
                           OcclusionHandles& handles);
    void uploadOnce(const FrameWork& work);
    // passes/transparent.cpp: the blended geometries of the instances `work`
    // draws, farthest first; then their draws into `layer` (cleared) over
    // the G-buffer's depth.
    std::vector<TransparentDraw> transparentDraws(const FrameWork& work) const;
    void recordTransparent(const FrameWork& work, const std::vector<TransparentDraw>& draws, rg::PassContext& pc,
                           rg::Texture layer, const GBufferOutputs& gbuf, rg::Texture environment);
    // Per slot the 1x1 fallback (a flat normal, white) and the first sampler.
    MaterialTextures fallbackTextures() const;
    // Puts the range's own textures into the slots it samples (the others
    // keep what `textures` holds); whether it samples any.
    bool rangeTextures(const DrawRange& range, MaterialTextures& textures) const;
    gpu::Pipeline createTransparentPipeline() const;  // passes/transparent.cpp
    // The bindings of the pipelines that light (gbuffer_surface.glsl).
    void pushSurfaceBindings(const gpu::Pipeline& pipeline, rg::PassContext& pc, const FrameSlot& slot,
                             const gpu::Buffer& vertices, const MaterialTextures& textures, rg::Texture shadowMap,
                             rg::Texture environment) const;
    void ensureCapacity(gpu::Buffer& buffer, VkDeviceSize bytes, const char* name);
    // Appends the morphed vertices of `inst` (its mesh's LOD 0 with its
    // morph weights applied on the CPU) to `out`; their first index, or -1
    // when the instance does not morph.
    // Appends the instance's morphed vertices (and, when its weights changed
    // since last frame, last frame's copy right after them); returns the
    // first vertex (-1: not morphing) and sets `previousDelta`.
    int64_t appendMorphed(const scene::Instance& inst, std::vector<shader::GBufferVertex>& out,
                          uint32_t& previousDelta) const;
    // The vertex buffer an instance's draws read and the shift of their
    // vertex offsets into it.
    std::pair<const gpu::Buffer*, int32_t> vertexSource(const FrameWork& work, size_t instance,
                                                        const FrameSlot& slot) const;

    gpu::Context& ctx_;
    const scene::Scene& scene_;
    uint32_t framesInFlight_;
    uint64_t frame_ = 0;
    gpu::Pipeline surfacePipeline_;
    gpu::Pipeline surfaceMaskedPipeline_;  // glTF alphaMode MASK: the alpha test (gbuffer_masked.frag)
    gpu::Pipeline skyPipeline_;
    gpu::Pipeline shadowPipeline_;
    gpu::Pipeline shadowMaskedPipeline_;   // the same test in the shadow map (shadow_masked.frag)
    // Occlusion culling (passes/gbuffer_occlusion.cpp): the depth pyramid's
    // two passes and the cull's two phases.
    gpu::Pipeline hizBasePipeline_;
    gpu::Pipeline hizDownPipeline_;
    gpu::Pipeline cullEarlyPipeline_;
    gpu::Pipeline cullLatePipeline_;
    // glTF alphaMode BLEND, forward-lit and blended (transparent.frag);
    // created with the first blended geometry.
    gpu::Pipeline transparentPipeline_;
    // Clears the transparent layer (passes/image_clear.h says why not a
    // load-op clear); made by the first addTransparentPass that draws.
    std::unique_ptr<ImageClearer> transparentClearer_;
    bool hasBlended_ = false;
    gpu::Sampler nearest_;  // completes the shadow map's descriptor; reads are texelFetch
    gpu::Sampler environmentSampler_;
    // Material textures: one image per scene texture and colour space some
    // drawn geometry's material samples (base colour and emissive sRGB;
    // metallic-roughness and normal UNORM), 1x1 fallbacks bound to draws
    // without (a flat normal, white), and one sampler per glTF wrap-mode pair.
    std::vector<gpu::Image> textureImages_;
    gpu::Image flatNormal_;
    gpu::Image white_;
    std::vector<gpu::Sampler> textureSamplers_;
    gpu::Buffer vertices_;  // GBufferVertex, every geometry of every mesh's LOD 0
    gpu::Buffer indices_;
    std::vector<std::vector<DrawRange>> meshDraws_;  // per mesh: its LOD-0 geometries
    uint32_t rangeStates_ = 0;  // distinct DrawRange::state values
    std::vector<int32_t> meshFirstVertex_;           // per mesh: its first vertex in vertices_
    // Per mesh with morph targets: its vertices as uploaded (else empty).
    std::vector<std::vector<shader::GBufferVertex>> morphBaseVertices_;
    scene::AssetStamp assets_;  // of the scene the above were made from
    RetiredObjects retired_;    // what a reload replaced, until no frame in flight reads it
    std::vector<std::unique_ptr<FrameSlot>> slots_;
    // The frame addGBufferPass declared last (the transparent pass draws it).
    std::shared_ptr<FrameWork> current_;
    GBufferStats stats_;
};

// The shadow map's fit for `camera` (glint/gbuffer_shared.h's GBufferShadow):
// an orthographic view along the sun's rays whose depth range holds every
// instance's world bounds (so casters outside the view still cast), whose
// square covers the bounding sphere of the camera's view up to
// settings.maxDistance, or the scene's bounds seen from the sun where those
// are smaller, centred on whole texels. enabled = 0 with shadows off or
// nothing to cast.
shader::GBufferShadow fitSunShadow(const scene::Scene& scene, const scene::Camera& camera,
                                   const SunShadowSettings& settings);

// Declares the shadow map and G-buffer passes (see the top of this file).
// Frames are declared and run one at a time, once each: the renderer's
// per-frame host buffers count frames by these calls.
GBufferOutputs addGBufferPass(rg::Graph& graph, GBufferRenderer& renderer, const GBufferInputs& inputs,
                              const GBufferSettings& settings = {});

} // namespace glint::passes
