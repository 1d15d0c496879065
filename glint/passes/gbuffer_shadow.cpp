// The sun's shadow map: its fit to what the camera sees (fitSunShadow) and
// the "shadow_map" pass's recording (GBufferRenderer::recordShadowMap; the
// pass is declared with the G-buffer's, in gbuffer.cpp).
#include "glint/passes/gbuffer.h"
#include "glint/passes/gbuffer_internal.h"

#include "glint/gpu/descriptors.h"
#include "glint/graph/executor.h"

#include "glint/gbuffer_shared.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace glint::passes {

using namespace gbuffer_detail;

namespace {

// Shadows fade out over the last tenth of SunShadowSettings::maxDistance.
constexpr float kShadowFadeStart = 0.9f;
// Texels added on each side of the fitted square: the filter reaches two
// texels beyond a lookup, the normal offset moves lookups by up to one and
// snapping the centre to whole texels moves the square by up to half.
constexpr uint32_t kShadowBorderTexels = 4;

// `extent` rounded up to a multiple of 1/32 of its enclosing power of two:
// bounds that change a little (animated instances) keep the same texel size
// most frames, and a changing texel size is what makes shadow edges swim.
float quantiseExtent(float extent) {
    const float step = std::exp2(std::ceil(std::log2(extent)) - 5.0f);
    return std::ceil(extent / step) * step;
}

} // namespace

shader::GBufferShadow fitSunShadow(const scene::Scene& scene, const scene::Camera& camera,
                                   const SunShadowSettings& settings) {
    shader::GBufferShadow fit{};
    fit.viewProjection = glm::mat4(1.0f);
    fit.texelWorldSize = 1.0f;
    fit.depthRange = 1.0f;
    fit.resolution = 1;
    if (!settings.enabled || settings.resolution == 0) return fit;

    // Everything that can cast: every instance's bounds this frame (skinned
    // ones over their whole palette).
    scene::Aabb casters;
    for (const scene::Instance& inst : scene.instances) {
        if (inst.mesh < scene.meshes.size() && !scene.meshes[inst.mesh].lods.empty()) {
            casters.extend(scene::instanceBounds(scene, inst));
        }
    }
    const glm::vec3 toSun = glm::normalize(scene.sun.directionToLight);
    if (casters.empty() || !std::isfinite(toSun.x + toSun.y + toSun.z)) return fit;

    // The sun's frame: rays travel along `forward`; `right` and `up` span
    // the map. Any basis works (the pipelines cull nothing); this one keeps
    // the map's axes still while the sun is.
    const glm::vec3 forward = -toSun;
    const glm::vec3 reference = std::abs(forward.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 right = glm::normalize(glm::cross(forward, reference));
    const glm::vec3 up = glm::cross(right, forward);

    glm::vec3 lightMin(std::numeric_limits<float>::max());
    glm::vec3 lightMax(-std::numeric_limits<float>::max());
    for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1) ? casters.max.x : casters.min.x, (c & 2) ? casters.max.y : casters.min.y,
                               (c & 4) ? casters.max.z : casters.min.z);
        const glm::vec3 l(glm::dot(corner, right), glm::dot(corner, up), glm::dot(corner, forward));
        lightMin = glm::min(lightMin, l);
        lightMax = glm::max(lightMax, l);
    }

    // The camera's view up to maxDistance, as its bounding sphere: the
    // sphere's size depends only on the lens, so turning the camera never
    // changes the texel size (Valient, "Stable Rendering of Cascaded Shadow
    // Maps", ShaderX6). For the slice [n, f] of a frustum whose corner rays
    // have squared slope k2, the sphere through both caps' corners is
    // centred at (n + f)(1 + k2) / 2 along the view axis, or at the far cap
    // when that lies beyond it.
    const float tanX = 1.0f / std::max(std::abs(camera.projection[0][0]), 1e-6f);
    const float tanY = 1.0f / std::max(std::abs(camera.projection[1][1]), 1e-6f);
    const float k2 = tanX * tanX + tanY * tanY;
    const float nearDistance = std::max(camera.lens.nearPlane, 0.0f);
    const float farDistance = std::max(std::min(settings.maxDistance, camera.lens.farPlane), nearDistance + 1e-3f);
    float centreDistance = 0.5f * (nearDistance + farDistance) * (1.0f + k2);
    float radius = 0.0f;
    if (centreDistance >= farDistance) {
        centreDistance = farDistance;
        radius = farDistance * std::sqrt(k2);
    } else {
        radius = std::sqrt((farDistance - centreDistance) * (farDistance - centreDistance) +
                           farDistance * farDistance * k2);
    }
    const glm::vec3 viewForward = -glm::vec3(glm::inverse(camera.view)[2]);
    const glm::vec3 viewCentre = camera.position + glm::normalize(viewForward) * centreDistance;

    const float res = float(settings.resolution);
    const float border = res / std::max(res - 2.0f * float(kShadowBorderTexels), 1.0f);
    const float sceneExtent =
        quantiseExtent(std::max(std::max(lightMax.x - lightMin.x, lightMax.y - lightMin.y), 1e-3f));
    const float viewExtent = 2.0f * radius;
    glm::vec2 centre;
    float extent;
    if (sceneExtent <= viewExtent) {
        // The whole scene fits in less: use it, and never fade.
        extent = sceneExtent * border;
        centre = 0.5f * (glm::vec2(lightMin) + glm::vec2(lightMax));
        fit.fadeStart = fit.fadeEnd = 0.0f;
    } else {
        extent = viewExtent * border;
        centre = {glm::dot(viewCentre, right), glm::dot(viewCentre, up)};
        fit.fadeStart = kShadowFadeStart * farDistance;
        fit.fadeEnd = farDistance;
    }
    // Whole texels: the texel grid stays fixed in the world as the centre
    // moves, so a static edge covers the same texels every frame.
    const float texel = extent / res;
    centre = glm::round(centre / texel) * texel;

    // Depth along the rays over all casters, padded so nothing touches the
    // clip planes. Reversed: 1 nearest the sun (glint/gbuffer_shared.h).
    const float pad = 0.01f * (lightMax.z - lightMin.z) + 4.0f * texel;
    const float depthNear = lightMin.z - pad;
    const float depthFar = lightMax.z + pad;
    const float depthRange = depthFar - depthNear;

    const float half = 0.5f * extent;
    glm::mat4 m(0.0f);  // m[column][row]
    for (int i = 0; i < 3; ++i) {
        m[i][0] = right[i] / half;
        m[i][1] = up[i] / half;
        m[i][2] = -forward[i] / depthRange;
    }
    m[3][0] = -centre.x / half;
    m[3][1] = -centre.y / half;
    m[3][2] = depthFar / depthRange;
    m[3][3] = 1.0f;

    fit.viewProjection = m;
    fit.texelWorldSize = texel;
    fit.depthRange = depthRange;
    fit.constantBias = settings.constantBias;
    fit.slopeBias = settings.slopeBias;
    fit.normalOffset = settings.normalOffset;
    fit.maxSlope = settings.maxSlope;
    fit.resolution = settings.resolution;
    fit.enabled = 1;
    return fit;
}

