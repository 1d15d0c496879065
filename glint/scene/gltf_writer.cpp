#include "glint/scene/gltf_writer.h"

#include "glint/scene/error.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cstring>
#include <fstream>

namespace glint::scene {

namespace {

using Json = nlohmann::json;

// glTF enums (glTF 2.0 section 5).
constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

class BufferWriter {
public:
    // Appends `count` elements of `components` floats or uints and returns
    // the accessor index.
    template <typename T>
    int add(const std::vector<T>& data, const char* type, int componentType, int target, bool withBounds) {
        const size_t offset = bytes_.size();
        const size_t size = data.size() * sizeof(T);
        bytes_.resize(offset + size);
        std::memcpy(bytes_.data() + offset, data.data(), size);
        bytes_.resize((bytes_.size() + 3) & ~size_t(3));  // keep every view 4-byte aligned
        bufferViews_.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}, {"target", target}});
        Json accessor = {{"bufferView", bufferViews_.size() - 1},
                         {"componentType", componentType},
                         {"count", data.size()},
                         {"type", type}};
        if constexpr (std::is_same_v<T, glm::vec3>) {
            if (withBounds) {
                // POSITION accessors must carry min and max (glTF 2.0 3.7.2.1).
                glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
                for (const glm::vec3& p : data) {
                    lo = glm::min(lo, p);
                    hi = glm::max(hi, p);
                }
                accessor["min"] = {lo.x, lo.y, lo.z};
                accessor["max"] = {hi.x, hi.y, hi.z};
            }
        }
        accessors_.push_back(std::move(accessor));
        return int(accessors_.size() - 1);
    }

    const std::vector<uint8_t>& bytes() const { return bytes_; }
    Json& accessors() { return accessors_; }
    Json& bufferViews() { return bufferViews_; }

private:
    std::vector<uint8_t> bytes_;
    Json accessors_ = Json::array();
    Json bufferViews_ = Json::array();
};

Json matrixJson(const glm::mat4& m) {
    Json out = Json::array();
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
            out.push_back(m[c][r]);  // column-major, as glTF and glm
        }
    }
    return out;
}

Json materialJson(const Material& m, bool& usesEmissiveStrength) {
    Json out = {
        {"name", m.name},
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {m.baseColorFactor.r, m.baseColorFactor.g, m.baseColorFactor.b, m.baseColorFactor.a}},
          {"metallicFactor", m.metallicFactor},
          {"roughnessFactor", m.roughnessFactor}}},
        {"emissiveFactor", {m.emissiveFactor.r, m.emissiveFactor.g, m.emissiveFactor.b}},
        {"doubleSided", m.doubleSided}};
    if (m.alphaMode == AlphaMode::Mask) {
        out["alphaMode"] = "MASK";
        out["alphaCutoff"] = m.alphaCutoff;
    } else if (m.alphaMode == AlphaMode::Blend) {
        out["alphaMode"] = "BLEND";
    }
    if (m.emissiveStrength != 1.0f) {
        out["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", m.emissiveStrength}};
        usesEmissiveStrength = true;
    }
    return out;
}

void writeFile(const std::filesystem::path& path, const void* data, size_t size) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(static_cast<const char*>(data), std::streamsize(size));
    if (!out) {
        throw SceneError(path.string(), "", "cannot write the file");
    }
}

} // namespace

void writeGltf(const Scene& scene, const std::filesystem::path& gltfPath) {
    const std::filesystem::path binPath = std::filesystem::path(gltfPath).replace_extension(".bin");
    BufferWriter buffer;
    Json meshes = Json::array();
    for (const Mesh& mesh : scene.meshes) {
        Json primitives = Json::array();
        static const MeshLod kNoLod;
        for (const Geometry& g : (mesh.lods.empty() ? kNoLod : mesh.lods[0]).geometries) {
            if (g.positions.empty() || g.indices.empty()) {
                continue;
            }
            Json attributes = {{"POSITION", buffer.add(g.positions, "VEC3", kFloat, kArrayBuffer, true)}};
            if (!g.normals.empty()) {
                attributes["NORMAL"] = buffer.add(g.normals, "VEC3", kFloat, kArrayBuffer, false);
            }
            if (!g.texcoords0.empty()) {
                attributes["TEXCOORD_0"] = buffer.add(g.texcoords0, "VEC2", kFloat, kArrayBuffer, false);
            }
            primitives.push_back(
                {{"attributes", attributes},
                 {"indices", buffer.add(g.indices, "SCALAR", kUnsignedInt, kElementArrayBuffer, false)},
                 {"material", g.material},
                 {"mode", 4}});
        }
        meshes.push_back({{"name", mesh.name}, {"primitives", primitives}});
    }

    bool usesEmissiveStrength = false;
    Json materials = Json::array();
    for (const Material& m : scene.materials) {
        materials.push_back(materialJson(m, usesEmissiveStrength));
    }

    Json nodes = Json::array();
    Json roots = Json::array();
    for (const Instance& inst : scene.instances) {
        roots.push_back(nodes.size());
        nodes.push_back({{"name", inst.name}, {"mesh", inst.mesh}, {"matrix", matrixJson(inst.transform)}});
    }
    // The sun: a node whose -Z points where the light travels.
    const glm::vec3 toLight = glm::normalize(scene.sun.directionToLight);
    const glm::vec3 up = std::abs(toLight.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::mat4 sunNode = glm::inverse(glm::lookAtRH(glm::vec3(0.0f), -toLight, up));
    roots.push_back(nodes.size());
    nodes.push_back(
        {{"name", "sun"}, {"matrix", matrixJson(sunNode)}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});

    Json extensionsUsed = {"KHR_lights_punctual"};
    if (usesEmissiveStrength) {
        extensionsUsed.push_back("KHR_materials_emissive_strength");
    }
    const Json doc = {
        {"asset", {{"version", "2.0"}, {"generator", "Glint scene writer"}}},
        {"extensionsUsed", extensionsUsed},
        {"extensions",
         {{"KHR_lights_punctual",
           {{"lights",
             {{{"type", "directional"},
               {"name", "sun"},
               {"color", {scene.sun.color.r, scene.sun.color.g, scene.sun.color.b}},
               {"intensity", scene.sun.illuminance}}}}}}}},
        {"scene", 0},
        {"scenes", {{{"name", scene.name}, {"nodes", roots}}}},
        {"nodes", nodes},
        {"meshes", meshes},
        {"materials", materials},
        {"accessors", buffer.accessors()},
        {"bufferViews", buffer.bufferViews()},
        {"buffers", {{{"uri", binPath.filename().string()}, {"byteLength", buffer.bytes().size()}}}},
    };
    writeFile(binPath, buffer.bytes().data(), buffer.bytes().size());
    const std::string text = doc.dump(1);
    writeFile(gltfPath, text.data(), text.size());
    spdlog::debug("wrote {} ({} meshes, {} nodes, {} KiB of buffer)", gltfPath.string(), scene.meshes.size(),
                  nodes.size(), buffer.bytes().size() >> 10);
}

} // namespace glint::scene
