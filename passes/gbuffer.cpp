#include "passes/gbuffer.h"

#include "gpu/commands.h"
#include "gpu/descriptors.h"
#include "gpu/error.h"
#include "graph/executor.h"
#include "scene/packed_primitives.h"

#include "glint/gbuffer_shared.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

namespace glint::passes {

namespace {

constexpr VkShaderStageFlags kRasterStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Bindings of shaders/gbuffer/gbuffer_common.glsl, shared by both pipelines.
std::vector<gpu::Binding> gbufferBindings() {
    std::vector<gpu::Binding> bindings;
    for (uint32_t b = 0; b < 5; ++b) {
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kRasterStages});
    }
    return bindings;
}

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

// One LOD-0 geometry in the shared vertex and index buffers.
struct GBufferRenderer::DrawRange {
    uint32_t firstIndex = 0;
    uint32_t indexCount = 0;
    int32_t vertexOffset = 0;
    bool doubleSided = false;
};

// Host-visible buffers of one frame in flight, written when the frame
// records (the executor has waited for the slot's previous frame by then).
struct GBufferRenderer::FrameSlot {
    gpu::Buffer frame;
    gpu::Buffer instances;
    gpu::Buffer joints;
    gpu::Buffer previousJoints;
};

// What one frame draws, copied from the scene and camera at declaration.
struct GBufferRenderer::FrameWork {
    uint32_t slot = 0;
    bool drawSky = true;
    shader::GBufferFrame frame{};
    std::vector<shader::GBufferInstance> instances;
    std::vector<uint32_t> meshes;  // per instance
    std::vector<glm::mat4> joints;
    std::vector<glm::mat4> previousJoints;
};

