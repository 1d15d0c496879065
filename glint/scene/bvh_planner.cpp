#include "glint/scene/bvh_planner.h"

#include "glint/scene/error.h"

#include "glint/packing.h"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <set>
#include <sstream>

namespace glint::scene {

std::string_view reasonName(BlasBuildReason reason) {
    switch (reason) {
    case BlasBuildReason::FirstInRange: return "first in range";
    case BlasBuildReason::Deformed: return "deformed";
    case BlasBuildReason::FirstPerson: return "first person";
    }
    return "?";
}

std::string_view reasonName(BlasDropReason reason) {
    switch (reason) {
    case BlasDropReason::ObjectRemoved: return "object removed";
    case BlasDropReason::Evicted: return "evicted";
    case BlasDropReason::AssetsEdited: return "assets edited";
    }
    return "?";
}

const BlasDesc* BvhPlan::find(BlasId id) const {
    const auto it = std::lower_bound(blases.begin(), blases.end(), id,
                                     [](const BlasDesc& b, BlasId value) { return b.id < value; });
    return it != blases.end() && it->id == id ? &*it : nullptr;
}

std::string formatStats(const BvhStats& s) {
    std::ostringstream out;
    out << "BLAS built " << s.built << ", rebuilt " << s.rebuilt << " (skinned " << s.rebuiltSkinned
        << ", first person " << s.rebuiltFirstPerson << "), dropped " << s.dropped << "; skipped: unchanged "
        << s.skippedUnchanged << ", out of range " << s.skippedOutOfRange << ", over budget " << s.deferredBudget
        << ", over skinned budget " << s.deferredSkinnedBudget << ", first builds waiting " << s.deferredFirstBuilds
        << "; static reused " << s.staticReused
        << "; instances in range " << s.instancesInRange << ", culled " << s.instancesCulled << " ("
        << s.instancesWithoutBlas << " without BLAS), awaiting their BLAS " << s.instancesAwaitingBlas << ", moved "
        << s.instancesMoved << "; TLAS " << s.tlasInstances
        << ", resident BLAS " << s.residentBlases << ", pool " << s.poolTriangles << " triangles";
    return out.str();
}

std::vector<std::vector<uint32_t>> partitionGeometries(const MeshLod& lod, uint32_t maxGeometries) {
    const uint32_t count = uint32_t(lod.geometries.size());
    maxGeometries = std::max(maxGeometries, 1u);
    std::vector<std::vector<uint32_t>> parts;
    if (count == 0) {
        return parts;
    }
    if (count <= maxGeometries) {
        parts.emplace_back(count);
        for (uint32_t g = 0; g < count; ++g) {
            parts[0][g] = g;
        }
        return parts;
    }
    // Material groups in order of first appearance.
    std::vector<std::vector<uint32_t>> groups;
    std::map<uint32_t, size_t> groupOf;
    for (uint32_t g = 0; g < count; ++g) {
        const auto [it, inserted] = groupOf.emplace(lod.geometries[g].material, groups.size());
        if (inserted) {
            groups.emplace_back();
        }
        groups[it->second].push_back(g);
    }
    for (std::vector<uint32_t>& group : groups) {
        // A material with more geometries than fit one BLAS fills whole BLASes.
        while (group.size() > maxGeometries) {
            parts.emplace_back(group.begin(), group.begin() + maxGeometries);
            group.erase(group.begin(), group.begin() + maxGeometries);
        }
        const auto fit = std::find_if(parts.begin(), parts.end(), [&](const std::vector<uint32_t>& p) {
            return p.size() + group.size() <= maxGeometries;
        });
        if (fit != parts.end()) {
            fit->insert(fit->end(), group.begin(), group.end());
        } else {
            parts.push_back(group);
        }
    }
    return parts;
}

// ---------------------------------------------------------------------------
// Pool allocator
// ---------------------------------------------------------------------------

uint32_t PoolAllocator::allocate(uint32_t triangles) {
    for (auto it = free_.begin(); it != free_.end(); ++it) {
        if (it->second >= triangles) {
            const uint32_t offset = it->first;
            const uint32_t rest = it->second - triangles;
            free_.erase(it);
            if (rest > 0) {
                free_.emplace(offset + triangles, rest);
            }
            return offset;
        }
    }
    // Grow; a free range touching the end is extended instead of skipped.
    if (!free_.empty()) {
        auto last = std::prev(free_.end());
        if (last->first + last->second == end_) {
            const uint32_t offset = last->first;
            end_ = offset + triangles;
            free_.erase(last);
            return offset;
        }
    }
    const uint32_t offset = end_;
    end_ += triangles;
    return offset;
}

void PoolAllocator::insertFree(uint32_t offset, uint32_t triangles) {
    auto next = free_.lower_bound(offset);
    if (next != free_.end() && offset + triangles == next->first) {
        triangles += next->second;
        next = free_.erase(next);
    }
    if (next != free_.begin()) {
        auto prev = std::prev(next);
        if (prev->first + prev->second == offset) {
            prev->second += triangles;
            return;
        }
    }
    free_.emplace(offset, triangles);
}

void PoolAllocator::release(uint32_t offset, uint32_t triangles, uint64_t reusableFrom) {
    if (triangles > 0) {
        pending_.push_back({offset, triangles, reusableFrom});
    }
}

void PoolAllocator::advance(uint64_t frame) {
    auto due = std::stable_partition(pending_.begin(), pending_.end(),
                                     [&](const Pending& p) { return p.reusableFrom > frame; });
    for (auto it = due; it != pending_.end(); ++it) {
        insertFree(it->offset, it->triangles);
    }
    pending_.erase(due, pending_.end());
}

// ---------------------------------------------------------------------------
// Planner
// ---------------------------------------------------------------------------

BvhPlanner::BvhPlanner(const BvhSettings& settings) : settings_(settings) {}

uint64_t deformationStamp(const Scene& scene, const Instance& instance) {
    // FNV-1a over each part's 32-bit words (every part is made of them):
    // it runs every frame for every deformable BLAS, skinned palettes
    // included, so a word at a time rather than a byte.
    uint64_t hash = 14695981039346656037ull;
    const auto add = [&](const void* data, size_t bytes) {
        const auto* p = static_cast<const uint8_t*>(data);
        for (size_t i = 0; i + 4 <= bytes; i += 4) {
            uint32_t word;
            std::memcpy(&word, p + i, 4);
            hash = (hash ^ word) * 1099511628211ull;
        }
    };
    add(&instance.deformVersion, sizeof(instance.deformVersion));
    add(&instance.mesh, sizeof(instance.mesh));
    add(&instance.skin, sizeof(instance.skin));
    add(instance.morphWeights.data(), instance.morphWeights.size() * sizeof(float));
    if (instance.motion == Motion::Skinned && instance.skin != kNone && size_t(instance.skin) < scene.skins.size()) {
        const size_t count = scene.skins[size_t(instance.skin)].joints.size();
        if (size_t(instance.jointOffset) + count <= scene.jointMatrices.size()) {
            add(scene.jointMatrices.data() + instance.jointOffset, count * sizeof(glm::mat4));
        }
    }
    return hash;
}

void BvhPlanner::reset() {
    resident_.clear();
    roundRobin_.clear();
    pool_ = PoolAllocator{};
    nextId_ = 1;
    havePlanned_ = false;
    assets_ = {};
}

BvhPlan BvhPlanner::plan(const Scene& scene, const glm::vec3& cameraPosition, uint64_t frame, float radius) {
    if (!(radius > 0.0f)) {
        throw SceneError(scene.name, "BVH planner", "radius " + std::to_string(radius) + ": must be positive");
    }
    if (havePlanned_ && frame <= lastFrame_) {
        throw SceneError(scene.name, "BVH planner",
                         "frame " + std::to_string(frame) + " after frame " + std::to_string(lastFrame_) +
                             " (frames must increase; call reset() to start over)");
    }
    havePlanned_ = true;
    lastFrame_ = frame;
    pool_.advance(frame);

    BvhPlan plan;
    plan.frame = frame;
    BvhStats& stats = plan.stats;

    // --- Edited assets: every BLAS was built from what changed. -----------
    if (const AssetStamp assets = assetStamp(scene); assets != assets_) {
        for (const auto& [key, r] : resident_) {
            pool_.release(r.desc.poolOffset, r.desc.triangleCount, frame + settings_.framesInFlight);
            plan.drops.push_back({r.desc.id, BlasDropReason::AssetsEdited});
            ++stats.dropped;
        }
        resident_.clear();
        roundRobin_.clear();
        assets_ = assets;
    }

    // --- Objects: each mesh's reflection LOD split into BLAS parts. -------
    std::vector<uint32_t> lodOf(scene.meshes.size());
    std::vector<std::vector<std::vector<uint32_t>>> partsOf(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        if (mesh.lods.empty()) {
            continue;
        }
        lodOf[m] = settings_.reflectionLods ? reflectionLodIndex(mesh) : 0;
        const MeshLod& lod = mesh.lods[lodOf[m]];
        // A part mixing single- and double-sided materials splits in two:
        // back-face culling is an instance's, not a geometry's.
        const auto doubleSided = [&](uint32_t g) {
            const uint32_t material = lod.geometries[g].material;
            return material < scene.materials.size() && scene.materials[material].doubleSided;
        };
        for (std::vector<uint32_t>& part : partitionGeometries(lod, settings_.maxGeometriesPerBlas)) {
            // A geometry without triangles would be an empty BLAS geometry;
            // blended ones (glTF alphaMode BLEND) are drawn over the frame
            // by the transparent pass and neither reflected nor shadowing
            // (passes/transparent.h).
            std::erase_if(part, [&](uint32_t g) {
                const Geometry& geometry = lod.geometries[g];
                return geometry.triangleCount() == 0 || blended(scene, geometry);
            });
            std::vector<uint32_t> twoSided;
            std::copy_if(part.begin(), part.end(), std::back_inserter(twoSided), doubleSided);
            std::erase_if(part, doubleSided);
            for (std::vector<uint32_t>* p : {&part, &twoSided}) {
                if (!p->empty()) partsOf[m].push_back(std::move(*p));
            }
        }
    }

    // --- Which instance is in range, and which BLAS keys exist. -----------
    struct InstanceView {
        std::vector<Key> keys;
        bool inRange = false;
    };
    std::vector<InstanceView> views(scene.instances.size());
    std::map<Key, bool> existing;  // key -> some instance of it is in range
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh >= scene.meshes.size()) {
            throw SceneError(scene.name, "instance " + std::to_string(i),
                             "mesh " + std::to_string(inst.mesh) + " out of range");
        }
        const bool deformable = inst.motion != Motion::Static;
        const float reach = inst.longRange ? std::max(settings_.longRangeRadius, radius) : radius;
        views[i].inRange = distanceToBounds(instanceBounds(scene, inst), cameraPosition) <= reach;
        for (uint32_t p = 0; p < partsOf[inst.mesh].size(); ++p) {
            const Key key{deformable, deformable ? uint32_t(i) : inst.mesh, inst.mesh, lodOf[inst.mesh], p};
            views[i].keys.push_back(key);
            existing[key] = existing[key] || views[i].inRange;
        }
    }
    const auto motionOf = [&](const Key& key) {
        return key.perInstance ? scene.instances[key.owner].motion : Motion::Static;
    };

    // --- Drops. -------------------------------------------------------------
    for (auto it = resident_.begin(); it != resident_.end();) {
        const auto use = existing.find(it->first);
        const bool removed = use == existing.end() || motionOf(it->first) != it->second.desc.motion;
        if (use != existing.end() && use->second) {
            it->second.lastInRange = frame;
        }
        const bool evicted = !removed && settings_.evictAfterFramesOutside > 0 &&
                             frame - it->second.lastInRange >= settings_.evictAfterFramesOutside;
        if (removed || evicted) {
            const BlasDesc& desc = it->second.desc;
            pool_.release(desc.poolOffset, desc.triangleCount, frame + settings_.framesInFlight);
            plan.drops.push_back({desc.id, removed ? BlasDropReason::ObjectRemoved : BlasDropReason::Evicted});
            ++stats.dropped;
            it = resident_.erase(it);
        } else {
            ++it;
        }
    }

    // --- First builds: objects within their radius that have no BLAS. ------
    // Candidates in priority order (first person, largest on screen,
    // nearest; a shared BLAS takes its best instance's place), built while
    // the frame's first-build budget lasts.
    struct Candidate {
        Key key;
        uint32_t instance = 0;
        bool firstPerson = false;
        float screenSize = 0.0f;  // bounding radius over distance
        float distance = 0.0f;
    };
    const auto better = [](const Candidate& a, const Candidate& b) {
        if (a.firstPerson != b.firstPerson) return a.firstPerson;
        if (a.screenSize != b.screenSize) return a.screenSize > b.screenSize;
        return a.distance < b.distance;
    };
    std::map<Key, Candidate> candidates;
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        if (!views[i].inRange) {
            continue;
        }
        const Instance& inst = scene.instances[i];
        const Aabb box = instanceBounds(scene, inst);
        Candidate c;
        c.instance = uint32_t(i);
        c.firstPerson = inst.firstPerson;
        c.distance = distanceToBounds(box, cameraPosition);
        c.screenSize = 0.5f * glm::length(box.max - box.min) / std::max(c.distance, 1e-3f);
        for (const Key& key : views[i].keys) {
            if (resident_.count(key)) {
                continue;
            }
            c.key = key;
            const auto [it, inserted] = candidates.emplace(key, c);
            if (!inserted && better(c, it->second)) {
                it->second = c;
            }
        }
    }
    std::vector<Candidate> order;
    for (const auto& [key, c] : candidates) order.push_back(c);
    std::stable_sort(order.begin(), order.end(), better);
    std::set<BlasId> builtThisFrame;
    uint32_t firstBuilds = 0;
    uint64_t firstBuildTriangles = 0;
    for (const Candidate& c : order) {
        const Key& key = c.key;
        const Instance& inst = scene.instances[c.instance];
        const MeshLod& lod = scene.meshes[inst.mesh].lods[lodOf[inst.mesh]];
        uint32_t triangles = 0;
        for (uint32_t g : partsOf[inst.mesh][key.part]) {
            triangles += lod.geometries[g].triangleCount();
        }
        const bool fits = firstBuilds < settings_.maxFirstBuildsPerFrame &&
                          (firstBuilds == 0 || firstBuildTriangles + triangles <= settings_.maxFirstBuildTrianglesPerFrame);
        if (!fits) {
            ++stats.deferredFirstBuilds;
            continue;
        }
        ++firstBuilds;
        firstBuildTriangles += triangles;
        Resident r;
        BlasDesc& desc = r.desc;
        desc.id = nextId_++;
        desc.mesh = inst.mesh;
        desc.lod = key.lod;
        desc.part = key.part;
        desc.instance = key.perInstance ? int32_t(c.instance) : kNone;
        desc.motion = motionOf(key);
        for (uint32_t g : partsOf[inst.mesh][key.part]) {
            desc.geometries.push_back({g, lod.geometries[g].material, lod.geometries[g].triangleCount(), 0});
            desc.triangleCount += lod.geometries[g].triangleCount();
        }
        const uint32_t firstMaterial = desc.geometries.front().material;
        desc.doubleSided = firstMaterial < scene.materials.size() && scene.materials[firstMaterial].doubleSided;
        desc.poolOffset = pool_.allocate(desc.triangleCount);
        uint32_t offset = desc.poolOffset;
        for (BlasGeometry& g : desc.geometries) {
            g.poolOffset = offset;
            offset += g.triangleCount;
        }
        r.builtShape = key.perInstance ? deformationStamp(scene, inst) : 0;
        r.lastInRange = frame;
        r.lastBuilt = frame;
        plan.builds.push_back({desc.id, BlasBuildReason::FirstInRange});
        stats.builtTriangles += desc.triangleCount;
        builtThisFrame.insert(desc.id);
        ++stats.built;
        resident_.emplace(key, std::move(r));
    }

    // --- Rebuilds: first person, then the round-robin loop, in budget. -----
    // The loop holds every deformable, non-first-person BLAS; new ones join
    // at the back, rebuilt ones move to the back.
    {
        std::set<Key> queued(roundRobin_.begin(), roundRobin_.end());
        std::erase_if(roundRobin_,
                      [&](const Key& k) { return !resident_.count(k) || scene.instances[k.owner].firstPerson; });
        for (const auto& [key, r] : resident_) {
            if (key.perInstance && !scene.instances[key.owner].firstPerson && !queued.count(key)) {
                roundRobin_.push_back(key);
            }
        }
    }
    uint32_t rebuilds = 0;
    uint32_t skinnedRebuilds = 0;
    // Returns true when rebuilt; counts why not otherwise.
    const auto consider = [&](const Key& key, Resident& r, BlasBuildReason reason) {
        if (builtThisFrame.count(r.desc.id)) {
            return false;
        }
        const Instance& inst = scene.instances[key.owner];
        const uint64_t shape = deformationStamp(scene, inst);
        if (shape == r.builtShape) {
            ++stats.skippedUnchanged;
            return false;
        }
        if (!views[key.owner].inRange) {
            ++stats.skippedOutOfRange;
            return false;
        }
        const bool skinned = r.desc.motion == Motion::Skinned;
        if (rebuilds >= settings_.maxRebuildsPerFrame) {
            ++stats.deferredBudget;
            return false;
        }
        if (skinned && skinnedRebuilds >= settings_.maxSkinnedRebuildsPerFrame) {
            ++stats.deferredSkinnedBudget;
            return false;
        }
        ++rebuilds;
        ++stats.rebuilt;
        if (skinned) {
            ++skinnedRebuilds;
            ++stats.rebuiltSkinned;
        }
        if (reason == BlasBuildReason::FirstPerson) {
            ++stats.rebuiltFirstPerson;
        }
        r.builtShape = shape;
        r.lastBuilt = frame;
        plan.builds.push_back({r.desc.id, reason});
        stats.builtTriangles += r.desc.triangleCount;
        builtThisFrame.insert(r.desc.id);
        return true;
    };
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        if (!scene.instances[i].firstPerson || scene.instances[i].motion == Motion::Static) {
            continue;
        }
        for (const Key& key : views[i].keys) {
            if (const auto it = resident_.find(key); it != resident_.end()) {
                consider(key, it->second, BlasBuildReason::FirstPerson);
            }
        }
    }
    {
        std::vector<Key> waiting, rebuilt;
        for (const Key& key : roundRobin_) {
            (consider(key, resident_.at(key), BlasBuildReason::Deformed) ? rebuilt : waiting).push_back(key);
        }
        roundRobin_ = std::move(waiting);
        roundRobin_.insert(roundRobin_.end(), rebuilt.begin(), rebuilt.end());
    }

    // --- The TLAS and the primitive offset table. ---------------------------
    std::set<BlasId> staticInTlas;
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (!views[i].inRange) {
            ++stats.instancesCulled;
            const bool hasBlas = std::any_of(views[i].keys.begin(), views[i].keys.end(),
                                             [&](const Key& k) { return resident_.count(k) > 0; });
            stats.instancesWithoutBlas += hasBlas ? 0 : 1;
            continue;
        }
        ++stats.instancesInRange;
        if (inst.transform != inst.previousTransform) {
            ++stats.instancesMoved;
        }
        // Whole objects only: one whose BLASes are not all built waits.
        if (!std::all_of(views[i].keys.begin(), views[i].keys.end(), [&](const Key& k) { return resident_.count(k) > 0; })) {
            ++stats.instancesAwaitingBlas;
            continue;
        }
        const uint8_t mask = uint8_t(inst.firstPerson ? shader::kInstanceMaskFirstPerson
                                     : inst.longRange ? shader::kInstanceMaskLongRange
                                                      : shader::kInstanceMaskWorld);
        for (const Key& key : views[i].keys) {
            const BlasDesc& desc = resident_.at(key).desc;
            if (desc.motion == Motion::Static && !builtThisFrame.count(desc.id)) {
                staticInTlas.insert(desc.id);
            }
            TlasInstance t;
            t.sceneInstance = uint32_t(i);
            t.blas = desc.id;
            t.transform = inst.transform;
            t.customIndex = uint32_t(plan.primitiveOffsets.size());
            t.sbtOffset = shader::kSbtOffsetPackedPrimitives;
            t.mask = mask;
            t.doubleSided = desc.doubleSided;
            if (t.customIndex + desc.geometries.size() > (1u << 24)) {
                throw SceneError(scene.name, "BVH planner", "primitive offset table exceeds the 24-bit custom index");
            }
            for (const BlasGeometry& g : desc.geometries) {
                plan.primitiveOffsets.push_back(g.poolOffset);
            }
            plan.tlas.push_back(t);
        }
    }
    stats.staticReused = uint32_t(staticInTlas.size());
    stats.tlasInstances = uint32_t(plan.tlas.size());

    plan.particleCount = uint32_t(scene.particles.size());
    plan.particleTlas = plan.particleCount > 0;

    plan.blases.reserve(resident_.size());
    for (const auto& [key, r] : resident_) {
        plan.blases.push_back(r.desc);
    }
    std::sort(plan.blases.begin(), plan.blases.end(), [](const BlasDesc& a, const BlasDesc& b) { return a.id < b.id; });
    plan.poolTriangles = pool_.size();
    stats.residentBlases = uint32_t(plan.blases.size());
    stats.poolTriangles = plan.poolTriangles;
    return plan;
}

} // namespace glint::scene