void GBufferRenderer::recordShadowMap(const FrameWork& work, rg::PassContext& pc, rg::Texture shadowMap) {
    uploadOnce(work);
    const VkCommandBuffer cmd = pc.cmd();
    FrameSlot& slot = *slots_[work.slot];
    const uint32_t size = pc.image(shadowMap).desc().width;

    // Cleared to 0, the far end of the reversed depth: no caster.
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = pc.view(shadowMap);
    depth.imageLayout = VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = {0.0f, 0};
    VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
    rendering.renderArea = {{0, 0}, {size, size}};
    rendering.layerCount = 1;
    rendering.pDepthAttachment = &depth;
    vkCmdBeginRendering(cmd, &rendering);

    stats_.shadowDraws = 0;
    if (work.frame.shadow.enabled != 0) {
        const VkViewport viewport{0.0f, 0.0f, float(size), float(size), 0.0f, 1.0f};
        const VkRect2D scissor{{0, 0}, {size, size}};
        vkCmdSetViewport(cmd, 0, 1, &viewport);
        vkCmdSetScissor(cmd, 0, 1, &scissor);
        // Opaque casters, then alpha-tested ones (their own pipeline reads
        // the base colour texture's alpha and discards).
        vkCmdBindIndexBuffer(cmd, indices_.handle(), 0, VK_INDEX_TYPE_UINT32);
        for (const bool masked : {false, true}) {
            const gpu::Pipeline& pipeline = masked ? shadowMaskedPipeline_ : shadowPipeline_;
            pipeline.bind(cmd);
            const gpu::Buffer* boundVertices = nullptr;
            const gpu::Image* boundImage = nullptr;
            const gpu::Sampler* boundSampler = nullptr;
            for (size_t i = 0; i < work.instances.size(); ++i) {
                if (!work.castsShadow[i]) continue;
                const auto [vertices, vertexShift] = vertexSource(work, i, slot);
                for (const DrawRange& range : meshDraws_.at(work.meshes[i])) {
                    // Blended surfaces cast no shadow (nor do they in the
                    // BVH the shadow rays of the RT hits trace).
                    if (range.indexCount == 0 || range.coverage != (masked ? Coverage::Masked : Coverage::Opaque)) {
                        continue;
                    }
                    const size_t image = range.image[kBaseColorSlot];
                    const gpu::Image* baseColor = image == kNoImage ? &white_ : &textureImages_[image];
                    const gpu::Sampler* sampler =
                        image == kNoImage ? &textureSamplers_[0] : &textureSamplers_[range.sampler[kBaseColorSlot]];
                    if (vertices != boundVertices || (masked && (baseColor != boundImage || sampler != boundSampler))) {
                        boundVertices = vertices;
                        boundImage = baseColor;
                        boundSampler = sampler;
                        gpu::PushDescriptors push(pipeline);
                        push.storageBuffer(0, slot.frame)
                            .storageBuffer(1, slot.instances)
                            .storageBuffer(2, *vertices)
                            .storageBuffer(3, slot.joints)
                            .storageBuffer(4, slot.previousJoints);
                        if (masked) {
                            push.sampledImage(kFirstMaterialTextureBinding + kBaseColorSlot, baseColor->view(),
                                              sampler->handle());
                        }
                        push.push(ctx_, cmd);
                    }
                    shader::GBufferDraw draw{};
                    if (masked) {
                        draw.alphaCutoff = range.material.alphaCutoff;
                        draw.baseColorMap = range.material.baseColorMap;
                        draw.baseColorUvTransform = range.material.baseColorUvTransform;
                    }
                    pipeline.pushConstants(cmd, draw);
                    vkCmdDrawIndexed(cmd, range.indexCount, 1, range.firstIndex, range.vertexOffset + vertexShift,
                                     uint32_t(i));
                    ++stats_.shadowDraws;
                }
            }
        }
    }
    vkCmdEndRendering(cmd);
}

} // namespace glint::passes
