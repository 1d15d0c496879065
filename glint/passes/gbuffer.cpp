#include "glint/passes/gbuffer.h"
#include "glint/passes/gbuffer_internal.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/passes/environment.h"
#include "glint/scene/animation.h"
#include "glint/scene/frustum.h"

#include "glint/gbuffer_shared.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <optional>
#include <string>

namespace glint::passes {

using namespace gbuffer_detail;

namespace {

VkSamplerAddressMode addressMode(scene::Wrap wrap) {
    switch (wrap) {
    case scene::Wrap::ClampToEdge: return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    case scene::Wrap::MirroredRepeat: return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
    case scene::Wrap::Repeat: break;
    }
    return VK_SAMPLER_ADDRESS_MODE_REPEAT;
}

// What a draw binds beyond its ranges: the pipeline (alpha-tested or not),
// the range's state (material and textures), the vertex buffer (a morphing
// instance's own copy, or the shared one) and the winding. Draws with the
// same key are one run, recorded as one multi-draw.
uint64_t runKey(bool masked, uint32_t state, bool morphed, bool mirrored) {
    return uint64_t(masked) << 33 | uint64_t(state) << 2 | uint64_t(morphed) << 1 | uint64_t(mirrored);
}

// Draws fit in the bits below a sort key's run key.
constexpr uint32_t kDrawIndexBits = 28;

// Colour attachments in the order of the fragment shaders' outputs.
constexpr std::array<VkFormat, 5> kColorFormats = {kGBufferNormalFormat, kGBufferAlbedoFormat,
                                                   kGBufferRoughnessMetalFormat, kGBufferMotionFormat,
                                                   kGBufferLitFormat};

// Host buffers grow to the next power of two, so a slowly growing scene
// reallocates O(log n) times.
VkDeviceSize grownCapacity(VkDeviceSize needed) {
    return std::bit_ceil(std::max<VkDeviceSize>(needed, 256));
}

} // namespace

GBufferRenderer::GBufferRenderer(gpu::Context& ctx, const scene::Scene& scene, uint32_t framesInFlight)
    : ctx_(ctx), scene_(scene), framesInFlight_(std::max(framesInFlight, 1u)), retired_(framesInFlight_) {
    gpu::GraphicsPipelineDesc surface;
    surface.vertexShader = "gbuffer/gbuffer.vert";
    surface.fragmentShader = "gbuffer/gbuffer.frag";
    surface.bindings = surfaceBindings();
    surface.pushConstantBytes = sizeof(shader::GBufferDraw);
    // Per draw (glTF): back faces culled for single-sided materials, none
    // for double-sided ones; front faces wind counter-clockwise on screen
    // (the projection flips Y with the framebuffer), clockwise under a
    // mirroring transform.
    surface.dynamicCulling = true;
    surface.colorFormats.assign(kColorFormats.begin(), kColorFormats.end());
    surface.depthFormat = kGBufferDepthFormat;
    surface.name = "gbuffer.surface";
    surfacePipeline_ = gpu::createGraphicsPipeline(ctx, surface);
    gpu::GraphicsPipelineDesc masked = surface;
    masked.fragmentShader = "gbuffer/gbuffer_masked.frag";
    masked.name = "gbuffer.surface_masked";
    surfaceMaskedPipeline_ = gpu::createGraphicsPipeline(ctx, masked);

    gpu::GraphicsPipelineDesc sky = surface;
    sky.vertexShader = "gbuffer/sky.vert";
    sky.fragmentShader = "gbuffer/sky.frag";
    // At depth 0 the GREATER_OR_EQUAL test passes only where the clear value
    // survived; writing would change nothing.
    sky.depthWrite = false;
    sky.dynamicCulling = false;
    sky.cullMode = VK_CULL_MODE_NONE;
    sky.name = "gbuffer.sky";
    skyPipeline_ = gpu::createGraphicsPipeline(ctx, sky);

    gpu::GraphicsPipelineDesc shadow;
    shadow.vertexShader = "gbuffer/shadow.vert";
    shadow.fragmentShader = "gbuffer/shadow.frag";
    shadow.bindings = geometryBindings();
    shadow.pushConstantBytes = sizeof(shader::GBufferDraw);
    // Open and double-sided geometry casts from both sides, as the
    // G-buffer draws it and as the shadow rays of the RT hits see it.
    shadow.cullMode = VK_CULL_MODE_NONE;
    shadow.depthFormat = kGBufferShadowMapFormat;
    shadow.name = "gbuffer.shadow_map";
    shadowPipeline_ = gpu::createGraphicsPipeline(ctx, shadow);
    // Alpha-tested casters read the base colour texture's alpha, at the
    // binding the G-buffer samples it from.
    gpu::GraphicsPipelineDesc shadowMasked = shadow;
    shadowMasked.fragmentShader = "gbuffer/shadow_masked.frag";
    shadowMasked.bindings.push_back({kFirstMaterialTextureBinding + kBaseColorSlot,
                                     VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_SHADER_STAGE_FRAGMENT_BIT});
    shadowMasked.name = "gbuffer.shadow_map_masked";
    shadowMaskedPipeline_ = gpu::createGraphicsPipeline(ctx, shadowMasked);

    nearest_ = gpu::Sampler(ctx, {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST,
                                  VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 0.0f, "gbuffer.nearest"});
    environmentSampler_ = createEnvironmentSampler(ctx, "gbuffer.environment");

    for (size_t wrapS = 0; wrapS < kWrapModes; ++wrapS) {
        for (size_t wrapT = 0; wrapT < kWrapModes; ++wrapT) {
            gpu::SamplerDesc desc{VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR,
                                  addressMode(scene::Wrap(wrapS)), VK_LOD_CLAMP_NONE, "gbuffer.material_texture"};
            desc.addressV = addressMode(scene::Wrap(wrapT));
            textureSamplers_.emplace_back(ctx, desc);
        }
    }
    // Bound where a draw has no texture in a slot, so every binding is
    // valid: (0.5, 0.5, 1) is the unperturbed normal; white leaves the
    // factors as they are.
    const std::array<uint8_t, 4> flat = {128, 128, 255, 255};
    const std::array<uint8_t, 4> white = {255, 255, 255, 255};
    flatNormal_ = gpu::createSampledImageWithMips(
        ctx, {.width = 1, .height = 1, .format = VK_FORMAT_R8G8B8A8_UNORM, .name = "gbuffer.flat_normal"}, flat.data());
    white_ = gpu::createSampledImageWithMips(
        ctx, {.width = 1, .height = 1, .format = VK_FORMAT_R8G8B8A8_UNORM, .name = "gbuffer.white"}, white.data());

    createOcclusionPipelines();
    loadAssets();
    for (uint32_t i = 0; i < framesInFlight_; ++i) {
        slots_.push_back(std::make_unique<FrameSlot>());
    }
}

GBufferRenderer::~GBufferRenderer() {
    // Frames in flight may still read the geometry and the slots' buffers.
    ctx_.waitIdleForTeardown("G-buffer renderer");
}

void GBufferRenderer::ensureCapacity(gpu::Buffer& buffer, VkDeviceSize bytes, const char* name) {
    if (buffer && buffer.size() >= bytes) return;
    buffer = gpu::Buffer(ctx_, {grownCapacity(bytes), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Upload, name});
}

std::shared_ptr<GBufferRenderer::FrameWork> GBufferRenderer::prepare(const GBufferInputs& inputs,
                                                                     const GBufferSettings& settings) {
    ++frame_;
    reloadAssetsIfEdited();
    auto work = std::make_shared<FrameWork>();
    work->slot = uint32_t(frame_ % framesInFlight_);
    stats_.frame = frame_;
    work->drawSky = settings.drawSky;

    const scene::Camera& camera = inputs.camera;
    shader::GBufferFrame& f = work->frame;
    f.jitteredViewProjection = camera.jitteredProjection * camera.view;
    f.viewProjection = camera.viewProjection();
    f.previousViewProjection = camera.previousViewProjection();
    f.inverseViewProjection = glm::inverse(f.viewProjection);
    f.cameraPosition = glm::vec4(camera.position, 1.0f);
    f.size = glm::vec2(camera.resolution);

    f.lighting = inputs.lighting ? *inputs.lighting : sceneLighting(scene_, settings.lighting);
    f.shadow = fitSunShadow(scene_, camera, settings.shadow);
    stats_.shadow = f.shadow;

    work->instances.reserve(scene_.instances.size());
    const scene::Frustum view(f.jitteredViewProjection);
    const scene::Frustum sun(f.shadow.viewProjection);
    stats_.instancesCulled = 0;
    stats_.shadowInstancesCulled = 0;
    for (const scene::Instance& inst : scene_.instances) {
        // Culled instances keep their slot (the shaders index instances by
        // scene order), they only get no draws.
        bool drawn = true, casts = f.shadow.enabled != 0;
        // The frustum test and the occlusion cull share one bounds per
        // instance (skinned ones span their whole palette).
        if (settings.frustumCulling || settings.occlusionCulling) {
            work->bounds.push_back(scene::instanceBounds(scene_, inst));
        }
        if (settings.frustumCulling) {
            const scene::Aabb& bounds = work->bounds.back();
            drawn = view.intersects(bounds);
            casts = casts && sun.intersects(bounds);
            stats_.instancesCulled += drawn ? 0u : 1u;
            stats_.shadowInstancesCulled += casts || f.shadow.enabled == 0 ? 0u : 1u;
        }
        work->visible.push_back(drawn ? 1 : 0);
        work->castsShadow.push_back(casts ? 1 : 0);
        work->mirrored.push_back(glm::determinant(glm::mat3(inst.transform)) < 0.0f ? 1 : 0);
        shader::GBufferInstance gi{};
        gi.transform = inst.transform;
        gi.previousTransform = inst.previousTransform;
        if (inst.motion == scene::Motion::Skinned && inst.skin != scene::kNone) {
            gi.jointOffset = inst.jointOffset;
            gi.jointCount = uint32_t(scene_.skins.at(size_t(inst.skin)).joints.size());
        }
        work->morphedFirstVertex.push_back(appendMorphed(inst, work->morphedVertices, gi.previousVertexDelta));
        work->instances.push_back(gi);
        work->meshes.push_back(inst.mesh);
    }
    // The draws: opaque and alpha-tested geometry (blended geometry is the
    // transparent pass's); those of instances outside the frustum count
    // towards the capacity only. A geometry stored by facing draws only its
    // facets that do not wholly face away, consecutive ones as one draw.
    std::vector<SurfaceDraw> draws;
    stats_.facetTrianglesSkipped = 0;
    for (size_t i = 0; i < work->instances.size(); ++i) {
        const bool morphed = work->morphedFirstVertex[i] >= 0;
        std::optional<glm::vec3> eye;  // the camera in the mesh's space, once a facet asks
        for (const DrawRange& range : meshDraws_.at(work->meshes[i])) {
            if (range.indexCount == 0 || range.coverage == Coverage::Blended) continue;
            // Kept facets between skipped ones: at most every other one.
            work->drawCapacity += std::max(1u, uint32_t(range.facets.size() + 1) / 2);
            if (!work->visible[i]) continue;
            const bool masked = range.coverage == Coverage::Masked;
            const uint64_t run = runKey(masked, range.state, morphed, work->mirrored[i] != 0);
            const auto draw = [&](uint32_t firstIndex, uint32_t indexCount) {
                draws.push_back({uint32_t(i), &range, firstIndex, indexCount, masked, run});
            };
            if (range.facets.empty() || morphed || !settings.facetCulling) {
                draw(range.firstIndex, range.indexCount);
                continue;
            }
            if (!eye) {
                // Affine: a singular one gives a non-finite eye, which hides
                // nothing (scene::facetHidden).
                const glm::mat4& transform = work->instances[i].transform;
                eye = glm::inverse(glm::mat3(transform)) * (camera.position - glm::vec3(transform[3]));
            }
            uint32_t first = 0, count = 0;  // the kept facets since the last skipped one
            for (const scene::Facet& facet : range.facets) {
                if (scene::facetHidden(facet, *eye)) {
                    stats_.facetTrianglesSkipped += facet.indexCount / 3;
                    if (count != 0) draw(first, count);
                    count = 0;
                    continue;
                }
                if (count == 0) first = facet.firstIndex;
                count += facet.indexCount;
            }
            if (count != 0) draw(first, count);
        }
    }
    // In the order record() issues them: by run key (opaque before
    // alpha-tested), then as found.
    if (draws.size() >= (size_t(1) << kDrawIndexBits)) {
        throw gpu::GpuError("G-buffer: " + std::to_string(draws.size()) + " draws in view; at most " +
                            std::to_string((size_t(1) << kDrawIndexBits) - 1) + " are supported");
    }
    std::vector<uint64_t> order(draws.size());
    for (size_t d = 0; d < draws.size(); ++d) order[d] = draws[d].run << kDrawIndexBits | d;
    std::sort(order.begin(), order.end());
    work->draws.reserve(draws.size());
    for (const uint64_t o : order) work->draws.push_back(draws[o & ((uint64_t(1) << kDrawIndexBits) - 1)]);
    // One instance in view cannot be hidden by another: then the cull's
    // passes would cost and skip nothing (a single glTF model).
    const bool severalInstances =
        std::any_of(work->draws.begin(), work->draws.end(),
                    [&](const SurfaceDraw& d) { return d.instance != work->draws.front().instance; });
    work->occlusionCulling = settings.occlusionCulling && severalInstances;
    if (work->occlusionCulling) prepareOcclusion(*work);
    work->joints = scene_.jointMatrices;
    work->previousJoints = scene_.previousJointMatrices;
    // Before the first advanceScene the previous palette may be missing:
    // then last frame looked like this one.
    if (work->previousJoints.size() != work->joints.size()) work->previousJoints = work->joints;
    return work;
}

int64_t GBufferRenderer::appendMorphed(const scene::Instance& inst, std::vector<shader::GBufferVertex>& out,
                                       uint32_t& previousDelta) const {
    previousDelta = 0;
    if (inst.mesh >= scene_.meshes.size() || inst.morphWeights.empty() || morphBaseVertices_[inst.mesh].empty()) {
        return -1;
    }
    const int64_t first = int64_t(out.size());
    const std::vector<shader::GBufferVertex>& base = morphBaseVertices_[inst.mesh];
    const auto append = [&](const std::vector<float>& weights) {
        size_t v = 0;
        for (const scene::Geometry& g : scene_.meshes[inst.mesh].lods[0].geometries) {
            const scene::Geometry morphed = scene::morphedGeometry(g, weights);
            for (uint32_t k = 0; k < morphed.vertexCount(); ++k, ++v) {
                shader::GBufferVertex vertex = base.at(v);
                vertex.position = morphed.positions[k];
                if (k < morphed.normals.size()) vertex.normal = morphed.normals[k];
                if (k < morphed.tangents.size()) vertex.tangent = morphed.tangents[k];
                out.push_back(vertex);
            }
        }
    };
    append(inst.morphWeights);
    // Motion vectors of the morph itself: last frame's shape follows this
    // one's (only positions are read from it).
    if (inst.previousMorphWeights.size() == inst.morphWeights.size() &&
        inst.previousMorphWeights != inst.morphWeights) {
        previousDelta = uint32_t(int64_t(out.size()) - first);
        append(inst.previousMorphWeights);
    }
    return first;
}

void GBufferRenderer::uploadOnce(const FrameWork& work) {
    // Whichever of the frame's passes records first (the shadow map, or
    // the occlusion cull's early phase, which share no resource) fills the
    // buffers they all read.
    std::call_once(work.uploaded, [&] { upload(work); });
}

void GBufferRenderer::upload(const FrameWork& work) {
    FrameSlot& slot = *slots_[work.slot];
    ensureCapacity(slot.morphedVertices,
                   std::max<size_t>(work.morphedVertices.size(), 1) * sizeof(shader::GBufferVertex),
                   "gbuffer.morphed_vertices");
    if (!work.morphedVertices.empty()) {
        std::memcpy(slot.morphedVertices.mapped(), work.morphedVertices.data(),
                    work.morphedVertices.size() * sizeof(shader::GBufferVertex));
    }

    // Host writes before the submit are visible to the device without a
    // barrier; this slot's previous frame has finished.
    ensureCapacity(slot.frame, sizeof(shader::GBufferFrame), "gbuffer.frame");
    ensureCapacity(slot.instances, std::max<size_t>(work.instances.size(), 1) * sizeof(shader::GBufferInstance),
                   "gbuffer.instances");
    ensureCapacity(slot.joints, std::max<size_t>(work.joints.size(), 1) * sizeof(glm::mat4), "gbuffer.joints");
    ensureCapacity(slot.previousJoints, std::max<size_t>(work.previousJoints.size(), 1) * sizeof(glm::mat4),
                   "gbuffer.previous_joints");
    std::memcpy(slot.frame.mapped(), &work.frame, sizeof(work.frame));
    if (!work.instances.empty()) {
        std::memcpy(slot.instances.mapped(), work.instances.data(),
                    work.instances.size() * sizeof(shader::GBufferInstance));
    }
    if (!work.joints.empty()) {
        std::memcpy(slot.joints.mapped(), work.joints.data(), work.joints.size() * sizeof(glm::mat4));
        std::memcpy(slot.previousJoints.mapped(), work.previousJoints.data(),
                    work.previousJoints.size() * sizeof(glm::mat4));
    }
    if (work.occlusionCulling) {
        ensureCapacity(slot.occlusionInstances,
                       std::max<size_t>(work.occlusionInstances.size(), 1) * sizeof(shader::OcclusionInstance),
                       "gbuffer.occlusion_instances");
        ensureCapacity(slot.occlusionDraws,
                       std::max<size_t>(work.occlusionDraws.size(), 1) * sizeof(shader::OcclusionDraw),
                       "gbuffer.occlusion_draws");
        if (!work.occlusionInstances.empty()) {
            std::memcpy(slot.occlusionInstances.mapped(), work.occlusionInstances.data(),
                        work.occlusionInstances.size() * sizeof(shader::OcclusionInstance));
        }
        if (!work.occlusionDraws.empty()) {
            std::memcpy(slot.occlusionDraws.mapped(), work.occlusionDraws.data(),
                        work.occlusionDraws.size() * sizeof(shader::OcclusionDraw));
        }
    }
}

std::pair<const gpu::Buffer*, int32_t> GBufferRenderer::vertexSource(const FrameWork& work, size_t instance,
                                                                     const FrameSlot& slot) const {
    const int64_t first = work.morphedFirstVertex[instance];
    if (first < 0) return {&vertices_, 0};
    // The morphed copy lies at `first`; the draw ranges index the shared buffer.
    return {&slot.morphedVertices, int32_t(first) - meshFirstVertex_[work.meshes[instance]]};
}

GBufferRenderer::MaterialTextures GBufferRenderer::fallbackTextures() const {
    return {std::pair{&flatNormal_, &textureSamplers_[0]}, std::pair{&white_, &textureSamplers_[0]},
            std::pair{&white_, &textureSamplers_[0]}, std::pair{&white_, &textureSamplers_[0]}};
}

bool GBufferRenderer::rangeTextures(const DrawRange& range, MaterialTextures& textures) const {
    bool textured = false;
    for (size_t t = 0; t < kMaterialSlots; ++t) {
        if (range.image[t] == kNoImage) continue;
        textures[t] = {&textureImages_[range.image[t]], &textureSamplers_[range.sampler[t]]};
        textured = true;
    }
    return textured;
}

void GBufferRenderer::pushSurfaceBindings(const gpu::Pipeline& pipeline, rg::PassContext& pc, const FrameSlot& slot,
                                          const gpu::Buffer& vertices, const MaterialTextures& textures,
                                          rg::Texture shadowMap, rg::Texture environment) const {
    gpu::PushDescriptors push(pipeline);
    push.storageBuffer(0, slot.frame)
        .storageBuffer(1, slot.instances)
        .storageBuffer(2, vertices)
        .storageBuffer(3, slot.joints)
        .storageBuffer(4, slot.previousJoints)
        .sampledImage(kShadowMapBinding, pc.view(shadowMap), nearest_.handle(), pc.layout(shadowMap));
    for (uint32_t t = 0; t < kMaterialSlots; ++t) {
        push.sampledImage(kFirstMaterialTextureBinding + t, textures[t].first->view(), textures[t].second->handle());
    }
    // The procedural sky reads no texture: the shadow map, which the
    // passes read anyway, fills the environment's binding.
    if (environment.valid()) {
        push.sampledImage(kEnvironmentBinding, pc.view(environment), environmentSampler_.handle(),
                          pc.layout(environment));
    } else {
        push.sampledImage(kEnvironmentBinding, pc.view(shadowMap), nearest_.handle(), pc.layout(shadowMap));
    }
    push.push(ctx_, pc.cmd());
}

void GBufferRenderer::record(const FrameWork& work, rg::PassContext& pc, const GBufferOutputs& targets,
                             rg::Texture environment, SurfacePhase phase, rg::Buffer args) {
    uploadOnce(work);
    const VkCommandBuffer cmd = pc.cmd();
    FrameSlot& slot = *slots_[work.slot];

    // Load-op clears: depth 0 is the reversed-Z far plane; zero normal w and
    // albedo mark "no surface" for the passes that read them. The late
    // phase draws over what the early one left.
    const VkAttachmentLoadOp load = phase == SurfacePhase::Late ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR;
    const std::array<rg::Texture, 5> colorTargets = {targets.normal, targets.albedo, targets.roughnessMetal,
                                                     targets.motion, targets.lit};
    std::array<VkRenderingAttachmentInfo, 5> colors{};
    for (size_t i = 0; i < colors.size(); ++i) {
        VkRenderingAttachmentInfo& a = colors[i];
        a.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        a.imageView = pc.view(colorTargets[i]);
        a.imageLayout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL;
        a.loadOp = load;
        a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        a.clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
    }
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = pc.view(targets.depth);
    depth.imageLayout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL;
    depth.loadOp = load;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = {0.0f, 0};

    VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
    rendering.renderArea = {{0, 0}, {targets.width, targets.height}};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = uint32_t(colors.size());
    rendering.pColorAttachments = colors.data();
    rendering.pDepthAttachment = &depth;
    vkCmdBeginRendering(cmd, &rendering);

    // Positive height: the projection already flips Y for Vulkan.
    const VkViewport viewport{0.0f, 0.0f, float(targets.width), float(targets.height), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, {targets.width, targets.height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);

    const MaterialTextures fallbacks = fallbackTextures();
    // Pushed again only when a draw's vertex buffer (a morphing instance's
    // own) or one of its material textures differs from the last draw's.
    const auto pushBindings = [&](const gpu::Pipeline& pipeline, const gpu::Buffer& vertices,
                                  const MaterialTextures& textures) {
        pushSurfaceBindings(pipeline, pc, slot, vertices, textures, targets.shadowMap, environment);
    };

    // Counted once a frame, by the pass that records every draw first.
    const bool counts = phase != SurfacePhase::Late;
    if (counts) {
        stats_.draws = 0;
        stats_.runs = 0;
        stats_.triangles = 0;
        stats_.normalMappedDraws = 0;
        stats_.texturedDraws = 0;
        stats_.maskedDraws = 0;
    }
    const VkBuffer indirect = phase == SurfacePhase::Direct ? VK_NULL_HANDLE : pc.buffer(args).handle();
    vkCmdBindIndexBuffer(cmd, indices_.handle(), 0, VK_INDEX_TYPE_UINT32);
    Facing facing;
    // Opaque draws first, then the alpha-tested ones with their own
    // pipeline: the discard costs early depth testing only where it exists,
    // and the opaque depth already rejects what the cutouts hide behind.
    const gpu::Pipeline* bound = nullptr;
    const gpu::Buffer* boundVertices = nullptr;
    MaterialTextures boundTextures = fallbacks;
    const uint64_t countsOffset = occlusionCountsOffset(work.argsChunks);
    constexpr uint32_t chunk = shader::kOcclusionGroupSize;
    constexpr uint32_t stride = sizeof(VkDrawIndexedIndirectCommand);
    size_t run = 0;
    for (size_t begin = 0; begin < work.draws.size(); ++run) {
        // One run: the draws that bind what its first one binds.
        const SurfaceDraw& first = work.draws[begin];
        size_t end = begin + 1;
        while (end < work.draws.size() && work.draws[end].run == first.run) ++end;
        const DrawRange& range = *first.range;
        const gpu::Pipeline& pipeline = first.masked ? surfaceMaskedPipeline_ : surfacePipeline_;
        if (&pipeline != bound) {
            bound = &pipeline;
            pipeline.bind(cmd);
            facing.bind(cmd);
            boundVertices = &vertices_;
            boundTextures = fallbacks;
            pushBindings(pipeline, *boundVertices, boundTextures);
        }
        const gpu::Buffer* vertices = vertexSource(work, first.instance, slot).first;
        facing.set(cmd, work.mirrored[first.instance] != 0, range.doubleSided);
        MaterialTextures textures = boundTextures;
        const bool textured = rangeTextures(range, textures);
        if (vertices != boundVertices || textures != boundTextures) {
            boundVertices = vertices;
            boundTextures = textures;
            pushBindings(pipeline, *boundVertices, boundTextures);
        }
        pipeline.pushConstants(cmd, range.material);
        if (phase == SurfacePhase::Direct) {
            for (size_t d = begin; d < end; ++d) {
                const SurfaceDraw& draw = work.draws[d];
                const int32_t vertexShift = vertexSource(work, draw.instance, slot).second;
                vkCmdDrawIndexed(cmd, draw.indexCount, 1, draw.firstIndex, draw.range->vertexOffset + vertexShift,
                                 draw.instance);
            }
        } else {
            // The run's chunks: the commands the cull kept, and their count.
            const uint64_t firstSlot = work.runFirstSlot.at(run);
            const uint64_t endSlot = firstSlot + (end - begin);
            for (uint64_t s = firstSlot; s < endSlot; s += chunk) {
                vkCmdDrawIndexedIndirectCount(cmd, indirect, s * stride, indirect,
                                              countsOffset + s / chunk * sizeof(uint32_t),
                                              uint32_t(std::min<uint64_t>(endSlot - s, chunk)), stride);
            }
        }
        if (counts) {
            ++stats_.runs;
            for (size_t d = begin; d < end; ++d) {
                const SurfaceDraw& draw = work.draws[d];
                stats_.normalMappedDraws += draw.range->material.normalMap != 0 ? 1u : 0u;
                stats_.texturedDraws += textured ? 1u : 0u;
                stats_.maskedDraws += first.masked ? 1u : 0u;
                ++stats_.draws;
                stats_.triangles += draw.indexCount / 3;
            }
        }
        begin = end;
    }
    if (work.drawSky && phase != SurfacePhase::Early) {
        skyPipeline_.bind(cmd);
        pushBindings(skyPipeline_, vertices_, fallbacks);
        skyPipeline_.pushConstants(cmd, shader::GBufferDraw{});
        vkCmdDraw(cmd, 3, 1, 0, 0);
    }
    vkCmdEndRendering(cmd);
}

GBufferOutputs addGBufferPass(rg::Graph& graph, GBufferRenderer& renderer, const GBufferInputs& inputs,
                              const GBufferSettings& settings) {
    const uint32_t width = inputs.camera.resolution.x;
    const uint32_t height = inputs.camera.resolution.y;
    if (width == 0 || height == 0) {
        throw gpu::GpuError("G-buffer: the camera's resolution is " + std::to_string(width) + "x" +
                            std::to_string(height) + "; both sides must be positive");
    }
    std::shared_ptr<GBufferRenderer::FrameWork> work = renderer.prepare(inputs, settings);
    renderer.current_ = work;
    if (work->frame.lighting.environment.x != 0.0f && !inputs.environment.valid()) {
        throw gpu::GpuError("G-buffer: the lighting looks up an environment image but no environment texture was given "
                            "(passes::importEnvironment)");
    }

    // With shadows off the map is one cleared texel: the G-buffer's
    // pipelines keep one layout and the frame one shape.
    const uint32_t shadowSize = work->frame.shadow.enabled != 0 ? work->frame.shadow.resolution : 1u;
    struct ShadowData {
        rg::Texture map;
    };
    const ShadowData& shadow = graph.addPass<ShadowData>(
        "shadow_map", rg::Queue::Graphics,
        [&](rg::Builder& b, ShadowData& d) {
            b.setPipeline(rg::Pipeline::Raster);
            d.map = b.write(b.createTexture("gbuffer.shadow_map", {.width = shadowSize,
                                                                    .height = shadowSize,
                                                                    .format = kGBufferShadowMapFormat}),
                            rg::Access::DepthWrite);
        },
        [&renderer, work](const ShadowData& d, rg::PassContext& pc) { renderer.recordShadowMap(*work, pc, d.map); });

    // With occlusion culling: the early cull before the G-buffer, then the
    // depth pyramid, the late cull and the late G-buffer pass after it.
    std::optional<GBufferRenderer::OcclusionHandles> occlusion;
    if (work->occlusionCulling) occlusion = renderer.addEarlyCull(graph, work);
    using Phase = GBufferRenderer::SurfacePhase;
    struct SurfaceData {
        GBufferOutputs out;
        rg::Buffer args;
    };
    // Both G-buffer passes: the first creates the targets, the late one
    // draws over them.
    const auto addSurfacePass = [&](const char* name, Phase phase, const GBufferOutputs* early, rg::Buffer args) {
        return graph.addPass<SurfaceData>(
            name, rg::Queue::Graphics,
            [&](rg::Builder& b, SurfaceData& d) {
                b.setPipeline(rg::Pipeline::Raster);
                const auto target = [&](rg::Texture previous, const char* targetName, VkFormat format,
                                        rg::Access access) {
                    if (early) return b.write(previous, access);
                    return b.write(b.createTexture(targetName, {.width = width, .height = height, .format = format}),
                                   access);
                };
                GBufferOutputs& o = d.out;
                const GBufferOutputs none;
                const GBufferOutputs& from = early ? *early : none;
                o.depth = target(from.depth, "gbuffer.depth", kGBufferDepthFormat, rg::Access::DepthWrite);
                o.normal = target(from.normal, "gbuffer.normal", kGBufferNormalFormat, rg::Access::ColorAttachment);
                o.albedo = target(from.albedo, "gbuffer.albedo", kGBufferAlbedoFormat, rg::Access::ColorAttachment);
                o.roughnessMetal = target(from.roughnessMetal, "gbuffer.roughness_metal",
                                          kGBufferRoughnessMetalFormat, rg::Access::ColorAttachment);
                o.motion = target(from.motion, "gbuffer.motion", kGBufferMotionFormat, rg::Access::ColorAttachment);
                o.lit = target(from.lit, "gbuffer.lit", kGBufferLitFormat, rg::Access::ColorAttachment);
                o.shadowMap = b.read(shadow.map, rg::Access::SampledRead);
                if (inputs.environment.valid()) {
                    b.read(inputs.environment, rg::Access::SampledRead);
                }
                if (args.valid()) d.args = b.read(args, rg::Access::IndirectArgs);
                o.width = width;
                o.height = height;
                o.shadowResolution = shadowSize;
                o.shadow = work->frame.shadow;
                o.lighting = work->frame.lighting;
            },
            [&renderer, work, phase, environment = inputs.environment](const SurfaceData& d, rg::PassContext& pc) {
                renderer.record(*work, pc, d.out, environment, phase, d.args);
            });
    };
    const SurfaceData& first =
        addSurfacePass("gbuffer", occlusion ? Phase::Early : Phase::Direct, nullptr,
                       occlusion ? occlusion->earlyArgs : rg::Buffer{});
    if (!occlusion) return first.out;
    const rg::Buffer lateArgs = renderer.addLateCull(graph, work, first.out, *occlusion);
    GBufferOutputs out = addSurfacePass("gbuffer.late", Phase::Late, &first.out, lateArgs).out;
    out.occlusionStats = occlusion->stats;
    return out;
}

} // namespace glint::passes