GBufferRenderer::GBufferRenderer(gpu::Context& ctx, const scene::Scene& scene, uint32_t framesInFlight)
    : ctx_(ctx), scene_(scene), framesInFlight_(std::max(framesInFlight, 1u)) {
    gpu::GraphicsPipelineDesc surface;
    surface.vertexShader = "gbuffer/gbuffer.vert";
    surface.fragmentShader = "gbuffer/gbuffer.frag";
    surface.bindings = gbufferBindings();
    surface.pushConstantBytes = sizeof(shader::GBufferDraw);
    // No culling: glTF leaves winding to the asset only for single-sided
    // materials, and the built-in scenes include open and double-sided
    // geometry; depth testing hides the back faces of closed meshes.
    surface.cullMode = VK_CULL_MODE_NONE;
    surface.colorFormats.assign(kColorFormats.begin(), kColorFormats.end());
    surface.depthFormat = kGBufferDepthFormat;
    surface.name = "gbuffer.surface";
    surfacePipeline_ = gpu::createGraphicsPipeline(ctx, surface);

    gpu::GraphicsPipelineDesc sky = surface;
    sky.vertexShader = "gbuffer/sky.vert";
    sky.fragmentShader = "gbuffer/sky.frag";
    // At depth 0 the GREATER_OR_EQUAL test passes only where the clear value
    // survived; writing would change nothing.
    sky.depthWrite = false;
    sky.name = "gbuffer.sky";
    skyPipeline_ = gpu::createGraphicsPipeline(ctx, sky);

    // Every mesh's LOD 0 into one vertex and one index buffer: one binding
    // for the whole frame, draws differ only in their ranges.
    std::vector<shader::GBufferVertex> vertices;
    std::vector<uint32_t> indices;
    meshDraws_.resize(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const scene::Mesh& mesh = scene.meshes[m];
        if (mesh.lods.empty()) continue;
        for (const scene::Geometry& g : mesh.lods[0].geometries) {
            DrawRange range;
            range.firstIndex = uint32_t(indices.size());
            range.indexCount = uint32_t(g.indices.size());
            range.vertexOffset = int32_t(vertices.size());
            range.doubleSided = scene.materials.at(g.material).doubleSided;
            for (uint32_t v = 0; v < g.vertexCount(); ++v) {
                const shader::SurfaceVertex s = scene::surfaceAtVertex(scene, g, v);
                shader::GBufferVertex out{};
                out.position = g.positions[v];
                out.normal = s.normal;
                out.albedo = s.albedo;
                out.roughness = s.roughness;
                out.metallic = s.metallic;
                out.reflectance = s.reflectance;
                if (g.skinned()) {
                    const glm::u16vec4 j = g.joints[v];
                    out.joints = {uint32_t(j.x) | uint32_t(j.y) << 16, uint32_t(j.z) | uint32_t(j.w) << 16};
                    out.weights = g.weights[v];
                }
                vertices.push_back(out);
            }
            indices.insert(indices.end(), g.indices.begin(), g.indices.end());
            meshDraws_[m].push_back(range);
        }
    }
    // Vulkan buffers cannot be empty; an empty scene still binds something.
    if (vertices.empty()) vertices.push_back({});
    if (indices.empty()) indices.push_back(0);
    vertices_ = gpu::createBufferWithData(ctx, {vertices.size() * sizeof(vertices[0]), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                                gpu::MemoryUsage::DeviceLocal, "gbuffer.vertices"},
                                          vertices.data());
    indices_ = gpu::createBufferWithData(ctx, {indices.size() * sizeof(uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                               gpu::MemoryUsage::DeviceLocal, "gbuffer.indices"},
                                         indices.data());
    stats_.geometryBytes = vertices_.size() + indices_.size();

    for (uint32_t i = 0; i < framesInFlight_; ++i) {
        slots_.push_back(std::make_unique<FrameSlot>());
    }
}

GBufferRenderer::~GBufferRenderer() {
    // Frames in flight may still read the geometry and the slots' buffers.
    ctx_.waitIdle();
}

void GBufferRenderer::ensureCapacity(gpu::Buffer& buffer, VkDeviceSize bytes, const char* name) {
    if (buffer && buffer.size() >= bytes) return;
    buffer = gpu::Buffer(ctx_, {grownCapacity(bytes), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Upload, name});
}

std::shared_ptr<GBufferRenderer::FrameWork> GBufferRenderer::prepare(const GBufferInputs& inputs,
                                                                     const GBufferSettings& settings) {
    ++frame_;
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

    f.lighting = sceneLighting(scene_, settings.lighting);

    work->instances.reserve(scene_.instances.size());
    for (const scene::Instance& inst : scene_.instances) {
        shader::GBufferInstance gi{};
        gi.transform = inst.transform;
        gi.previousTransform = inst.previousTransform;
        if (inst.motion == scene::Motion::Skinned && inst.skin != scene::kNone) {
            gi.jointOffset = inst.jointOffset;
            gi.jointCount = uint32_t(scene_.skins.at(size_t(inst.skin)).joints.size());
        }
        work->instances.push_back(gi);
        work->meshes.push_back(inst.mesh);
    }
    work->joints = scene_.jointMatrices;
    work->previousJoints = scene_.previousJointMatrices;
    // Before the first advanceScene the previous palette may be missing:
    // then last frame looked like this one.
    if (work->previousJoints.size() != work->joints.size()) work->previousJoints = work->joints;
    return work;
}

void GBufferRenderer::record(const FrameWork& work, rg::PassContext& pc, const GBufferOutputs& targets) {
    const VkCommandBuffer cmd = pc.cmd();
    FrameSlot& slot = *slots_[work.slot];

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

    // Load-op clears: depth 0 is the reversed-Z far plane; zero normal w and
    // albedo mark "no surface" for the passes that read them.
    const std::array<rg::Texture, 5> colorTargets = {targets.normal, targets.albedo, targets.roughnessMetal,
                                                     targets.motion, targets.lit};
    std::array<VkRenderingAttachmentInfo, 5> colors{};
    for (size_t i = 0; i < colors.size(); ++i) {
        VkRenderingAttachmentInfo& a = colors[i];
        a.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        a.imageView = pc.view(colorTargets[i]);
        a.imageLayout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL;
        a.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        a.clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
    }
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = pc.view(targets.depth);
    depth.imageLayout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
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

    const auto pushBindings = [&](const gpu::Pipeline& pipeline) {
        gpu::PushDescriptors(pipeline)
            .storageBuffer(0, slot.frame)
            .storageBuffer(1, slot.instances)
            .storageBuffer(2, vertices_)
            .storageBuffer(3, slot.joints)
            .storageBuffer(4, slot.previousJoints)
            .push(ctx_, cmd);
    };

    stats_.draws = 0;
    stats_.triangles = 0;
    surfacePipeline_.bind(cmd);
    pushBindings(surfacePipeline_);
    vkCmdBindIndexBuffer(cmd, indices_.handle(), 0, VK_INDEX_TYPE_UINT32);
    for (size_t i = 0; i < work.instances.size(); ++i) {
        for (const DrawRange& range : meshDraws_.at(work.meshes[i])) {
            if (range.indexCount == 0) continue;
            surfacePipeline_.pushConstants(cmd, shader::GBufferDraw{uint32_t(i), range.doubleSided ? 1u : 0u});
            vkCmdDrawIndexed(cmd, range.indexCount, 1, range.firstIndex, range.vertexOffset, 0);
            ++stats_.draws;
            stats_.triangles += range.indexCount / 3;
        }
    }
    if (work.drawSky) {
        skyPipeline_.bind(cmd);
        pushBindings(skyPipeline_);
        skyPipeline_.pushConstants(cmd, shader::GBufferDraw{0, 0});
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

    const GBufferOutputs& out = graph.addPass<GBufferOutputs>(
        "gbuffer", rg::Queue::Graphics,
        [&](rg::Builder& b, GBufferOutputs& d) {
            b.setPipeline(rg::Pipeline::Raster);
            const auto target = [&](const char* name, VkFormat format, rg::Access access) {
                return b.write(b.createTexture(name, {.width = width, .height = height, .format = format}), access);
            };
            d.depth = target("gbuffer.depth", kGBufferDepthFormat, rg::Access::DepthWrite);
            d.normal = target("gbuffer.normal", kGBufferNormalFormat, rg::Access::ColorAttachment);
            d.albedo = target("gbuffer.albedo", kGBufferAlbedoFormat, rg::Access::ColorAttachment);
            d.roughnessMetal =
                target("gbuffer.roughness_metal", kGBufferRoughnessMetalFormat, rg::Access::ColorAttachment);
            d.motion = target("gbuffer.motion", kGBufferMotionFormat, rg::Access::ColorAttachment);
            d.lit = target("gbuffer.lit", kGBufferLitFormat, rg::Access::ColorAttachment);
            d.width = width;
            d.height = height;
        },
        [&renderer, work](const GBufferOutputs& d, rg::PassContext& pc) { renderer.record(*work, pc, d); });
    return out;
}

} // namespace glint::passes
