#include "glint/scene/animation.h"

#include "glint/scene/error.h"
#include "glint/scene/mesh_tools.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>

namespace glint::scene {

namespace {

glm::quat toQuat(const glm::vec4& v) {
    return glm::quat(v.w, v.x, v.y, v.z);
}

glm::vec4 fromQuat(const glm::quat& q) {
    return {q.x, q.y, q.z, q.w};
}

glm::vec4 normalizedRotation(const glm::vec4& v) {
    const float len = glm::length(v);
    return len > 0.0f ? v / len : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
}

} // namespace

glm::vec4 sampleAnimation(const AnimationSampler& sampler, AnimationPath path, float seconds) {
    const std::vector<float>& times = sampler.times;
    const bool cubic = sampler.interpolation == Interpolation::CubicSpline;
    const size_t stride = cubic ? 3 : 1;
    const size_t valueOffset = cubic ? 1 : 0;  // the value between the in- and out-tangent
    if (times.empty() || sampler.values.size() < times.size() * stride) {
        return path == AnimationPath::Rotation ? glm::vec4(0, 0, 0, 1)
                                               : glm::vec4(path == AnimationPath::Scale ? 1.0f : 0.0f);
    }
    const auto value = [&](size_t key) { return sampler.values[key * stride + valueOffset]; };
    const auto finish = [&](const glm::vec4& v) { return path == AnimationPath::Rotation ? normalizedRotation(v) : v; };

    if (!(seconds > times.front())) {  // also catches NaN
        return finish(value(0));
    }
    if (seconds >= times.back()) {
        return finish(value(times.size() - 1));
    }
    // First key after `seconds`; exists and is > 0 given the checks above.
    const size_t k1 = size_t(std::upper_bound(times.begin(), times.end(), seconds) - times.begin());
    const size_t k0 = k1 - 1;
    const float dt = times[k1] - times[k0];
    const float s = dt > 0.0f ? (seconds - times[k0]) / dt : 0.0f;

    switch (sampler.interpolation) {
    case Interpolation::Step: return finish(value(k0));
    case Interpolation::Linear:
        if (path == AnimationPath::Rotation) {
            // glm::slerp takes the shorter arc (it flips the second quaternion
            // when the dot product is negative), as glTF requires.
            return fromQuat(glm::normalize(glm::slerp(toQuat(value(k0)), toQuat(value(k1)), s)));
        }
        return glm::mix(value(k0), value(k1), s);
    case Interpolation::CubicSpline: {
        // glTF 2.0 Appendix C: Hermite spline with tangents scaled by the
        // key interval.
        const glm::vec4 p0 = value(k0);
        const glm::vec4 m0 = sampler.values[k0 * 3 + 2] * dt;  // out-tangent of k0
        const glm::vec4 p1 = value(k1);
        const glm::vec4 m1 = sampler.values[k1 * 3 + 0] * dt;  // in-tangent of k1
        const float s2 = s * s;
        const float s3 = s2 * s;
        const glm::vec4 v = (2.0f * s3 - 3.0f * s2 + 1.0f) * p0 + (s3 - 2.0f * s2 + s) * m0 +
                            (-2.0f * s3 + 3.0f * s2) * p1 + (s3 - s2) * m1;
        return finish(v);
    }
    }
    return finish(value(k0));
}

void sampleMorphWeights(const AnimationSampler& sampler, float seconds, std::span<float> out) {
    const size_t count = sampler.weightCount;
    const std::vector<float>& times = sampler.times;
    const bool cubic = sampler.interpolation == Interpolation::CubicSpline;
    const size_t stride = cubic ? 3 : 1;
    if (times.empty() || count == 0 || sampler.weights.size() < times.size() * stride * count) {
        return;
    }
    // Element w of the value (cubic: in-tangent 0, value 1, out-tangent 2) of `key`.
    const auto at = [&](size_t key, size_t part, size_t w) { return sampler.weights[(key * stride + part) * count + w]; };
    const size_t valuePart = cubic ? 1 : 0;
    const size_t n = std::min(out.size(), count);
    if (!(seconds > times.front()) || seconds >= times.back()) {  // also catches NaN
        const size_t key = seconds >= times.back() ? times.size() - 1 : 0;
        for (size_t w = 0; w < n; ++w) out[w] = at(key, valuePart, w);
        return;
    }
    const size_t k1 = size_t(std::upper_bound(times.begin(), times.end(), seconds) - times.begin());
    const size_t k0 = k1 - 1;
    const float dt = times[k1] - times[k0];
    const float s = dt > 0.0f ? (seconds - times[k0]) / dt : 0.0f;
    for (size_t w = 0; w < n; ++w) {
        switch (sampler.interpolation) {
        case Interpolation::Step: out[w] = at(k0, 0, w); break;
        case Interpolation::Linear: out[w] = at(k0, 0, w) + (at(k1, 0, w) - at(k0, 0, w)) * s; break;
        case Interpolation::CubicSpline: {
            // The same Hermite basis as sampleAnimation.
            const float s2 = s * s;
            const float s3 = s2 * s;
            out[w] = (2.0f * s3 - 3.0f * s2 + 1.0f) * at(k0, 1, w) + (s3 - 2.0f * s2 + s) * at(k0, 2, w) * dt +
                     (-2.0f * s3 + 3.0f * s2) * at(k1, 1, w) + (s3 - s2) * at(k1, 0, w) * dt;
            break;
        }
        }
    }
}

Geometry morphedGeometry(const Geometry& base, std::span<const float> weights) {
    Geometry g = base;
    const size_t targets = std::min(weights.size(), base.morphTargets.size());
    for (size_t t = 0; t < targets; ++t) {
        const float w = weights[t];
        const MorphTarget& target = base.morphTargets[t];
        if (w == 0.0f) continue;
        for (size_t v = 0; v < target.positions.size() && v < g.positions.size(); ++v) {
            g.positions[v] += w * target.positions[v];
        }
        for (size_t v = 0; v < target.normals.size() && v < g.normals.size(); ++v) {
            g.normals[v] += w * target.normals[v];
        }
        for (size_t v = 0; v < target.tangents.size() && v < g.tangents.size(); ++v) {
            g.tangents[v] += glm::vec4(w * target.tangents[v], 0.0f);
        }
    }
    if (targets > 0) {
        for (glm::vec3& n : g.normals) {
            const float len = glm::length(n);
            n = len > 0.0f ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
        }
        for (glm::vec4& t : g.tangents) {
            const float len = glm::length(glm::vec3(t));
            t = len > 0.0f ? glm::vec4(glm::vec3(t) / len, t.w) : glm::vec4(1.0f, 0.0f, 0.0f, t.w);
        }
        g.bounds = computeBounds(g.positions);
    }
    return g;
}

void applyAnimation(const Animation& animation, float seconds, std::span<Node> nodes) {
    for (const AnimationChannel& channel : animation.channels) {
        if (channel.sampler >= animation.samplers.size() || channel.node >= nodes.size()) {
            continue;  // validateScene reports these; evaluation just skips them
        }
        Node& node = nodes[channel.node];
        if (channel.path == AnimationPath::Weights) {
            sampleMorphWeights(animation.samplers[channel.sampler], seconds, node.morphWeights);
            continue;
        }
        const glm::vec4 v = sampleAnimation(animation.samplers[channel.sampler], channel.path, seconds);
        switch (channel.path) {
        case AnimationPath::Translation: node.translation = glm::vec3(v); break;
        case AnimationPath::Rotation: node.rotation = toQuat(v); break;
        case AnimationPath::Scale: node.scale = glm::vec3(v); break;
        case AnimationPath::Weights: break;
        }
    }
}

std::vector<glm::mat4> worldTransforms(std::span<const Node> nodes) {
    std::vector<glm::mat4> world(nodes.size(), glm::mat4(1.0f));
    std::vector<uint8_t> done(nodes.size(), 0);
    std::vector<size_t> chain;
    for (size_t i = 0; i < nodes.size(); ++i) {
        // Walk up to the first finished ancestor (or a root), then fill in
        // the world transforms on the way back down.
        chain.clear();
        size_t n = i;
        while (!done[n]) {
            chain.push_back(n);
            if (chain.size() > nodes.size()) {
                throw SceneError("", "node " + std::to_string(i), "is its own ancestor (cycle)");
            }
            const int32_t p = nodes[n].parent;
            if (p == kNone) {
                break;
            }
            if (p < 0 || size_t(p) >= nodes.size()) {
                throw SceneError("", "node " + std::to_string(n), "parent " + std::to_string(p) + " out of range");
            }
            n = size_t(p);
        }
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const int32_t p = nodes[*it].parent;
            world[*it] = p == kNone ? nodes[*it].localTransform() : world[size_t(p)] * nodes[*it].localTransform();
            done[*it] = 1;
        }
    }
    return world;
}

