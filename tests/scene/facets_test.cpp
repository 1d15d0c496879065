#include "glint/scene/facets.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/procedural_meshes.h"

#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

using namespace glint::scene;

namespace {

// A box of side 2 centred on the origin, each face n x n quads (2 n^2
// triangles).
Geometry gridBox(uint32_t n) { return makeDividedBox(glm::vec3(2.0f), n, 0); }

// Each triangle's three indices, sorted as triangles: what a split must
// keep, whatever the order.
std::vector<std::array<uint32_t, 3>> triangleSet(const std::vector<uint32_t>& indices) {
    std::vector<std::array<uint32_t, 3>> out;
    for (size_t t = 0; t + 2 < indices.size(); t += 3) out.push_back({indices[t], indices[t + 1], indices[t + 2]});
    std::sort(out.begin(), out.end());
    return out;
}

// Whether a triangle of `g` faces `eye` (strictly), in double.
bool facesEye(const Geometry& g, const uint32_t* tri, const glm::vec3& eye) {
    const glm::dvec3 p0(g.positions[tri[0]]), p1(g.positions[tri[1]]), p2(g.positions[tri[2]]);
    return glm::dot(glm::cross(p1 - p0, p2 - p0), glm::dvec3(eye) - p0) > 0.0;
}

// Every triangle of every facet hidden from `eye` faces away from it;
// returns how many facets were hidden.
uint32_t checkHiddenFaceAway(const Geometry& g, const FacetSplit& split, const glm::vec3& eye) {
    uint32_t hidden = 0;
    for (const Facet& f : split.facets) {
        if (!facetHidden(f, eye)) continue;
        ++hidden;
        uint32_t facing = 0;
        for (uint32_t i = f.firstIndex; i < f.firstIndex + f.indexCount; i += 3) {
            facing += facesEye(g, &split.indices[i], eye) ? 1u : 0u;
        }
        CHECK(facing == 0u);
    }
    return hidden;
}

} // namespace

TEST_CASE("a finely divided box splits into its six faces, and a facet is hidden exactly when it faces away") {
    const Geometry box = gridBox(16);  // 512 triangles a face
    const FacetSplit split = splitIntoFacets(box.positions, box.indices);
    REQUIRE(split.facets.size() == 6u);
    CHECK(triangleSet(split.indices) == triangleSet(box.indices));
    uint32_t next = 0;
    for (const Facet& f : split.facets) {
        CHECK(f.cullable);
        CHECK(f.firstIndex == next);  // consecutive, in bin order
        CHECK(f.indexCount == 512u * 3u);
        CHECK(f.spread < 1e-5f);
        next += f.indexCount;
    }
    CHECK(split.facets[0].axis.x == doctest::Approx(1.0f));
    CHECK(split.facets[5].axis.z == doctest::Approx(-1.0f));
    CHECK(split.facets[0].minPlane == doctest::Approx(1.0f));

    // From a corner three faces are seen; beside one face only that one.
    CHECK(checkHiddenFaceAway(box, split, {10.0f, 10.0f, 10.0f}) == 3u);
    CHECK(checkHiddenFaceAway(box, split, {10.0f, 0.1f, 0.2f}) == 5u);
    // From inside every face is seen from behind... and culled.
    CHECK(checkHiddenFaceAway(box, split, {0.0f, 0.0f, 0.0f}) == 6u);
    // In a face's plane (edge-on) it is kept: the margin leans to drawing.
    CHECK_FALSE(facetHidden(split.facets[1], {0.0f, 1.0f, 5.0f}));
    CHECK_FALSE(facetHidden(split.facets[1], {0.0f, 1.0f + 1e-6f, 5.0f}));
}

