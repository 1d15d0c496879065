// glTF skins and animations -> scene skins, animation samplers and
// channels (translation, rotation, scale and morph target weights), every
// key time and output count checked. Members of the Converter
// (gltf_converter.h).

#include "glint/scene/gltf_converter.h"

#include <glm/gtc/type_ptr.hpp>

#include <map>
#include <tuple>

namespace glint::scene::gltf {

void Converter::convertSkins() {
    for (size_t s = 0; s < model_.skins.size(); ++s) {
        const tinygltf::Skin& src = model_.skins[s];
        const std::string where = element("skin", s, src.name);
        Skin skin;
        skin.name = src.name;
        if (src.joints.empty()) {
            fail(where, "has no joints");
        }
        for (int j : src.joints) {
            if (j < 0 || size_t(j) >= model_.nodes.size()) {
                fail(where, "joint node " + std::to_string(j) + " out of range (" +
                                std::to_string(model_.nodes.size()) + " nodes)");
            }
            skin.joints.push_back(uint32_t(j));
        }
        if (src.inverseBindMatrices == -1) {
            skin.inverseBindMatrices.assign(skin.joints.size(), glm::mat4(1.0f));
        } else {
            const CheckedAccessor c =
                checkAccessor(src.inverseBindMatrices, where + " inverseBindMatrices", inverseBindRule());
            if (c.count < skin.joints.size()) {
                fail(c.element,
                     std::to_string(c.count) + " matrices for " + std::to_string(skin.joints.size()) + " joints");
            }
            const std::vector<float> m = readFloats(c);
            for (size_t j = 0; j < skin.joints.size(); ++j) {
                skin.inverseBindMatrices.push_back(glm::make_mat4(m.data() + 16 * j));
            }
        }
        scene_.skins.push_back(std::move(skin));
    }
}

// `weightCount`: morph targets of the animated node's mesh (Weights only).
AnimationSampler Converter::convertSampler(const tinygltf::Animation& anim, int samplerIndex, AnimationPath path,
                                           const std::string& where, size_t weightCount) {
    const tinygltf::AnimationSampler& src = anim.samplers[size_t(samplerIndex)];
    const std::string samplerWhere = where + " sampler " + std::to_string(samplerIndex);
    AnimationSampler out;
    if (src.interpolation == "LINEAR" || src.interpolation.empty()) {
        out.interpolation = Interpolation::Linear;
    } else if (src.interpolation == "STEP") {
        out.interpolation = Interpolation::Step;
    } else if (src.interpolation == "CUBICSPLINE") {
        out.interpolation = Interpolation::CubicSpline;
    } else {
        fail(samplerWhere, "interpolation '" + src.interpolation + "'");
    }
    const CheckedAccessor input = checkAccessor(src.input, samplerWhere + " input", timesRule());
    out.times = readFloats(input);
    for (size_t k = 1; k < out.times.size(); ++k) {
        if (out.times[k] < out.times[k - 1]) {
            fail(input.element, "key times decrease at key " + std::to_string(k));
        }
    }
    const size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
    if (path == AnimationPath::Weights) {
        const CheckedAccessor output = checkAccessor(src.output, samplerWhere + " output", weightsOutputRule());
        if (output.count != input.count * perKey * weightCount) {
            fail(output.element, std::to_string(output.count) + " values for " + std::to_string(input.count) +
                                     " keys of " + std::to_string(weightCount) + " morph target weights" +
                                     (perKey == 3 ? " (CUBICSPLINE needs 3 per key)" : ""));
        }
        out.weights = readFloats(output);
        out.weightCount = uint32_t(weightCount);
        return out;
    }
    const CheckedAccessor output = checkAccessor(src.output, samplerWhere + " output", animationOutputRule(path));
    if (output.count != input.count * perKey) {
        fail(output.element, std::to_string(output.count) + " values for " + std::to_string(input.count) + " keys" +
                                 (perKey == 3 ? " (CUBICSPLINE needs 3 per key)" : ""));
    }
    out.values = toVectors<glm::vec4>(readFloats(output), output.components);
    return out;
}

void Converter::convertAnimations() {
    for (size_t a = 0; a < model_.animations.size(); ++a) {
        const tinygltf::Animation& src = model_.animations[a];
        const std::string where = element("animation", a, src.name);
        Animation anim;
        anim.name = src.name;
        // glTF samplers -> scene samplers, per path (a sampler's output
        // type follows the path of the channels using it).
        std::map<std::tuple<int, AnimationPath, size_t>, uint32_t> converted;
        for (size_t c = 0; c < src.channels.size(); ++c) {
            const tinygltf::AnimationChannel& ch = src.channels[c];
            const std::string channelWhere = where + " channel " + std::to_string(c);
            if (ch.sampler < 0 || size_t(ch.sampler) >= src.samplers.size()) {
                fail(channelWhere, "sampler " + std::to_string(ch.sampler) + " out of range (" +
                                       std::to_string(src.samplers.size()) + " samplers)");
            }
            if (ch.target_node == -1) {
                continue;  // targets something an extension defines
            }
            if (ch.target_node < 0 || size_t(ch.target_node) >= model_.nodes.size()) {
                fail(channelWhere, "target node " + std::to_string(ch.target_node) + " out of range (" +
                                       std::to_string(model_.nodes.size()) + " nodes)");
            }
            AnimationPath path;
            if (ch.target_path == "translation") {
                path = AnimationPath::Translation;
            } else if (ch.target_path == "rotation") {
                path = AnimationPath::Rotation;
            } else if (ch.target_path == "scale") {
                path = AnimationPath::Scale;
            } else if (ch.target_path == "weights") {
                path = AnimationPath::Weights;
            } else {
                fail(channelWhere, "target path '" + ch.target_path + "'");
            }
            const size_t weightCount = scene_.nodes[size_t(ch.target_node)].morphWeights.size();
            if (path == AnimationPath::Weights && weightCount == 0) {
                fail(channelWhere, "animates the weights of node " + std::to_string(ch.target_node) +
                                       ", whose mesh has no morph targets");
            }
            if (path != AnimationPath::Weights && scene_.nodes[size_t(ch.target_node)].matrix) {
                fail(channelWhere, "targets node " + std::to_string(ch.target_node) +
                                       ", which has a matrix (glTF allows animating TRS nodes only)");
            }
            const size_t keyWeights = path == AnimationPath::Weights ? weightCount : 0;
            const auto key = std::make_tuple(ch.sampler, path, keyWeights);
            auto it = converted.find(key);
            if (it == converted.end()) {
                it = converted.emplace(key, uint32_t(anim.samplers.size())).first;
                anim.samplers.push_back(convertSampler(src, ch.sampler, path, where, keyWeights));
            }
            anim.channels.push_back({it->second, uint32_t(ch.target_node), path});
            (path == AnimationPath::Weights ? morphedNodes_ : animatedNodes_).insert(uint32_t(ch.target_node));
        }
        scene_.animations.push_back(std::move(anim));
    }
    if (!scene_.animations.empty()) {
        scene_.playbacks.push_back({0, 1.0f, true});
    }
}

} // namespace glint::scene::gltf
