#include "glint/scene/scene.h"

#include "glint/scene/error.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace glint::scene {

// ---------------------------------------------------------------------------
// Bounds
// ---------------------------------------------------------------------------

void Aabb::extend(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
}

void Aabb::extend(const Aabb& b) {
    if (!b.empty()) {
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
}

Aabb transformBounds(const Aabb& box, const glm::mat4& transform) {
    Aabb out;
    if (box.empty()) {
        return out;
    }
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p{(corner & 1) ? box.max.x : box.min.x, (corner & 2) ? box.max.y : box.min.y,
                          (corner & 4) ? box.max.z : box.min.z};
        out.extend(glm::vec3(transform * glm::vec4(p, 1.0f)));
    }
    return out;
}

float distanceToBounds(const Aabb& box, const glm::vec3& point) {
    if (box.empty()) {
        return std::numeric_limits<float>::infinity();
    }
    const glm::vec3 d = glm::max(glm::max(box.min - point, point - box.max), glm::vec3(0.0f));
    return glm::length(d);
}

// ---------------------------------------------------------------------------
// Textures
// ---------------------------------------------------------------------------

bool Texture::valid() const {
    const size_t texels = size_t(width) * height * 4;
    if (width == 0 || height == 0) {
        return false;
    }
    return format == TextureFormat::Rgba8 ? rgba8.size() == texels : rgba32f.size() == texels;
}

glm::vec4 Texture::texel(uint32_t x, uint32_t y) const {
    const size_t i = (size_t(y) * width + x) * 4;
    if (format == TextureFormat::Rgba8) {
        return glm::vec4(rgba8[i], rgba8[i + 1], rgba8[i + 2], rgba8[i + 3]) * (1.0f / 255.0f);
    }
    return {rgba32f[i], rgba32f[i + 1], rgba32f[i + 2], rgba32f[i + 3]};
}

namespace {

int64_t wrapCoordinate(int64_t i, int64_t size, Wrap wrap) {
    switch (wrap) {
    case Wrap::ClampToEdge: return std::clamp<int64_t>(i, 0, size - 1);
    case Wrap::MirroredRepeat: {
        const int64_t period = 2 * size;
        const int64_t m = ((i % period) + period) % period;
        return m < size ? m : period - 1 - m;
    }
    case Wrap::Repeat: break;
    }
    return ((i % size) + size) % size;
}

// Brings a coordinate into a small range with the same wrapped result, so
// that huge or non-finite texture coordinates cannot overflow the integer
// texel index.
float reduceCoordinate(float u, Wrap wrap) {
    if (!std::isfinite(u)) {
        return 0.0f;
    }
    switch (wrap) {
    case Wrap::ClampToEdge: return std::clamp(u, -1.0f, 2.0f);
    case Wrap::MirroredRepeat: return u - 2.0f * std::floor(u * 0.5f);
    case Wrap::Repeat: break;
    }
    return u - std::floor(u);
}

} // namespace

glm::vec4 sampleBilinear(const Texture& texture, glm::vec2 uv, Wrap wrapS, Wrap wrapT) {
    if (!texture.valid()) {
        return glm::vec4(1.0f);
    }
    const float x = reduceCoordinate(uv.x, wrapS) * float(texture.width) - 0.5f;
    const float y = reduceCoordinate(uv.y, wrapT) * float(texture.height) - 0.5f;
    const float fx = std::floor(x);
    const float fy = std::floor(y);
    const float tx = x - fx;
    const float ty = y - fy;
    const int64_t x0 = int64_t(fx);
    const int64_t y0 = int64_t(fy);
    const auto at = [&](int64_t xi, int64_t yi) {
        return texture.texel(uint32_t(wrapCoordinate(xi, texture.width, wrapS)),
                             uint32_t(wrapCoordinate(yi, texture.height, wrapT)));
    };
    const glm::vec4 top = glm::mix(at(x0, y0), at(x0 + 1, y0), tx);
    const glm::vec4 bottom = glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), tx);
    return glm::mix(top, bottom, ty);
}

// ---------------------------------------------------------------------------
// Meshes, nodes, animation
// ---------------------------------------------------------------------------

uint32_t reflectionLodIndex(const Mesh& mesh) {
    if (mesh.lods.empty()) {
        return 0;
    }
    const uint32_t last = uint32_t(mesh.lods.size() - 1);
    if (mesh.reflectionLod) {
        return std::min(*mesh.reflectionLod, last);
    }
    return std::min(1u, last);
}

uint64_t triangleCount(const MeshLod& lod) {
    uint64_t n = 0;
    for (const Geometry& g : lod.geometries) {
        n += g.triangleCount();
    }
    return n;
}

glm::mat4 Node::localTransform() const {
    if (matrix) {
        return *matrix;
    }
    return glm::translate(glm::mat4(1.0f), translation) * glm::mat4_cast(rotation) * glm::scale(glm::mat4(1.0f), scale);
}

