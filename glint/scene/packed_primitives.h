#pragma once
// CPU reference of the compute pass that fills the primitive pool: per
// triangle the unwrapped (optionally skinned) positions the BLAS is built
// from, and the packed surface (glint/packing.h) sampled from the material
// at each vertex. Tests compare the GPU pass against it; tools can use it
// to fill a pool without a GPU.

#include "glint/scene/bvh_planner.h"
#include "glint/scene/scene.h"

#include "glint/packing.h"

#include <span>
#include <vector>

namespace glint::scene {

// The surface at `vertex` of `geometry`: base colour factor x vertex colour
// x base colour texture (sRGB decoded), roughness and metallic factors x the
// metallic-roughness texture (G, B), the vertex normal, the material's
// reflectance. Textures are sampled bilinearly from their base level at the
// vertex's texture coordinates (the set each reference names, through its
// KHR_texture_transform); normal maps do not apply at vertex rate.
shader::SurfaceVertex surfaceAtVertex(const Scene& scene, const Geometry& geometry, uint32_t vertex);

// Emission in glTF units (the renderers scale it to lit units with
// passes::LightingSettings::emissiveScale): emissiveFactor x
// KHR_materials_emissive_strength x the emissive texture (sRGB-decoded when
// 8-bit, linear when float) sampled bilinearly at `vertex`'s coordinates.
glm::vec3 emissionAtVertex(const Scene& scene, const Geometry& geometry, uint32_t vertex);

// A material's emission as one colour: factor x strength x the mean of its
// emissive texture's base level (linear, i.e. after sRGB decoding; O(texels)),
// what a ray-traced hit adds (the packed primitives have no room for it; see
// passes/bvh_update.h). Zero for non-emissive materials.
glm::vec3 meanEmission(const Scene& scene, const Material& material);

struct UnwrappedGeometry {
    std::vector<glm::vec3> positions;                 // three per triangle, object space
    std::vector<shader::PackedPrimitive> primitives;  // one per triangle
};

// Unwraps `geometry`. With `jointMatrices` (the instance's slice of
// Scene::jointMatrices) a skinned geometry's positions and normals are
// skinned first (linear blend skinning), as the GPU pass does.
UnwrappedGeometry unwrapGeometry(const Scene& scene, const Geometry& geometry,
                                 std::span<const glm::mat4> jointMatrices = {});

// The whole pool of `plan` (poolTriangles entries), every BLAS at its
// range; deformable BLASes use their instance's current joint matrices and
// morph weights (morph targets applied first, as passes::BvhManager feeds
// the pack pass).
// Ranges no BLAS owns stay zero.
std::vector<shader::PackedPrimitive> buildPrimitivePool(const Scene& scene, const BvhPlan& plan);

} // namespace glint::scene
