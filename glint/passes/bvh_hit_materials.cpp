#include "glint/passes/bvh_hit_materials.h"

#include "glint/gpu/commands.h"
#include "glint/scene/alpha_test.h"
#include "glint/scene/packed_primitives.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace glint::passes {

HitMaterials::HitMaterials(gpu::Context& ctx, const scene::Scene& scene, const HitMaterialOptions& options)
    : scene_(scene) {
    // O(texels) per emissive texture, once: a hit's emission is its
    // material's mean.
    materialEmission_.reserve(scene.materials.size());
    for (const scene::Material& material : scene.materials) {
        materialEmission_.push_back(scene::meanEmission(scene, material));
    }
    // One mask layer per base colour texture of an alpha-tested material.
    const uint32_t size = std::max(options.alphaMaskSize, 1u);
    std::map<int32_t, uint32_t> layerOf;
    std::vector<uint8_t> texels;
    materialMask_.assign(scene.materials.size(), shader::kAlphaNoMask);
    for (size_t m = 0; m < scene.materials.size(); ++m) {
        const scene::Material& material = scene.materials[m];
        if (!scene::alphaTested(material)) continue;
        uint32_t layer = shader::kAlphaNoMask;
        const int32_t texture = material.baseColorTexture.texture;
        if (texture != scene::kNone && scene.textures.at(size_t(texture)).valid()) {
            const auto [it, added] = layerOf.try_emplace(texture, uint32_t(layerOf.size()));
            if (added) {
                const std::vector<uint8_t> layerTexels = scene::alphaMaskTexels(scene.textures[size_t(texture)], size);
                texels.insert(texels.end(), layerTexels.begin(), layerTexels.end());
            }
            layer = it->second;
        }
        materialMask_[m] = scene::alphaMaskWord(material, layer);
    }
    // Every LOD of every mesh: the planner picks the reflection LOD, the
    // reference the full detail.
    std::vector<shader::AlphaTriangle> triangles;
    for (uint32_t mesh = 0; mesh < scene.meshes.size(); ++mesh) {
        const std::vector<scene::MeshLod>& lods = scene.meshes[mesh].lods;
        for (uint32_t lod = 0; lod < lods.size(); ++lod) {
            for (uint32_t g = 0; g < lods[lod].geometries.size(); ++g) {
                const scene::Geometry& geometry = lods[lod].geometries[g];
                if (!scene::alphaTested(scene.materials.at(geometry.material))) continue;
                firstTriangle_[{mesh, lod, g}] = uint32_t(triangles.size());
                const std::vector<shader::AlphaTriangle> own = scene::alphaTriangles(scene, geometry);
                triangles.insert(triangles.end(), own.begin(), own.end());
                ++stats_.alphaTestedGeometries;
            }
        }
    }
    stats_.alphaTriangles = triangles.size();
    stats_.alphaMaskLayers = uint32_t(layerOf.size());
    // Complete descriptors even without alpha-tested geometry: one zero
    // triangle, one opaque layer that nothing reads.
    if (triangles.empty()) triangles.push_back({});
    const uint32_t layers = std::max<uint32_t>(uint32_t(layerOf.size()), 1u);
    if (texels.empty()) texels.assign(size_t(size) * size, 255);
    triangles_ = gpu::createBufferWithData(
        ctx, {triangles.size() * sizeof(shader::AlphaTriangle), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
              gpu::MemoryUsage::DeviceLocal, "bvh.alpha_triangles"},
        triangles.data());
    masks_ = gpu::createSampledImageWithMips(
        ctx, {.width = size, .height = size, .layers = layers, .format = VK_FORMAT_R8_UNORM, .name = "bvh.alpha_masks",
              .arrayView = true},
        texels.data());
    uint64_t maskBytes = 0;
    for (uint32_t s = size; s > 0; s /= 2) maskBytes += uint64_t(s) * s * layers;
    stats_.alphaBytes = triangles_.size() + maskBytes;
    if (stats_.alphaTestedGeometries > 0) {
        spdlog::info("BVH: {} alpha-tested geometries ({} triangles), {} alpha mask layers of {}x{}, {:.1f} KiB",
                     stats_.alphaTestedGeometries, stats_.alphaTriangles, stats_.alphaMaskLayers, size, size,
                     double(stats_.alphaBytes) / 1024.0);
    }
}

shader::RtGeometryMaterial HitMaterials::row(uint32_t mesh, uint32_t lod, uint32_t geometry) const {
    const scene::Geometry& g = scene_.meshes.at(mesh).lods.at(lod).geometries.at(geometry);
    shader::RtGeometryMaterial r{};
    r.emission = g.material < materialEmission_.size() ? materialEmission_[g.material] : glm::vec3(0.0f);
    r.alphaTriangles = shader::kAlphaOpaque;
    r.alphaMask = shader::kAlphaNoMask;
    const auto it = firstTriangle_.find({mesh, lod, geometry});
    if (it != firstTriangle_.end()) {
        r.alphaTriangles = it->second;
        r.alphaMask = materialMask_[g.material];
        r.alphaCutoff = scene_.materials[g.material].alphaCutoff;
    }
    return r;
}

} // namespace glint::passes
