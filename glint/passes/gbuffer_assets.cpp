// The G-buffer renderer's assets: every mesh's LOD 0 in one vertex and one
// index buffer with its draw ranges, and the material textures, uploaded
// when the renderer is made and again when the scene's assets change
// (scene::Scene::assetRevision).
#include "glint/passes/gbuffer.h"
#include "glint/passes/gbuffer_internal.h"

#include "glint/gpu/resources.h"
#include "glint/scene/packed_primitives.h"

#include "glint/gbuffer_shared.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>

namespace glint::passes {

using namespace gbuffer_detail;

void GBufferRenderer::loadAssets() {
    assets_ = scene::assetStamp(scene_);
    textureImages_.clear();
    meshDraws_.clear();
    morphBaseVertices_.clear();
    hasBlended_ = false;
    // Material textures, uploaded with their mips the first time a drawn
    // geometry's material needs them, each once per colour space however
    // many materials share it. glTF: base colour and emissive are sRGB (the sampler
    // decodes before filtering; the CPU sampling at vertices decodes after,
    // which agrees at texel centres), metallic-roughness and normal linear.
    std::map<std::pair<int32_t, VkFormat>, size_t> imageOf;
    uint64_t textureBytes = 0;
    std::set<size_t> normalImages;
    const auto textureImage = [&](const scene::TextureRef& ref, VkFormat format, const char* slotName) {
        if (!ref.valid()) return kNoImage;
        const scene::Texture& texture = scene_.textures.at(size_t(ref.texture));
        if (texture.format != scene::TextureFormat::Rgba8) return kNoImage;
        const auto [it, added] = imageOf.try_emplace({ref.texture, format}, textureImages_.size());
        if (!added) return it->second;
        textureImages_.push_back(gpu::createSampledImageWithMips(ctx_,
                                                                 {.width = texture.width,
                                                                  .height = texture.height,
                                                                  .format = format,
                                                                  .name = std::string("gbuffer.") + slotName + "." +
                                                                          texture.name},
                                                                 texture.rgba8.data()));
        for (uint32_t w = texture.width, h = texture.height;; w = std::max(w / 2, 1u), h = std::max(h / 2, 1u)) {
            textureBytes += uint64_t(w) * h * 4;
            if (w == 1 && h == 1) break;
        }
        return it->second;
    };

    // Every mesh's LOD 0 into one vertex and one index buffer: one binding
    // for the whole frame, draws differ only in their ranges.
    std::vector<shader::GBufferVertex> vertices;
    std::vector<uint32_t> indices;
    uint32_t facetedGeometries = 0;
    meshDraws_.resize(scene_.meshes.size());
    meshFirstVertex_.assign(scene_.meshes.size(), 0);
    morphBaseVertices_.resize(scene_.meshes.size());
    for (size_t m = 0; m < scene_.meshes.size(); ++m) {
        const scene::Mesh& mesh = scene_.meshes[m];
        meshFirstVertex_[m] = int32_t(vertices.size());
        if (mesh.lods.empty()) continue;
        for (const scene::Geometry& g : mesh.lods[0].geometries) {
            DrawRange range;
            range.firstIndex = uint32_t(indices.size());
            range.indexCount = uint32_t(g.indices.size());
            range.vertexOffset = int32_t(vertices.size());
            const scene::Material& material = scene_.materials.at(g.material);
            range.doubleSided = material.doubleSided;
            range.coverage = material.alphaMode == scene::AlphaMode::Mask    ? Coverage::Masked
                             : material.alphaMode == scene::AlphaMode::Blend ? Coverage::Blended
                                                                               : Coverage::Opaque;
            range.bounds = g.bounds;
            hasBlended_ = hasBlended_ || (range.coverage == Coverage::Blended && range.indexCount > 0);
            // A slot samples its texture when `wanted` and the texture has an
            // image: its coordinate set (+1; 0 = not sampled), transform and
            // sampler go to the draw.
            const auto useSlot = [&](uint32_t slot, const scene::TextureRef& ref, VkFormat format, const char* what,
                                     bool wanted, uint32_t& map, shader::UvTransform& transform) {
                if (wanted) range.image[slot] = textureImage(ref, format, what);
                if (range.image[slot] == kNoImage) return false;
                map = ref.texCoord + 1;
                transform = ref.uvTransform();
                range.sampler[slot] = samplerIndex(ref);
                return true;
            };
            shader::GBufferDraw& draw = range.material;
            draw.doubleSided = range.doubleSided ? 1u : 0u;
            draw.alphaCutoff = range.coverage == Coverage::Masked ? material.alphaCutoff : -1.0f;
            if (useSlot(kNormalSlot, material.normalTexture, VK_FORMAT_R8G8B8A8_UNORM, "normal_map",
                        g.tangents.size() == g.vertexCount(), draw.normalMap, draw.normalUvTransform)) {
                draw.normalScale = material.normalScale;
                normalImages.insert(range.image[kNormalSlot]);
            }
            useSlot(kBaseColorSlot, material.baseColorTexture, VK_FORMAT_R8G8B8A8_SRGB, "base_color", true,
                    draw.baseColorMap, draw.baseColorUvTransform);
            useSlot(kMetalRoughSlot, material.metallicRoughnessTexture, VK_FORMAT_R8G8B8A8_UNORM, "metal_rough", true,
                    draw.metalRoughMap, draw.metalRoughUvTransform);
            // Only a material that emits uploads its emissive texture.
            const glm::vec3 emissiveFactor = material.emissiveFactor * material.emissiveStrength;
            useSlot(kEmissiveSlot, material.emissiveTexture, VK_FORMAT_R8G8B8A8_SRGB, "emissive",
                    emissiveFactor != glm::vec3(0.0f), draw.emissiveMap, draw.emissiveUvTransform);
            for (uint32_t v = 0; v < g.vertexCount(); ++v) {
                const shader::SurfaceVertex s = scene::surfaceAtVertex(scene_, g, v);
                shader::GBufferVertex out{};
                out.position = g.positions[v];
                out.normal = s.normal;
                out.albedo = s.albedo;
                out.roughness = s.roughness;
                out.metallic = s.metallic;
                // Textures sampled per pixel leave their factors (and
                // COLOR_0) here; the fragment shader multiplies the texel in.
                if (range.material.baseColorMap != 0) {
                    glm::vec3 albedo = glm::vec3(material.baseColorFactor);
                    if (v < g.colors.size()) albedo *= glm::vec3(g.colors[v]);
                    out.albedo = glm::clamp(albedo, glm::vec3(0.0f), glm::vec3(1.0f));
                }
                if (range.material.metalRoughMap != 0) {
                    out.roughness = std::clamp(material.roughnessFactor, 0.0f, 1.0f);
                    out.metallic = std::clamp(material.metallicFactor, 0.0f, 1.0f);
                }
                out.reflectance = s.reflectance;
                // Per pixel the texel multiplies the factor; else (no
                // texture, or not 8-bit) the vertex holds it all.
                out.emissive = range.material.emissiveMap != 0 ? emissiveFactor
                                                               : scene::emissionAtVertex(scene_, g, v);
                if (g.skinned()) {
                    const glm::u16vec4 j = g.joints[v];
                    out.joints = {uint32_t(j.x) | uint32_t(j.y) << 16, uint32_t(j.z) | uint32_t(j.w) << 16};
                    out.weights = g.weights[v];
                }
                out.tangent = v < g.tangents.size() ? g.tangents[v] : glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
                out.uv0 = v < g.texcoords0.size() ? g.texcoords0[v] : glm::vec2(0.0f);
                out.uv1 = v < g.texcoords1.size() ? g.texcoords1[v] : glm::vec2(0.0f);
                out.alpha = std::clamp(material.baseColorFactor.a * (v < g.colors.size() ? g.colors[v].a : 1.0f),
                                       0.0f, 1.0f);
                vertices.push_back(out);
            }
            // Single-sided opaque and alpha-tested geometry that does not
            // move its vertices is stored by facing, so that a frame can
            // skip the groups that face away (SurfaceDraw).
            const bool facing = !range.doubleSided && range.coverage != Coverage::Blended && !g.skinned() &&
                                g.morphTargets.empty();
            scene::FacetSplit split;
            if (facing) split = scene::splitIntoFacets(g.positions, g.indices);
            if (split.facets.empty()) {
                indices.insert(indices.end(), g.indices.begin(), g.indices.end());
            } else {
                indices.insert(indices.end(), split.indices.begin(), split.indices.end());
                for (scene::Facet& f : split.facets) f.firstIndex += range.firstIndex;
                range.facets = std::move(split.facets);
                ++facetedGeometries;
            }
            meshDraws_[m].push_back(std::move(range));
        }
        if (!mesh.morphWeights.empty()) {
            // Kept for the per-frame morphed copies: materials and skins stay,
            // positions, normals and tangents are replaced.
            morphBaseVertices_[m].assign(vertices.begin() + meshFirstVertex_[m], vertices.end());
        }
    }
    // Ranges that bind the same: one state, drawn together (the frame's
    // draws are sorted by it; FrameWork::draws).
    std::map<std::string, uint32_t> states;
    for (std::vector<DrawRange>& ranges : meshDraws_) {
        for (DrawRange& range : ranges) {
            std::string key(reinterpret_cast<const char*>(&range.material), sizeof(range.material));
            key.append(reinterpret_cast<const char*>(range.image.data()), sizeof(range.image));
            key.append(reinterpret_cast<const char*>(range.sampler.data()), sizeof(range.sampler));
            key.push_back(char(range.coverage));
            range.state = states.emplace(std::move(key), uint32_t(states.size())).first->second;
        }
    }
    rangeStates_ = uint32_t(states.size());
    // Vulkan buffers cannot be empty; an empty scene still binds something.
    if (vertices.empty()) vertices.push_back({});
    if (indices.empty()) indices.push_back(0);
    vertices_ = gpu::createBufferWithData(ctx_,
                                          {vertices.size() * sizeof(vertices[0]), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                           gpu::MemoryUsage::DeviceLocal, "gbuffer.vertices"},
                                          vertices.data());
    indices_ = gpu::createBufferWithData(ctx_,
                                         {indices.size() * sizeof(uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                          gpu::MemoryUsage::DeviceLocal, "gbuffer.indices"},
                                         indices.data());
    if (hasBlended_ && transparentPipeline_.handle() == VK_NULL_HANDLE) {
        transparentPipeline_ = createTransparentPipeline();
    }
    stats_.geometryBytes = vertices_.size() + indices_.size();
    stats_.textureImages = uint32_t(textureImages_.size());
    stats_.textureBytes = textureBytes;
    stats_.normalMaps = uint32_t(normalImages.size());
    stats_.facetedGeometries = facetedGeometries;
    spdlog::info("G-buffer: {} material textures uploaded for per-pixel sampling ({:.2f} MiB with mips), {} of them "
                 "normal maps",
                 stats_.textureImages, double(textureBytes) / (1024.0 * 1024.0), stats_.normalMaps);
    spdlog::debug("G-buffer: {} geometries stored by facing, their groups skipped where they face away",
                  facetedGeometries);
}

void GBufferRenderer::reloadAssetsIfEdited() {
    retired_.release(frame_);
    if (scene::assetStamp(scene_) == assets_) return;
    // Frames up to frame_ - 1 may still read them.
    retired_.keep(std::move(textureImages_), frame_);
    retired_.keep(std::move(vertices_), frame_);
    retired_.keep(std::move(indices_), frame_);
    loadAssets();
    spdlog::info("G-buffer: the scene's assets changed (revision {}): geometry and textures uploaded again",
                 assets_.revision);
}

} // namespace glint::passes
