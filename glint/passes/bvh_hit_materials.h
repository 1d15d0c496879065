#pragma once
// What a ray-traced hit reads of its geometry beyond the packed vertices
// (glint/alpha_test.h): per primitive offset row a shader::RtGeometryMaterial
// (the material's mean emission and its alpha test), and for alpha-tested
// geometry (glTF alphaMode MASK) the per-triangle texture coordinates and
// alpha and the alpha mask array. Built from the scene when the
// passes::BvhManager is created, and again when the scene's assets change
// (scene::Scene::assetRevision): emission and alpha do not change from
// frame to frame otherwise, only which rows the TLAS uses.

#include "glint/gpu/context.h"
#include "glint/gpu/resources.h"
#include "glint/scene/scene.h"

#include "glint/alpha_test.h"

#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

namespace glint::passes {

struct HitMaterialOptions {
    // Side of each alpha mask layer (texels): every alpha-tested base colour
    // texture resampled to it. A reflection rarely shows a leaf's outline
    // sharper than this; 256 x 256 R8 with mips is 85 KiB a texture.
    uint32_t alphaMaskSize = 256;
};

struct HitMaterialStats {
    uint32_t alphaTestedGeometries = 0;  // geometries of every mesh LOD whose material is alpha-tested
    uint64_t alphaTriangles = 0;         // their triangles (one AlphaTriangle each)
    uint32_t alphaMaskLayers = 0;        // base colour textures of alpha-tested materials
    uint64_t alphaBytes = 0;             // the triangles' buffer and the mask array, mips included
};

class HitMaterials {
public:
    HitMaterials(gpu::Context& ctx, const scene::Scene& scene, const HitMaterialOptions& options = {});

    // The row of geometry `geometry` of mesh `mesh`'s LOD `lod`. Rays run
    // the alpha test on it (its BLAS geometry is not opaque) unless its
    // alphaTriangles is shader::kAlphaOpaque.
    shader::RtGeometryMaterial row(uint32_t mesh, uint32_t lod, uint32_t geometry) const;

    // shader::AlphaTriangle per alpha-tested triangle (at least one entry).
    const gpu::Buffer& alphaTriangles() const { return triangles_; }
    // R8 2D array, a layer per masked base colour texture (at least one),
    // mips, SHADER_READ_ONLY_OPTIMAL; sampled linearly, repeating (the
    // shader applies the other wrap modes).
    const gpu::Image& alphaMasks() const { return masks_; }
    const HitMaterialStats& stats() const { return stats_; }

private:
    using GeometryKey = std::tuple<uint32_t, uint32_t, uint32_t>;  // mesh, lod, geometry
    const scene::Scene& scene_;
    std::vector<glm::vec3> materialEmission_;  // per material: scene::meanEmission
    std::vector<uint32_t> materialMask_;       // per material: its alphaMask word
    std::map<GeometryKey, uint32_t> firstTriangle_;  // alpha-tested geometries only
    gpu::Buffer triangles_;
    gpu::Image masks_;
    HitMaterialStats stats_;
};

} // namespace glint::passes
