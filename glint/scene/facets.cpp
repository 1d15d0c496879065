#include "glint/scene/facets.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace glint::scene {

namespace {

constexpr uint32_t kBins = 6;  // +x, +y, +z, -x, -y, -z

// The bin of a unit normal: its largest component's axis, then its sign.
uint32_t binOf(const glm::dvec3& n) {
    const glm::dvec3 a = glm::abs(n);
    const uint32_t axis = a.x >= a.y && a.x >= a.z ? 0u : a.y >= a.z ? 1u : 2u;
    return n[int(axis)] >= 0.0 ? axis : axis + 3u;
}

// A triangle's unit normal from its winding (counter-clockwise front,
// glTF), in double; false when it has none (zero area, or not finite).
bool triangleNormal(std::span<const glm::vec3> positions, const uint32_t* tri, glm::dvec3& n) {
    const glm::dvec3 p0(positions[tri[0]]), p1(positions[tri[1]]), p2(positions[tri[2]]);
    const glm::dvec3 c = glm::cross(p1 - p0, p2 - p0);
    const double length = glm::length(c);
    if (!(length > 0.0) || !std::isfinite(length)) return false;
    n = c / length;
    return true;
}

} // namespace

FacetSplit splitIntoFacets(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                           const FacetSettings& settings) {
    FacetSplit split;
    const size_t triangles = indices.size() / 3;
    if (triangles < settings.minTriangles) return split;
    // Each triangle's bin (kBins: the remainder) and the bins' normal sums.
    std::vector<uint8_t> bin(triangles, uint8_t(kBins));
    std::vector<glm::dvec3> normals(triangles);
    std::array<glm::dvec3, kBins> sum{};
    std::array<uint32_t, kBins> count{};
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t* tri = &indices[3 * t];
        if (tri[0] >= positions.size() || tri[1] >= positions.size() || tri[2] >= positions.size()) continue;
        if (!triangleNormal(positions, tri, normals[t])) continue;
        const uint32_t b = binOf(normals[t]);
        bin[t] = uint8_t(b);
        sum[b] += normals[t];
        ++count[b];
    }
    // Each bin's axis: the mean of its normals, then the mean of those
    // within maxSpread of it, so that a few stray triangles do not tilt it.
    // Triangles further than maxSpread from the axis join the remainder;
    // a bin left with fewer than minTriangles joins it whole.
    std::array<Facet, kBins> facets{};
    std::array<bool, kBins> kept{};
    const double maxSpread = double(settings.maxSpread);
    for (uint32_t b = 0; b < kBins; ++b) {
        if (count[b] < settings.minTriangles || !(glm::length(sum[b]) > 0.0)) continue;
        glm::dvec3 axis = glm::normalize(sum[b]);
        glm::dvec3 close(0.0);
        for (size_t t = 0; t < triangles; ++t) {
            if (bin[t] == b && glm::length(normals[t] - axis) <= maxSpread) close += normals[t];
        }
        if (!(glm::length(close) > 0.0)) continue;
        axis = glm::normalize(close);
        uint32_t members = 0;
        for (size_t t = 0; t < triangles; ++t) {
            if (bin[t] != b) continue;
            if (glm::length(normals[t] - axis) <= maxSpread) {
                ++members;
            } else {
                bin[t] = uint8_t(kBins);
            }
        }
        if (members < settings.minTriangles) continue;
        double spread = 0.0, minPlane = std::numeric_limits<double>::max();
        glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        for (size_t t = 0; t < triangles; ++t) {
            if (bin[t] != b) continue;
            spread = std::max(spread, glm::length(normals[t] - axis));
            for (uint32_t k = 0; k < 3; ++k) {
                const glm::dvec3 v(positions[indices[3 * t + k]]);
                minPlane = std::min(minPlane, glm::dot(axis, v));
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
        }
        Facet& f = facets[b];
        f.cullable = true;
        f.axis = glm::vec3(axis);
        // Rounded outwards, so that the float values keep the bound.
        f.spread = std::nextafter(float(spread), std::numeric_limits<float>::max());
        f.minPlane = std::nextafter(float(minPlane), -std::numeric_limits<float>::max());
        const glm::dvec3 centre = 0.5 * (lo + hi);
        f.centre = glm::vec3(centre);
        f.radius = std::nextafter(float(glm::length(hi - centre) + glm::length(centre - glm::dvec3(f.centre))),
                                  std::numeric_limits<float>::max());
        kept[b] = true;
    }
    if (std::none_of(kept.begin(), kept.end(), [](bool k) { return k; })) return split;
    // The facets in bin order, then the remainder, each in the triangles'
    // own order.
    split.indices.reserve(triangles * 3);
    for (uint32_t b = 0; b <= kBins; ++b) {
        if (b < kBins && !kept[b]) continue;
        Facet f = b < kBins ? facets[b] : Facet{};
        f.firstIndex = uint32_t(split.indices.size());
        for (size_t t = 0; t < triangles; ++t) {
            const bool inRemainder = bin[t] == kBins || !kept[bin[t]];
            if (b < kBins ? bin[t] != b : !inRemainder) continue;
            split.indices.insert(split.indices.end(), &indices[3 * t], &indices[3 * t] + 3);
        }
        f.indexCount = uint32_t(split.indices.size()) - f.firstIndex;
        if (f.indexCount > 0) split.facets.push_back(f);
    }
    // Indices past the last whole triangle (none in a valid geometry) stay
    // at the end, unused by any facet: the split holds as many indices as
    // the geometry, so either can take its place in an index buffer.
    split.indices.insert(split.indices.end(), indices.begin() + 3 * triangles, indices.end());
    return split;
}

bool facetHidden(const Facet& facet, const glm::vec3& eye) {
    if (!facet.cullable) return false;
    // The bound of the header with |eye - centre| taken as its L1 norm (no
    // smaller, so the bound holds; no square root: this runs per facet and
    // instance every frame), less a margin for the rounding of the eye's
    // transform into mesh space and of the vertices onto the screen. A
    // non-finite eye compares false: kept.
    const glm::vec3 d = glm::abs(eye - facet.centre);
    const float reach = d.x + d.y + d.z + facet.radius;
    const float bound = glm::dot(facet.axis, eye) - facet.minPlane + facet.spread * reach;
    return bound < -1e-4f * reach;
}

} // namespace glint::scene
