#include "glint/scene/reflection_lod.h"

#include "glint/scene/mesh_tools.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace glint::scene {

namespace {

constexpr uint32_t kUnused = UINT32_MAX;

// `source`'s entries at `kept`, in that order (empty stays empty).
template <class T> std::vector<T> gather(const std::vector<T>& source, const std::vector<uint32_t>& kept) {
    std::vector<T> out;
    if (source.empty()) return out;
    out.reserve(kept.size());
    for (const uint32_t k : kept) out.push_back(source[k]);
    return out;
}

} // namespace

Geometry simplifyGeometry(const Geometry& geometry, const ReflectionLodSettings& settings, float* relativeError) {
    const size_t indexCount = geometry.indices.size();
    const size_t targetTriangles =
        std::max<size_t>(1, size_t(double(geometry.triangleCount()) * double(settings.targetRatio)));
    std::vector<uint32_t> indices(indexCount);
    float error = 0.0f;
    // Borders stay where they are: an open edge moved would open a crack
    // against the neighbouring geometry of the mesh.
    const size_t count = geometry.positions.empty()
                             ? 0
                             : meshopt_simplify(indices.data(), geometry.indices.data(), indexCount,
                                                &geometry.positions[0].x, geometry.positions.size(), sizeof(glm::vec3),
                                                targetTriangles * 3, settings.maxError, meshopt_SimplifyLockBorder,
                                                &error);
    indices.resize(count);
    if (relativeError) *relativeError = error;

    // The vertices the triangles still use, in order of first use.
    std::vector<uint32_t> remap(geometry.positions.size(), kUnused);
    std::vector<uint32_t> kept;
    for (uint32_t& index : indices) {
        if (remap[index] == kUnused) {
            remap[index] = uint32_t(kept.size());
            kept.push_back(index);
        }
        index = remap[index];
    }
    Geometry out;
    out.material = geometry.material;
    out.indices = std::move(indices);
    out.positions = gather(geometry.positions, kept);
    out.normals = gather(geometry.normals, kept);
    out.tangents = gather(geometry.tangents, kept);
    out.texcoords0 = gather(geometry.texcoords0, kept);
    out.texcoords1 = gather(geometry.texcoords1, kept);
    out.colors = gather(geometry.colors, kept);
    out.joints = gather(geometry.joints, kept);
    out.weights = gather(geometry.weights, kept);
    for (const MorphTarget& target : geometry.morphTargets) {
        out.morphTargets.push_back(
            {gather(target.positions, kept), gather(target.normals, kept), gather(target.tangents, kept)});
    }
    out.bounds = computeBounds(out.positions);
    return out;
}

ReflectionLodStats generateReflectionLods(Scene& scene, const ReflectionLodSettings& settings) {
    if (!(settings.targetRatio > 0.0f && settings.targetRatio <= 1.0f) ||
        !(settings.maxError >= 0.0f && settings.maxError <= 1.0f)) {
        throw std::invalid_argument("reflection LODs: target ratio " + std::to_string(settings.targetRatio) +
                                    " must be in (0, 1] and error " + std::to_string(settings.maxError) +
                                    " in [0, 1]");
    }
    ReflectionLodStats stats;
    for (Mesh& mesh : scene.meshes) {
        if (mesh.lods.size() != 1 || mesh.reflectionLod) continue;
        const MeshLod& full = mesh.lods[0];
        MeshLod lod;
        uint64_t before = 0, after = 0;
        float largest = 0.0f;
        for (const Geometry& g : full.geometries) {
            before += g.triangleCount();
            if (g.triangleCount() < settings.minTriangles) {
                lod.geometries.push_back(g);
            } else {
                float error = 0.0f;
                lod.geometries.push_back(simplifyGeometry(g, settings, &error));
                largest = std::max(largest, error);
            }
            after += lod.geometries.back().triangleCount();
        }
        if (after >= before) continue;  // nothing simplified: one LOD serves both
        mesh.lods.push_back(std::move(lod));
        ++stats.meshes;
        stats.trianglesBefore += before;
        stats.trianglesAfter += after;
        stats.largestError = std::max(stats.largestError, largest);
    }
    return stats;
}

} // namespace glint::scene
