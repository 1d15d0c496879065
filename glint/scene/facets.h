#pragma once
// Facets: a geometry's triangles grouped by the way they face, so that a
// rasterizer's caller can skip a group that faces away from the eye as a
// whole instead of sending its triangles to be culled one by one (cluster
// back-face culling, as GPU-driven renderers do it per meshlet with a
// normal cone; here per geometry, with few and large groups, since every
// group kept is a draw of its own).
//
// The triangles are binned by the dominant axis and sign of their normal
// (six bins). A bin's triangles whose unit normals lie within `maxSpread`
// of the bin's mean normal are a facet when there are at least
// minTriangles of them; every other triangle goes to one remainder,
// always drawn.
// Within each group the triangles keep their order, so the triangles a
// draw of the kept groups rasterizes are those of the whole geometry, in
// the same order, less those that face away.
//
// The test (facetHidden) is conservative: for a facet with unit axis a,
// spread s = max |n_i - a| over its triangles' unit normals, m = min over
// its vertices of dot(a, v) and a bounding sphere (c, r), every triangle i
// has dot(n_i, eye - v_i) <= dot(a, eye) - m + s (|eye - c| + r). When
// that bound is below zero by a margin, every triangle faces away from the
// eye or is seen edge-on, and none can produce a fragment with back faces
// culled. Affine transforms keep the sign of dot(n, eye - v) (the plane's
// normal transforms by the inverse transpose, the vector by the transform),
// so the test runs in the mesh's own space with the eye moved into it,
// mirrored instances included (their winding flips with their front face).
// The margin (1e-4 of the eye's distance plus the facet's radius) covers
// the float rounding of that move and of the GPU's own transform while
// coordinates stay well inside float's range for the scene's scale: 2 mm
// on a 20 m wall, against 0.06 mm steps of a float at 1 km from the origin.
//
// meshoptimizer's meshlets carry the same kind of cone (meshopt_
// computeMeshletBounds), but a meshlet holds at most a few hundred
// triangles, and each group here is a draw: six large groups with an
// exact plane bound cull a wall's hidden sides at a few draws per mesh.

#include "glint/scene/scene.h"

#include <cstdint>
#include <span>
#include <vector>

namespace glint::scene {

struct FacetSettings {
    // A bin smaller than this joins the remainder: a facet is a draw, and
    // a draw costs about what a few hundred culled triangles do.
    uint32_t minTriangles = 256;
    // Triangles whose normal lies further than this from their bin's axis
    // (|n - a|: 0.1 is about 6 degrees) join the remainder: the wider a
    // facet's normals spread, the further behind it the eye must be for
    // its test to pass.
    float maxSpread = 0.1f;
};

struct Facet {
    uint32_t firstIndex = 0;  // into FacetSplit::indices
    uint32_t indexCount = 0;
    // False for the remainder (drawn from anywhere).
    bool cullable = false;
    glm::vec3 axis{0.0f};    // unit: the mean of its triangles' normals
    float spread = 0.0f;     // max |n - axis| over its triangles
    float minPlane = 0.0f;   // min over its vertices of dot(axis, v)
    glm::vec3 centre{0.0f};  // bounding sphere of its vertices
    float radius = 0.0f;
};

struct FacetSplit {
    // The geometry's indices regrouped: the facets in bin order (+x, +y,
    // +z, -x, -y, -z), then the remainder. Empty when no facet is
    // cullable: the geometry stays one draw, in its own order.
    std::vector<uint32_t> indices;
    std::vector<Facet> facets;
};

// Groups `indices` (three per triangle, into `positions`) into facets; see
// the top of this file. Triangles with no normal (zero area) go to the
// remainder.
FacetSplit splitIntoFacets(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                           const FacetSettings& settings = {});

// True when every triangle of `facet` faces away from `eye` (in the
// geometry's space) or is seen edge-on, by a margin for rounding; always
// false for the remainder.
bool facetHidden(const Facet& facet, const glm::vec3& eye);

} // namespace glint::scene
