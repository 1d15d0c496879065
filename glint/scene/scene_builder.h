#pragma once
// What the built-in scenes (builtin_scenes.cpp, city_scene.cpp) are built
// with: deterministic noise for generated textures, material makers and
// SceneBuilder, which keeps the index bookkeeping of nodes, meshes,
// instances, skins and sampled animation tracks in one place. Internal to
// glint/scene.

#include "glint/scene/animation.h"
#include "glint/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace glint::scene {

// Deterministic hash of a lattice point -> [0, 1), identical on every run.
float hash01(int32_t x, int32_t y, uint32_t seed);
// Value noise on a lattice of `period` cells that wraps, so textures tile.
float valueNoise(float x, float y, int32_t period, uint32_t seed);
// Four octaves of valueNoise over the unit square (tiling), in [0, 1].
float fbm(float u, float v, uint32_t seed);
uint8_t toByte(float v);
uint8_t toSrgbByte(float linear);

Material makeMaterial(const std::string& name, const glm::vec3& baseColor, float metallic, float roughness);
Material makeEmissive(const std::string& name, const glm::vec3& color, float strength);
glm::quat axisAngle(const glm::vec3& axis, float radians);
Geometry transformed(Geometry g, const glm::mat4& m);
glm::mat4 translation(const glm::vec3& t);

// Builds a scene: nodes, meshes, instances, skins and sampled animation
// tracks, keeping the index bookkeeping in one place.
class SceneBuilder {
public:
    explicit SceneBuilder(std::string name) { scene.name = std::move(name); }

    uint32_t material(Material m) {
        scene.materials.push_back(std::move(m));
        return uint32_t(scene.materials.size() - 1);
    }

    int32_t texture(Texture t) {
        scene.textures.push_back(std::move(t));
        return int32_t(scene.textures.size() - 1);
    }

    uint32_t mesh(std::string name, std::vector<std::vector<Geometry>> lods) {
        Mesh m;
        m.name = std::move(name);
        for (std::vector<Geometry>& lod : lods) {
            m.lods.push_back({std::move(lod)});
        }
        scene.meshes.push_back(std::move(m));
        return uint32_t(scene.meshes.size() - 1);
    }

    uint32_t node(std::string name, int32_t parent, const glm::vec3& translation,
                  const glm::quat& rotation = glm::quat(1, 0, 0, 0), const glm::vec3& scale = glm::vec3(1.0f)) {
        Node n;
        n.name = std::move(name);
        n.parent = parent;
        n.translation = translation;
        n.rotation = rotation;
        n.scale = scale;
        scene.nodes.push_back(std::move(n));
        return uint32_t(scene.nodes.size() - 1);
    }

    Instance& instance(std::string name, uint32_t meshIndex, uint32_t nodeIndex, Motion motion = Motion::Static) {
        Instance inst;
        inst.name = std::move(name);
        inst.mesh = meshIndex;
        inst.node = int32_t(nodeIndex);
        inst.motion = motion;
        scene.instances.push_back(std::move(inst));
        return scene.instances.back();
    }

    // A static instance at `translation` with its own node.
    Instance& place(const std::string& name, uint32_t meshIndex, const glm::vec3& translation,
                    const glm::quat& rotation = glm::quat(1, 0, 0, 0), const glm::vec3& scale = glm::vec3(1.0f)) {
        return instance(name, meshIndex, node(name, kNone, translation, rotation, scale));
    }

    // A chain of `count` joints below `instanceNode`, `step` apart, and the
    // skin binding them in the current (rest) pose: inverse bind =
    // inverse(joint world) * instance world, so the rest pose skins to the
    // unskinned mesh placed by the instance node.
    std::pair<int32_t, std::vector<uint32_t>> jointChain(const std::string& name, uint32_t instanceNode,
                                                         const glm::vec3& step, uint32_t count) {
        std::vector<uint32_t> joints;
        int32_t parent = int32_t(instanceNode);
        for (uint32_t k = 0; k < count; ++k) {
            joints.push_back(node(name + "_joint" + std::to_string(k), parent, k == 0 ? glm::vec3(0.0f) : step));
            parent = int32_t(joints.back());
        }
        const std::vector<glm::mat4> world = worldTransforms(scene.nodes);
        Skin skin;
        skin.name = name;
        skin.joints = joints;
        for (uint32_t j : joints) {
            skin.inverseBindMatrices.push_back(glm::inverse(world[j]) * world[instanceNode]);
        }
        scene.skins.push_back(std::move(skin));
        return {int32_t(scene.skins.size() - 1), joints};
    }

    // Samples `f` (seconds -> value) at `keys` evenly spaced keys over
    // `duration` into a LINEAR track of `animation`.
    void track(Animation& animation, uint32_t nodeIndex, AnimationPath path, float duration, uint32_t keys,
               const std::function<glm::vec4(float)>& f) {
        AnimationSampler sampler;
        sampler.interpolation = Interpolation::Linear;
        for (uint32_t k = 0; k < keys; ++k) {
            const float t = duration * float(k) / float(keys - 1);
            sampler.times.push_back(t);
            sampler.values.push_back(f(t));
        }
        animation.samplers.push_back(std::move(sampler));
        animation.channels.push_back({uint32_t(animation.samplers.size() - 1), nodeIndex, path});
    }

    // A LINEAR track of `animation` through the given keys (times in
    // seconds, non-decreasing; values as AnimationSampler::values).
    void keyedTrack(Animation& animation, uint32_t nodeIndex, AnimationPath path, std::vector<float> times,
                    std::vector<glm::vec4> values) {
        AnimationSampler sampler;
        sampler.interpolation = Interpolation::Linear;
        sampler.times = std::move(times);
        sampler.values = std::move(values);
        animation.samplers.push_back(std::move(sampler));
        animation.channels.push_back({uint32_t(animation.samplers.size() - 1), nodeIndex, path});
    }

    void rotationTrack(Animation& animation, uint32_t nodeIndex, float duration, uint32_t keys,
                       const std::function<glm::quat(float)>& f) {
        track(animation, nodeIndex, AnimationPath::Rotation, duration, keys, [&](float t) {
            const glm::quat q = f(t);
            return glm::vec4(q.x, q.y, q.z, q.w);
        });
    }

    void translationTrack(Animation& animation, uint32_t nodeIndex, float duration, uint32_t keys,
                          const std::function<glm::vec3(float)>& f) {
        track(animation, nodeIndex, AnimationPath::Translation, duration, keys,
              [&](float t) { return glm::vec4(f(t), 0.0f); });
    }

    void play(Animation animation) {
        scene.animations.push_back(std::move(animation));
        scene.playbacks.push_back({uint32_t(scene.animations.size() - 1), 1.0f, true});
    }

    Scene scene;
};

} // namespace glint::scene
