// tinygltf model -> scene model. Every accessor is checked against its
// bufferView and buffer (offset, count, stride, component type, element
// type) and every index against what it indexes before anything is read;
// tinygltf itself checks none of it.
//
// The conversion is one Converter (gltf_converter.h) whose members are
// split by what they convert: this file has the entry point, the node
// hierarchy and the active scene (instances, the sun, cameras); accessors,
// materials, meshes and animations have files of their own
// (gltf_accessors.cpp, gltf_materials.cpp, gltf_meshes.cpp,
// gltf_animation.cpp).

#include "glint/scene/gltf_converter.h"

#include "glint/scene/animation.h"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

namespace glint::scene::gltf {

std::string element(const char* kind, size_t index, const std::string& name) {
    std::string s = std::string(kind) + " " + std::to_string(index);
    return name.empty() ? s : s + " ('" + name + "')";
}

Scene Converter::run() {
    scene_.name = context_.file;
    convertMaterials();
    convertMeshes();
    convertNodes();
    convertSkins();
    convertAnimations();
    instantiate();
    return std::move(scene_);
}

// ----- nodes -------------------------------------------------------------

void Converter::convertNodes() {
    scene_.nodes.resize(model_.nodes.size());
    for (size_t i = 0; i < model_.nodes.size(); ++i) {
        const tinygltf::Node& src = model_.nodes[i];
        const std::string where = element("node", i, src.name);
        Node& node = scene_.nodes[i];
        node.name = src.name;
        const auto numbers = [&](const std::vector<double>& values, size_t expected, const char* what) {
            if (!values.empty() && values.size() != expected) {
                fail(where, std::string(what) + " has " + std::to_string(values.size()) + " numbers (expected " +
                                std::to_string(expected) + ")");
            }
            for (double v : values) {
                finiteNumber(v, where, what);
            }
            return !values.empty();
        };
        if (numbers(src.matrix, 16, "matrix")) {
            std::array<float, 16> m{};
            std::transform(src.matrix.begin(), src.matrix.end(), m.begin(), [](double d) { return float(d); });
            node.matrix = glm::make_mat4(m.data());  // glTF matrices are column-major, as glm's
        }
        if (numbers(src.translation, 3, "translation")) {
            node.translation = glm::vec3(src.translation[0], src.translation[1], src.translation[2]);
        }
        if (numbers(src.rotation, 4, "rotation")) {
            const glm::vec4 q(src.rotation[0], src.rotation[1], src.rotation[2], src.rotation[3]);
            const float len = glm::length(q);
            if (!(len > 0.0f)) {
                fail(where, "rotation is a zero quaternion");
            }
            node.rotation = glm::quat(q.w / len, q.x / len, q.y / len, q.z / len);
        }
        if (numbers(src.scale, 3, "scale")) {
            node.scale = glm::vec3(src.scale[0], src.scale[1], src.scale[2]);
        }
        if (src.mesh < -1 || src.mesh >= int(model_.meshes.size())) {
            fail(where, "mesh " + std::to_string(src.mesh) + " out of range (" +
                            std::to_string(model_.meshes.size()) + " meshes)");
        }
        if (src.mesh >= 0) {
            node.morphWeights = scene_.meshes[size_t(src.mesh)].morphWeights;
        }
        if (!src.weights.empty()) {
            if (src.mesh < 0) {
                fail(where, "has weights but no mesh");
            }
            if (src.weights.size() != node.morphWeights.size()) {
                fail(where, "weights has " + std::to_string(src.weights.size()) + " numbers for the " +
                                std::to_string(node.morphWeights.size()) + " morph targets of mesh " +
                                std::to_string(src.mesh));
            }
            for (size_t t = 0; t < src.weights.size(); ++t) {
                node.morphWeights[t] = finiteNumber(src.weights[t], where, "weights");
            }
        }
        if (src.skin < -1 || src.skin >= int(model_.skins.size())) {
            fail(where, "skin " + std::to_string(src.skin) + " out of range (" +
                            std::to_string(model_.skins.size()) + " skins)");
        }
        if (src.camera < -1 || src.camera >= int(model_.cameras.size())) {
            fail(where, "camera " + std::to_string(src.camera) + " out of range");
        }
    }
    for (size_t i = 0; i < model_.nodes.size(); ++i) {
        for (int child : model_.nodes[i].children) {
            const std::string where = element("node", i, model_.nodes[i].name);
            if (child < 0 || size_t(child) >= model_.nodes.size()) {
                fail(where, "child " + std::to_string(child) + " out of range (" +
                                std::to_string(model_.nodes.size()) + " nodes)");
            }
            if (size_t(child) == i) {
                fail(where, "is its own child");
            }
            Node& c = scene_.nodes[size_t(child)];
            if (c.parent != kNone) {
                fail(element("node", size_t(child), c.name),
                     "has two parents (nodes " + std::to_string(c.parent) + " and " + std::to_string(i) + ")");
            }
            c.parent = int32_t(i);
        }
    }
    for (size_t i = 0; i < scene_.nodes.size(); ++i) {
        int32_t p = scene_.nodes[i].parent;
        for (size_t steps = 0; p != kNone; ++steps) {
            if (steps > scene_.nodes.size()) {
                fail(element("node", i, scene_.nodes[i].name), "is its own ancestor (the hierarchy has a cycle)");
            }
            p = scene_.nodes[size_t(p)].parent;
        }
    }
}

// ----- the active scene ------------------------------------------------

bool Converter::animatedOrBelowAnimated(uint32_t node) const {
    for (int32_t n = int32_t(node); n != kNone; n = scene_.nodes[size_t(n)].parent) {
        if (animatedNodes_.count(uint32_t(n))) {
            return true;
        }
    }
    return false;
}

void Converter::instantiate() {
    std::vector<uint32_t> roots;
    if (model_.scenes.empty()) {
        for (size_t n = 0; n < scene_.nodes.size(); ++n) {
            if (scene_.nodes[n].parent == kNone) {
                roots.push_back(uint32_t(n));
            }
        }
    } else {
        const int index = model_.defaultScene == -1 ? 0 : model_.defaultScene;
        if (index < 0 || size_t(index) >= model_.scenes.size()) {
            fail("scene", "default scene " + std::to_string(index) + " out of range (" +
                              std::to_string(model_.scenes.size()) + " scenes)");
        }
        const std::string where = element("scene", size_t(index), model_.scenes[size_t(index)].name);
        std::set<int> seen;
        for (int n : model_.scenes[size_t(index)].nodes) {
            if (n < 0 || size_t(n) >= scene_.nodes.size()) {
                fail(where, "node " + std::to_string(n) + " out of range (" + std::to_string(scene_.nodes.size()) +
                                " nodes)");
            }
            if (scene_.nodes[size_t(n)].parent != kNone) {
                fail(where, "node " + std::to_string(n) + " is not a root (its parent is node " +
                                std::to_string(scene_.nodes[size_t(n)].parent) + ")");
            }
            if (!seen.insert(n).second) {
                fail(where, "lists node " + std::to_string(n) + " twice");
            }
            roots.push_back(uint32_t(n));
        }
    }
    std::vector<std::vector<uint32_t>> children(scene_.nodes.size());
    for (size_t n = 0; n < scene_.nodes.size(); ++n) {
        if (scene_.nodes[n].parent != kNone) {
            children[size_t(scene_.nodes[n].parent)].push_back(uint32_t(n));
        }
    }
    const std::vector<glm::mat4> world = worldTransforms(scene_.nodes);
    bool warnedLights = false;
    // Depth-first in document order, iteratively (no recursion on
    // untrusted depth).
    std::vector<uint32_t> stack(roots.rbegin(), roots.rend());
    while (!stack.empty()) {
        const uint32_t n = stack.back();
        stack.pop_back();
        const std::vector<uint32_t>& kids = children[n];
        stack.insert(stack.end(), kids.rbegin(), kids.rend());
        const tinygltf::Node& src = model_.nodes[n];
        instantiateNode(n, src, world[n]);
        lightFromNode(n, src, world[n], warnedLights);
        cameraFromNode(src, world[n]);
    }
}

void Converter::instantiateNode(uint32_t n, const tinygltf::Node& src, const glm::mat4& world) {
    if (src.mesh < 0) {
        return;
    }
    Instance inst;
    inst.name = src.name.empty() ? scene_.meshes[size_t(src.mesh)].name : src.name;
    inst.mesh = uint32_t(src.mesh);
    inst.node = int32_t(n);
    inst.transform = inst.previousTransform = world;
    // Morph weights deform the mesh: animated or not zero, the instance
    // gets a BLAS of its own with its shape (a shared static BLAS holds
    // the base shape), rebuilt when they change (deformVersion).
    inst.morphWeights = scene_.nodes[n].morphWeights;
    const bool morphed = morphedNodes_.count(n) != 0 ||
                         std::any_of(inst.morphWeights.begin(), inst.morphWeights.end(),
                                     [](float w) { return w != 0.0f; });
    inst.motion = animatedOrBelowAnimated(n) || morphed ? Motion::Dynamic : Motion::Static;
    if (src.skin >= 0) {
        const std::string where = element("node", n, src.name);
        const size_t joints = scene_.skins[size_t(src.skin)].joints.size();
        const Mesh& mesh = scene_.meshes[size_t(src.mesh)];
        bool skinnable = !mesh.lods[0].geometries.empty();
        for (const Geometry& g : mesh.lods[0].geometries) {
            skinnable = skinnable && g.skinned();
            for (size_t v = 0; v < g.joints.size(); ++v) {
                const glm::u16vec4 j = g.joints[v];
                if (std::max({j.x, j.y, j.z, j.w}) >= joints) {
                    fail(where, "mesh " + std::to_string(src.mesh) + " vertex " + std::to_string(v) +
                                    " uses joint " + std::to_string(std::max({j.x, j.y, j.z, j.w})) + " but skin " +
                                    std::to_string(src.skin) + " has " + std::to_string(joints) + " joints");
                }
            }
        }
        if (skinnable) {
            inst.motion = Motion::Skinned;
            inst.skin = src.skin;
        } else {
            warn(where, "has a skin but its mesh has no JOINTS_0/WEIGHTS_0; drawn rigid");
        }
    }
    scene_.instances.push_back(std::move(inst));
}

void Converter::lightFromNode(uint32_t n, const tinygltf::Node& src, const glm::mat4& world, bool& warnedLights) {
    const auto ext = src.extensions.find("KHR_lights_punctual");
    if (ext == src.extensions.end() || !ext->second.Get("light").IsNumber()) {
        return;
    }
    const double index = ext->second.Get("light").GetNumberAsDouble();
    const std::string where = element("node", n, src.name);
    if (!(index >= 0.0 && index < double(model_.lights.size())) || index != std::floor(index)) {
        fail(where, "KHR_lights_punctual light " + std::to_string(index) + " out of range (" +
                        std::to_string(model_.lights.size()) + " lights)");
    }
    const size_t light = size_t(index);
    const tinygltf::Light& l = model_.lights[light];
    if (l.type != "directional") {
        if (!warnedLights) {
            spdlog::info("{}: point and spot lights are not used (only a directional sun)", context_.file);
            warnedLights = true;
        }
        return;
    }
    if (sunFound_) {
        return;
    }
    const std::string lightWhere = element("light", light, l.name);
    // KHR_lights_punctual: a directional light shines along its node's -Z.
    const glm::vec3 shines = glm::vec3(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
    if (!(glm::length(shines) > 0.0f)) {
        fail(where, "the light's node transform is degenerate");
    }
    scene_.sun.directionToLight = -glm::normalize(shines);
    scene_.sun.color = factor<3>(l.color, glm::vec3(1.0f), lightWhere, "color");
    scene_.sun.illuminance = finiteNumber(l.intensity, lightWhere, "intensity");  // lux for directional lights
    sunFound_ = true;
}

// Every usable perspective camera becomes a named view; the first is
// also the scene's suggested view.
void Converter::cameraFromNode(const tinygltf::Node& src, const glm::mat4& world) {
    if (src.camera < 0 || model_.cameras[size_t(src.camera)].type != "perspective") {
        return;
    }
    const tinygltf::Camera& camera = model_.cameras[size_t(src.camera)];
    const tinygltf::PerspectiveCamera& p = camera.perspective;
    constexpr double kLargest = 1e30;  // keeps the float conversions defined
    if (!(p.yfov > 0.0 && p.yfov < 3.1) || !(p.znear > 0.0 && p.znear < kLargest) ||
        !(p.zfar >= 0.0 && p.zfar < kLargest)) {
        return;  // unusable; the loader frames the scene instead
    }
    const glm::vec3 position(world[3]);
    const glm::vec3 forward = -glm::vec3(world[2]);
    if (!(glm::length(forward) > 0.0f) || !std::isfinite(position.x + position.y + position.z)) {
        return;
    }
    SceneView view;
    view.name = !camera.name.empty() ? camera.name
                : !src.name.empty()  ? src.name
                                     : "camera " + std::to_string(scene_.views.size());
    view.lens.verticalFovRadians = float(p.yfov);
    view.lens.nearPlane = float(p.znear);
    view.lens.farPlane = p.zfar > p.znear ? float(p.zfar) : kInfiniteFar;
    view.position = position;
    view.target = position + glm::normalize(forward);
    scene_.views.push_back(view);
    if (!cameraFound_) {
        useView(scene_, view);
        cameraFound_ = true;
    }
}

Scene convertModel(const tinygltf::Model& model, LoadContext& context) {
    return Converter(model, context).run();
}

} // namespace glint::scene::gltf
