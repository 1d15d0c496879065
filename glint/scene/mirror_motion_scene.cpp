// The built-in "mirror-motion" (builtin_scenes.h): a bright object moving
// across a wet floor, then a camera moving past it; what reflections in
// motion are measured on (glint-bench --motion, the ghosting tests).

#include "glint/scene/builtin_scenes.h"

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/procedural_meshes.h"
#include "glint/scene/scene_builder.h"

#include <algorithm>

namespace glint::scene {

namespace {

// The object's x along its line at `seconds` (metres).
float objectX(float seconds) {
    if (seconds <= kMirrorMotion.objectStartSeconds) return kMirrorMotion.objectStartX;
    const float moved = std::min(seconds, kMirrorMotion.objectStopSeconds) - kMirrorMotion.objectStartSeconds;
    return kMirrorMotion.objectStartX + kMirrorMotion.objectSpeed * moved;
}

} // namespace

MirrorMotionLamp parseMirrorMotionLamp(std::string_view spec) {
    const size_t colon = spec.find(':');
    if (spec.substr(0, colon) != "mirror-motion") {
        throw SceneError(std::string(spec), "",
                         "not a mirror-motion scene (mirror-motion or mirror-motion:lamp=rigid|skinned|morphed)");
    }
    if (colon == std::string_view::npos) return MirrorMotionLamp::Rigid;
    const std::string_view option = spec.substr(colon + 1);
    const std::string_view key = option.substr(0, option.find('='));
    if (key != "lamp" || option.size() == key.size()) {
        throw SceneError(std::string(spec), std::string(option), "expected lamp=rigid, lamp=skinned or lamp=morphed");
    }
    const std::string_view how = option.substr(key.size() + 1);
    if (how == "rigid") return MirrorMotionLamp::Rigid;
    if (how == "skinned") return MirrorMotionLamp::Skinned;
    if (how == "morphed") return MirrorMotionLamp::Morphed;
    throw SceneError(std::string(spec), "lamp", "'" + std::string(how) + "' is not rigid, skinned or morphed");
}

Scene makeMirrorMotion(bool withObject, MirrorMotionLamp lampMotion) {
    SceneBuilder b("mirror-motion");
    Scene& s = b.scene;
    const MirrorMotionTimeline& m = kMirrorMotion;
    const uint32_t wet = b.material(makeMaterial("wet floor", {0.9f, 0.92f, 0.95f}, 1.0f, 0.1f));
    const uint32_t wall = b.material(makeMaterial("backdrop", {0.08f, 0.1f, 0.14f}, 0.0f, 0.8f));
    const uint32_t pillar = b.material(makeMaterial("pillar", {0.2f, 0.25f, 0.35f}, 0.0f, 0.5f));
    const uint32_t lamp = b.material(makeEmissive("moving lamp", {1.0f, 0.55f, 0.2f}, 6.0f));

    // A 16 m square of wet floor, a wall behind it and two still pillars, so the
    // reflection has still neighbours to be compared with.
    const uint32_t floor = b.mesh("wet floor", {{makeGrid({16, 16}, {4, 4}, wet)}});
    b.place("wet floor", floor, {0, 0, 0});
    const uint32_t backdrop = b.mesh("backdrop", {{makeBox({16.0f, 4.0f, 0.2f}, wall)}});
    b.place("backdrop", backdrop, {0, 2.0f, -6.0f});
    const uint32_t post = b.mesh("pillar", {{makeBox({0.3f, 1.6f, 0.3f}, pillar)}});
    b.place("pillar left", post, {-2.5f, 0.8f, -1.5f});
    b.place("pillar right", post, {2.5f, 0.8f, -1.5f});

    if (withObject) {
        Geometry box = makeBox({0.5f, 0.5f, 0.5f}, lamp);
        const glm::vec3 start(objectX(0.0f), m.objectHeight, m.objectZ);
        const uint32_t node = b.node("moving lamp", kNone, start);
        Animation slide;
        slide.name = "moving lamp";
        // Keys every 50 ms: the start and the stop fall on keys, so the
        // linear tracks are the piecewise-linear motion exactly.
        const uint32_t keys = uint32_t(m.loopSeconds * 20.0f) + 1;
        const auto moved = [&](float t) { return glm::vec3(objectX(t), m.objectHeight, m.objectZ) - start; };
        switch (lampMotion) {
        case MirrorMotionLamp::Rigid: {
            b.instance("moving lamp", b.mesh("moving lamp", {{std::move(box)}}), node, Motion::Dynamic);
            b.translationTrack(slide, node, m.loopSeconds, keys, [&](float t) { return start + moved(t); });
            break;
        }
        case MirrorMotionLamp::Skinned: {
            // The instance stands; its one joint carries the box.
            bindToJoint(box, 0);
            const auto [skin, joints] = b.jointChain("moving lamp", node, glm::vec3(0.0f), 1);
            b.instance("moving lamp", b.mesh("moving lamp", {{std::move(box)}}), node, Motion::Skinned).skin = skin;
            b.translationTrack(slide, joints[0], m.loopSeconds, keys, moved);
            break;
        }
        case MirrorMotionLamp::Morphed: {
            // The instance stands; one morph target holds the whole slide,
            // its weight the fraction travelled.
            const float travel = m.objectSpeed * (m.objectStopSeconds - m.objectStartSeconds);
            MorphTarget target;
            target.positions.assign(box.positions.size(), glm::vec3(travel, 0.0f, 0.0f));
            box.morphTargets.push_back(std::move(target));
            const uint32_t mesh = b.mesh("moving lamp", {{std::move(box)}});
            b.scene.meshes[mesh].morphWeights = {0.0f};
            b.scene.nodes[node].morphWeights = {0.0f};
            b.instance("moving lamp", mesh, node, Motion::Dynamic);
            AnimationSampler weights;
            weights.interpolation = Interpolation::Linear;
            weights.weightCount = 1;
            for (uint32_t k = 0; k < keys; ++k) {
                const float t = m.loopSeconds * float(k) / float(keys - 1);
                weights.times.push_back(t);
                weights.weights.push_back(moved(t).x / travel);
            }
            slide.samplers.push_back(std::move(weights));
            slide.channels.push_back({uint32_t(slide.samplers.size() - 1), node, AnimationPath::Weights});
            break;
        }
        }
        b.play(std::move(slide));
    }

    s.sun.directionToLight = glm::normalize(glm::vec3(-0.4f, 0.8f, 0.45f));
    s.lens = {glm::radians(60.0f), 0.05f, kInfiniteFar};
    // Still until the camera's start, then a strafe to the right at a
    // constant speed (the keys before and after keep Catmull-Rom straight).
    const glm::vec3 eye(0.0f, 1.4f, 3.5f), target(0.0f, 0.1f, -1.0f);
    const glm::vec3 step(m.cameraSpeed * 0.5f, 0.0f, 0.0f);
    s.cameraPath.keys = {{0.0f, eye, target}};
    for (int k = 0; k <= 4; ++k) {
        const glm::vec3 offset = float(std::max(k - 1, 0)) * step;
        s.cameraPath.keys.push_back({m.cameraStartSeconds - 0.5f + 0.5f * float(k), eye + offset, target + offset});
    }
    s.views.push_back({"mirror", s.lens, eye, target});
    prepareScene(s);
    return s;
}

} // namespace glint::scene
