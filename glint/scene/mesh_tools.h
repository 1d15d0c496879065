#pragma once
// Geometry processing shared by the loaders and the procedural scenes.

#include "glint/scene/scene.h"

#include <span>

namespace glint::scene {

Aabb computeBounds(std::span<const glm::vec3> positions);

// Face normals, as glTF prescribes for primitives without NORMAL: every
// triangle gets its own three vertices (all attributes are unwelded).
void generateFlatNormals(Geometry& geometry);

// Per-vertex tangents (w = bitangent sign, glTF convention: bitangent =
// cross(normal, tangent) * w) from texture coordinate set `texCoord` (0 or
// 1) by accumulating area-weighted per-triangle UV derivatives (Lengyel,
// "Computing Tangent Space Basis Vectors for an Arbitrary Mesh", 2001),
// orthogonalised against the normal (Gram-Schmidt). Not full MikkTSpace:
// no angle weighting and no splitting of vertices whose triangles disagree
// on handedness, so normal maps baked by MikkTSpace match on smooth,
// unmirrored regions and differ slightly on seams. Vertices without usable
// UVs get any tangent perpendicular to the normal (Duff et al., "Building
// an Orthonormal Basis, Revisited", JCGT 2017). Requires normals.
void generateTangents(Geometry& geometry, uint32_t texCoord = 0);

// A unit vector perpendicular to unit vector `n` (Duff et al. 2017).
glm::vec3 anyPerpendicular(const glm::vec3& n);

// Transforms positions, normals and tangents in place.
void transformGeometry(Geometry& geometry, const glm::mat4& transform);

// Appends `source` to `target` (same attribute sets, same material).
void appendGeometry(Geometry& target, const Geometry& source);

} // namespace glint::scene