float Animation::duration() const {
    float d = 0.0f;
    for (const AnimationSampler& s : samplers) {
        if (!s.times.empty()) {
            d = std::max(d, s.times.back());
        }
    }
    return d;
}

// ---------------------------------------------------------------------------
// Environment
// ---------------------------------------------------------------------------

glm::vec2 equirectUv(const glm::vec3& direction) {
    const glm::vec3 d = glm::normalize(direction);
    const float u = std::atan2(d.x, -d.z) / glm::two_pi<float>() + 0.5f;
    const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / glm::pi<float>();
    return {u, v};
}

glm::vec3 equirectDirection(const glm::vec2& uv) {
    const float phi = (uv.x - 0.5f) * glm::two_pi<float>();
    const float theta = uv.y * glm::pi<float>();
    const float s = std::sin(theta);
    return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

// ---------------------------------------------------------------------------
// Scene queries
// ---------------------------------------------------------------------------

const SceneView& findView(const Scene& scene, std::string_view nameOrIndex) {
    for (const SceneView& v : scene.views) {
        if (v.name == nameOrIndex) return v;
    }
    const std::string text(nameOrIndex);
    if (!text.empty() && text.find_first_not_of("0123456789") == std::string::npos && text.size() < 10) {
        const size_t index = std::stoul(text);
        if (index < scene.views.size()) return scene.views[index];
    }
    std::string names;
    for (size_t i = 0; i < scene.views.size(); ++i) {
        names += (i ? ", " : "") + std::to_string(i) + " '" + scene.views[i].name + "'";
    }
    throw SceneError(scene.name, "camera '" + text + "'",
                     scene.views.empty() ? "the scene has no cameras" : "no such camera (available: " + names + ")");
}

void useView(Scene& scene, const SceneView& view) {
    const SceneView copy = view;  // `view` may live in scene.views
    scene.lens = copy.lens;
    scene.cameraPath.keys = {{0.0f, copy.position, copy.target}};
}

uint64_t meshTriangleCount(const Scene& scene) {
    uint64_t n = 0;
    for (const Mesh& m : scene.meshes) {
        if (!m.lods.empty()) {
            n += triangleCount(m.lods[0]);
        }
    }
    return n;
}

uint64_t instancedTriangleCount(const Scene& scene) {
    uint64_t n = 0;
    for (const Instance& inst : scene.instances) {
        const Mesh& m = scene.meshes[inst.mesh];
        if (!m.lods.empty()) {
            n += triangleCount(m.lods[0]);
        }
    }
    return n;
}

AssetStamp assetStamp(const Scene& scene) {
    return {scene.assetRevision, scene.meshes.size(), scene.materials.size(), scene.textures.size()};
}

bool blended(const Scene& scene, const Geometry& geometry) {
    return geometry.material < scene.materials.size() &&
           scene.materials[geometry.material].alphaMode == AlphaMode::Blend;
}

Aabb instanceBounds(const Scene& scene, const Instance& instance) {
    const Mesh& mesh = scene.meshes[instance.mesh];
    if (instance.motion != Motion::Skinned || instance.skin == kNone) {
        return transformBounds(mesh.bounds, instance.transform);
    }
    const size_t joints = scene.skins[size_t(instance.skin)].joints.size();
    if (size_t(instance.jointOffset) + joints > scene.jointMatrices.size()) {
        return transformBounds(mesh.bounds, instance.transform);  // not prepared yet: bind pose
    }
    Aabb out;
    for (size_t j = 0; j < joints; ++j) {
        out.extend(transformBounds(mesh.bounds, instance.transform * scene.jointMatrices[instance.jointOffset + j]));
    }
    return out;
}

Aabb sceneBounds(const Scene& scene) {
    Aabb out;
    for (const Instance& inst : scene.instances) {
        out.extend(transformBounds(scene.meshes[inst.mesh].bounds, inst.transform));
    }
    return out;
}

// ---------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------

namespace {

std::string named(const char* kind, size_t index, const std::string& name) {
    std::string s = std::string(kind) + " " + std::to_string(index);
    if (!name.empty()) {
        s += " ('" + name + "')";
    }
    return s;
}

void checkTextureRef(const Scene& scene, const TextureRef& ref, const std::string& element) {
    if (ref.texture == kNone) {
        return;
    }
    if (ref.texture < 0 || size_t(ref.texture) >= scene.textures.size()) {
        throw SceneError(scene.name, element,
                         "texture " + std::to_string(ref.texture) + " out of range (" +
                             std::to_string(scene.textures.size()) + " textures)");
    }
    if (ref.texCoord > 1) {
        throw SceneError(scene.name, element, "texCoord " + std::to_string(ref.texCoord) + " (only 0 and 1 exist)");
    }
}

void checkGeometry(const Scene& scene, const Geometry& g, const std::string& element) {
    const size_t n = g.positions.size();
    const auto checkLength = [&](size_t size, const char* what) {
        if (size != 0 && size != n) {
            throw SceneError(scene.name, element,
                             std::string(what) + " has " + std::to_string(size) + " entries for " + std::to_string(n) +
                                 " positions");
        }
    };
    checkLength(g.normals.size(), "normals");
    checkLength(g.tangents.size(), "tangents");
    checkLength(g.texcoords0.size(), "texcoords0");
    checkLength(g.texcoords1.size(), "texcoords1");
    checkLength(g.colors.size(), "colors");
    checkLength(g.joints.size(), "joints");
    checkLength(g.weights.size(), "weights");
    if (g.joints.size() != g.weights.size()) {
        throw SceneError(scene.name, element, "joints and weights differ in length");
    }
    for (size_t t = 0; t < g.morphTargets.size(); ++t) {
        const std::string target = "morph target " + std::to_string(t) + " ";
        checkLength(g.morphTargets[t].positions.size(), (target + "positions").c_str());
        checkLength(g.morphTargets[t].normals.size(), (target + "normals").c_str());
        checkLength(g.morphTargets[t].tangents.size(), (target + "tangents").c_str());
    }
    if (g.indices.size() % 3 != 0) {
        throw SceneError(scene.name, element,
                         "index count " + std::to_string(g.indices.size()) + " is not a multiple of 3");
    }
    for (size_t i = 0; i < g.indices.size(); ++i) {
        if (g.indices[i] >= n) {
            throw SceneError(scene.name, element,
                             "index " + std::to_string(g.indices[i]) + " at position " + std::to_string(i) +
                                 " >= vertex count " + std::to_string(n));
        }
    }
    if (g.material >= scene.materials.size()) {
        throw SceneError(scene.name, element,
                         "material " + std::to_string(g.material) + " out of range (" +
                             std::to_string(scene.materials.size()) + " materials)");
    }
}

} // namespace

void validateScene(const Scene& scene) {
    for (size_t t = 0; t < scene.textures.size(); ++t) {
        if (!scene.textures[t].valid()) {
            throw SceneError(scene.name, named("texture", t, scene.textures[t].name),
                             "texel data does not match its size and format");
        }
    }
    for (size_t m = 0; m < scene.materials.size(); ++m) {
        const Material& mat = scene.materials[m];
        const std::string element = named("material", m, mat.name);
        for (const TextureRef* ref : {&mat.baseColorTexture, &mat.metallicRoughnessTexture, &mat.normalTexture,
                                      &mat.emissiveTexture, &mat.occlusionTexture}) {
            checkTextureRef(scene, *ref, element);
        }
    }
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const std::string element = named("mesh", m, mesh.name);
        if (mesh.lods.empty()) {
            throw SceneError(scene.name, element, "has no LOD");
        }
        if (mesh.reflectionLod && *mesh.reflectionLod >= mesh.lods.size()) {
            throw SceneError(scene.name, element,
                             "reflection LOD " + std::to_string(*mesh.reflectionLod) + " of " +
                                 std::to_string(mesh.lods.size()) + " LODs");
        }
        for (size_t l = 0; l < mesh.lods.size(); ++l) {
            for (size_t g = 0; g < mesh.lods[l].geometries.size(); ++g) {
                const Geometry& geometry = mesh.lods[l].geometries[g];
                const std::string geometryElement =
                    element + " lod " + std::to_string(l) + " geometry " + std::to_string(g);
                checkGeometry(scene, geometry, geometryElement);
                if (l == 0 && geometry.morphTargets.size() != mesh.morphWeights.size()) {
                    throw SceneError(scene.name, geometryElement,
                                     std::to_string(geometry.morphTargets.size()) + " morph targets for the mesh's " +
                                         std::to_string(mesh.morphWeights.size()) + " weights");
                }
            }
        }
    }
    for (size_t n = 0; n < scene.nodes.size(); ++n) {
        // Walking up must reach a root within nodes.size() steps, or there
        // is a cycle.
        int32_t p = scene.nodes[n].parent;
        for (size_t steps = 0; p != kNone; ++steps) {
            if (p < 0 || size_t(p) >= scene.nodes.size()) {
                throw SceneError(scene.name, named("node", n, scene.nodes[n].name),
                                 "parent " + std::to_string(p) + " out of range");
            }
            if (steps > scene.nodes.size()) {
                throw SceneError(scene.name, named("node", n, scene.nodes[n].name), "is its own ancestor (cycle)");
            }
            p = scene.nodes[size_t(p)].parent;
        }
    }
    for (size_t s = 0; s < scene.skins.size(); ++s) {
        const Skin& skin = scene.skins[s];
        for (uint32_t j : skin.joints) {
            if (j >= scene.nodes.size()) {
                throw SceneError(scene.name, named("skin", s, skin.name),
                                 "joint node " + std::to_string(j) + " out of range");
            }
        }
        if (skin.inverseBindMatrices.size() != skin.joints.size()) {
            throw SceneError(scene.name, named("skin", s, skin.name),
                             std::to_string(skin.inverseBindMatrices.size()) + " inverse bind matrices for " +
                                 std::to_string(skin.joints.size()) + " joints");
        }
    }
    for (size_t a = 0; a < scene.animations.size(); ++a) {
        const Animation& anim = scene.animations[a];
        const std::string element = named("animation", a, anim.name);
        for (const AnimationSampler& s : anim.samplers) {
            const size_t perKey = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
            if (s.weightCount > 0 && (s.times.empty() || s.weights.size() != s.times.size() * perKey * s.weightCount)) {
                throw SceneError(scene.name, element,
                                 "sampler has " + std::to_string(s.times.size()) + " keys and " +
                                     std::to_string(s.weights.size()) + " weights for " +
                                     std::to_string(s.weightCount) + " morph targets");
            }
            if (s.weightCount == 0 && (s.times.empty() || s.values.size() != s.times.size() * perKey)) {
                throw SceneError(scene.name, element,
                                 "sampler has " + std::to_string(s.times.size()) + " keys and " +
                                     std::to_string(s.values.size()) + " values");
            }
            if (!std::is_sorted(s.times.begin(), s.times.end())) {
                throw SceneError(scene.name, element, "sampler key times decrease");
            }
        }
        for (const AnimationChannel& c : anim.channels) {
            if (c.sampler >= anim.samplers.size() || c.node >= scene.nodes.size()) {
                throw SceneError(scene.name, element,
                                 "channel refers to sampler " + std::to_string(c.sampler) + " / node " +
                                     std::to_string(c.node) + " out of range");
            }
            const bool weights = c.path == AnimationPath::Weights;
            if (weights != (anim.samplers[c.sampler].weightCount > 0) ||
                (weights && anim.samplers[c.sampler].weightCount != scene.nodes[c.node].morphWeights.size())) {
                throw SceneError(scene.name, element,
                                 "channel of node " + std::to_string(c.node) +
                                     ": morph weight samplers drive exactly the node's morph weights");
            }
        }
    }
    for (const AnimationPlayback& p : scene.playbacks) {
        if (p.animation >= scene.animations.size()) {
            throw SceneError(scene.name, "playback", "animation " + std::to_string(p.animation) + " out of range");
        }
    }
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const std::string element = named("instance", i, inst.name);
        if (inst.mesh >= scene.meshes.size()) {
            throw SceneError(scene.name, element, "mesh " + std::to_string(inst.mesh) + " out of range");
        }
        if (inst.node != kNone && (inst.node < 0 || size_t(inst.node) >= scene.nodes.size())) {
            throw SceneError(scene.name, element, "node " + std::to_string(inst.node) + " out of range");
        }
        if (!inst.morphWeights.empty() && inst.morphWeights.size() != scene.meshes[inst.mesh].morphWeights.size()) {
            throw SceneError(scene.name, element,
                             std::to_string(inst.morphWeights.size()) + " morph weights for the mesh's " +
                                 std::to_string(scene.meshes[inst.mesh].morphWeights.size()) + " targets");
        }
        const bool hasSkin = inst.skin != kNone;
        if (hasSkin != (inst.motion == Motion::Skinned)) {
            throw SceneError(scene.name, element, "a skin is required for, and only for, Motion::Skinned");
        }
        if (hasSkin) {
            if (inst.skin < 0 || size_t(inst.skin) >= scene.skins.size()) {
                throw SceneError(scene.name, element, "skin " + std::to_string(inst.skin) + " out of range");
            }
            const size_t joints = scene.skins[size_t(inst.skin)].joints.size();
            for (const MeshLod& lod : scene.meshes[inst.mesh].lods) {
                for (const Geometry& g : lod.geometries) {
                    if (!g.skinned()) {
                        throw SceneError(scene.name, element, "skinned instance of a mesh without joints/weights");
                    }
                    for (const glm::u16vec4& j : g.joints) {
                        if (std::max({j.x, j.y, j.z, j.w}) >= joints) {
                            throw SceneError(scene.name, element,
                                             "vertex joint index beyond the skin's " + std::to_string(joints) +
                                                 " joints");
                        }
                    }
                }
            }
        }
    }
    if (scene.cameraNode != kNone && (scene.cameraNode < 0 || size_t(scene.cameraNode) >= scene.nodes.size())) {
        throw SceneError(scene.name, "cameraNode", std::to_string(scene.cameraNode) + " out of range");
    }
}

} // namespace glint::scene
