#pragma once
// Shared by gltf_loader.cpp (files, GLB container, JSON preflight, tinygltf)
// and the conversion (tinygltf model -> scene, with every accessor checked:
// gltf_convert.cpp and the files beside it, through gltf_converter.h).
// Internal: nothing outside glint/scene includes it.

#include "glint/scene/gltf_loader.h"

// The implementation lives in libtinygltf (Debian builds it against libstb
// and nlohmann-json); only declarations are compiled here.
#include <tiny_gltf.h>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace glint::scene::gltf {

struct LoadContext {
    std::string file;  // as errors print it
    GltfLoadOptions options;
    // Encoded bytes of the images tinygltf read from a URI (external file or
    // data URI), by image index; bufferView images are read after their view
    // has been checked.
    std::map<int, std::vector<uint8_t>> encodedImages;
    // Images whose URI preflight found missing: image index -> reason.
    std::map<int, std::string> missingImages;
    uint64_t decodedBytes = 0;

    // Adds `bytes` to the decoded total; throws SceneError naming `element`
    // when it would pass options.maxDecodedBytes.
    void chargeDecoded(uint64_t bytes, const std::string& element);
};

// tinygltf model -> scene (not yet prepared). Throws SceneError.
Scene convertModel(const tinygltf::Model& model, LoadContext& context);

// "%20" -> " " as tinygltf decodes URIs, so preflight checks the same file.
std::string decodeUri(const std::string& uri);

} // namespace glint::scene::gltf