void computeJointMatrices(const Skin& skin, std::span<const glm::mat4> world, const glm::mat4& instanceWorld,
                          std::span<glm::mat4> out) {
    const glm::mat4 toObject = glm::inverse(instanceWorld);
    for (size_t j = 0; j < skin.joints.size() && j < out.size(); ++j) {
        out[j] = toObject * world[skin.joints[j]] * skin.inverseBindMatrices[j];
    }
}

namespace {

// `trackDeformation`: bump deformVersion where joints changed since last
// frame (not while preparing, when there is no last frame).
void evaluate(Scene& scene, double seconds, const Camera* camera, bool trackDeformation) {
    if (camera && scene.cameraNode != kNone) {
        scene.nodes[size_t(scene.cameraNode)].matrix = glm::inverse(camera->view);
    }
    for (const AnimationPlayback& playback : scene.playbacks) {
        const Animation& animation = scene.animations[playback.animation];
        double t = seconds * double(playback.speed);
        const double duration = animation.duration();
        if (playback.loop && duration > 0.0) {
            t = std::fmod(t, duration);
            if (t < 0.0) {
                t += duration;
            }
        }
        applyAnimation(animation, float(t), scene.nodes);
    }
    const std::vector<glm::mat4> world = worldTransforms(scene.nodes);
    for (Instance& inst : scene.instances) {
        if (inst.node != kNone) {
            inst.transform = world[size_t(inst.node)];
            const std::vector<float>& weights = scene.nodes[size_t(inst.node)].morphWeights;
            if (!inst.morphWeights.empty() && weights.size() == inst.morphWeights.size() &&
                weights != inst.morphWeights) {
                inst.morphWeights = weights;
                if (trackDeformation) {
                    ++inst.deformVersion;
                }
            }
        }
    }
    for (Instance& inst : scene.instances) {
        if (inst.motion != Motion::Skinned) {
            continue;
        }
        const Skin& skin = scene.skins[size_t(inst.skin)];
        const std::span<glm::mat4> joints(scene.jointMatrices.data() + inst.jointOffset, skin.joints.size());
        computeJointMatrices(skin, world, inst.transform, joints);
        if (trackDeformation &&
            !std::equal(joints.begin(), joints.end(), scene.previousJointMatrices.begin() + inst.jointOffset)) {
            ++inst.deformVersion;
        }
    }
    scene.time = seconds;
}

} // namespace