TEST_CASE("a hidden facet never holds a triangle that faces the eye, for any shape and any eye") {
    std::vector<Geometry> shapes;
    shapes.push_back(gridBox(16));
    shapes.push_back(makeSphere(1.5f, 96, 48, 0));
    shapes.push_back(makeTorus(2.0f, 0.5f, 96, 48, 0));
    // A gently rolling ground: normals within a few degrees of +y.
    shapes.push_back(makeGrid({20.0f, 20.0f}, {40, 40}, 0, 1.0f,
                              [](float x, float z) { return 0.1f * std::sin(x) * std::cos(0.7f * z); }));
    // A box rotated off the axes and sheared, so that no bin is exact.
    Geometry skewed = gridBox(16);
    transformGeometry(skewed, glm::rotate(glm::mat4(1.0f), 0.3f, glm::normalize(glm::vec3(1, 2, 3))) *
                                  glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0.05f, 1, 0, 0), glm::vec4(0, 0, 1, 0),
                                            glm::vec4(0, 0, 0, 1)));
    shapes.push_back(skewed);

    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coordinate(-12.0f, 12.0f);
    uint32_t hiddenFacets = 0;
    for (const Geometry& g : shapes) {
        const FacetSplit split = splitIntoFacets(g.positions, g.indices);
        if (!split.facets.empty()) CHECK(triangleSet(split.indices) == triangleSet(g.indices));
        for (int k = 0; k < 400; ++k) {
            glm::vec3 eye(coordinate(rng), coordinate(rng), coordinate(rng));
            if (k % 4 == 0) eye *= 0.1f;  // close to the surface, and inside
            if (k % 7 == 0) eye.y = 1.0f;  // in the box's top plane
            hiddenFacets += checkHiddenFaceAway(g, split, eye);
        }
    }
    CHECK(hiddenFacets > 1000u);  // the check above was not vacuous
}

TEST_CASE("geometry that faces every way, or is small, stays one draw in its own order") {
    const Geometry sphere = makeSphere(1.0f, 64, 32, 0);
    CHECK(splitIntoFacets(sphere.positions, sphere.indices).facets.empty());
    const Geometry box = makeBox({1.0f, 1.0f, 1.0f}, 0);  // 12 triangles
    CHECK(splitIntoFacets(box.positions, box.indices).facets.empty());
    CHECK(splitIntoFacets(box.positions, box.indices).indices.empty());
}

TEST_CASE("triangles without a normal, or facing away from their bin's axis, go to a remainder never hidden") {
    Geometry g = gridBox(16);
    // A sphere's worth of triangles facing every way, and degenerate ones.
    appendGeometry(g, makeSphere(0.5f, 64, 32, 0));
    const uint32_t v = g.vertexCount();
    g.positions.push_back({0, 0, 0});
    g.positions.push_back({1, 0, 0});
    g.positions.push_back({2, 0, 0});  // collinear
    for (size_t k = 0; k < 3; ++k) {
        g.normals.push_back({0, 1, 0});
        g.texcoords0.push_back({0, 0});
    }
    g.indices.insert(g.indices.end(), {v, v + 1, v + 2, v, v, v + 1});
    const FacetSplit split = splitIntoFacets(g.positions, g.indices);
    CHECK(triangleSet(split.indices) == triangleSet(g.indices));
    // The sphere's stray normals did not tilt the box's faces.
    REQUIRE(split.facets.size() == 7u);
    for (size_t k = 0; k < 6; ++k) {
        CHECK(split.facets[k].cullable);
        CHECK(split.facets[k].spread <= 0.1f);
        CHECK(split.facets[k].indexCount >= 512u * 3u);
    }
    CHECK(split.facets[0].axis.x > 0.999f);
    const Facet& remainder = split.facets.back();
    CHECK_FALSE(remainder.cullable);
    CHECK(remainder.firstIndex + remainder.indexCount == split.indices.size());
    // The degenerate pair is in it, and nothing hides it from anywhere.
    const auto begin = split.indices.begin() + remainder.firstIndex;
    CHECK(std::search(begin, split.indices.end(), g.indices.end() - 6, g.indices.end()) != split.indices.end());
    CHECK_FALSE(facetHidden(remainder, {100.0f, 0.0f, 0.0f}));
    CHECK_FALSE(facetHidden(remainder, {0.0f, 0.0f, 0.0f}));
}