void prepareScene(Scene& scene, double seconds) {
    validateScene(scene);
    for (Mesh& mesh : scene.meshes) {
        for (MeshLod& lod : mesh.lods) {
            for (Geometry& g : lod.geometries) {
                g.bounds = computeBounds(g.positions);
            }
        }
        mesh.bounds = Aabb{};
        for (const Geometry& g : mesh.lods[0].geometries) {
            mesh.bounds.extend(g.bounds);
            // Every shape the morph targets reach with weights in [0, 1]
            // (the usual range; glTF allows others): per vertex, the base
            // plus each target's negative or positive displacement.
            if (g.morphTargets.empty()) continue;
            for (size_t v = 0; v < g.positions.size(); ++v) {
                glm::vec3 low = g.positions[v], high = g.positions[v];
                for (const MorphTarget& target : g.morphTargets) {
                    if (v < target.positions.size()) {
                        low += glm::min(target.positions[v], glm::vec3(0.0f));
                        high += glm::max(target.positions[v], glm::vec3(0.0f));
                    }
                }
                mesh.bounds.extend(low);
                mesh.bounds.extend(high);
            }
        }
    }
    uint32_t palette = 0;
    for (Instance& inst : scene.instances) {
        if (inst.morphWeights.empty()) {
            inst.morphWeights = scene.meshes[inst.mesh].morphWeights;
        }
        if (inst.motion == Motion::Skinned) {
            inst.jointOffset = palette;
            palette += uint32_t(scene.skins[size_t(inst.skin)].joints.size());
        }
    }
    scene.jointMatrices.assign(palette, glm::mat4(1.0f));
    scene.previousJointMatrices.assign(palette, glm::mat4(1.0f));
    evaluate(scene, seconds, nullptr, false);
    scene.previousJointMatrices = scene.jointMatrices;
    for (Instance& inst : scene.instances) {
        inst.previousTransform = inst.transform;
        inst.previousMorphWeights = inst.morphWeights;
    }
}

void advanceScene(Scene& scene, double seconds, const Camera* camera) {
    for (Instance& inst : scene.instances) {
        inst.previousTransform = inst.transform;
        inst.previousMorphWeights = inst.morphWeights;
    }
    scene.previousJointMatrices = scene.jointMatrices;
    evaluate(scene, seconds, camera, true);
}

} // namespace glint::scene
