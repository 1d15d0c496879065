#pragma once
// Errors of the scene layer: one exception type that names the file and the
// element that is wrong, so a tool can print one line such as
//   scene.gltf: accessor 3 (mesh 'Body' primitive 0 POSITION): byteOffset 1200
//   + count 100 * stride 12 exceeds bufferView 2 (1024 bytes)
// and exit non-zero.

#include <stdexcept>
#include <string>

namespace glint::scene {

class SceneError : public std::runtime_error {
public:
    // `file` is the file (or built-in scene name) being read; `element` the
    // part of it that is wrong ("accessor 3 (mesh 'Body' primitive 0
    // POSITION)"), empty when the whole file is meant.
    SceneError(std::string file, std::string element, const std::string& detail);

    const std::string& file() const { return file_; }
    const std::string& element() const { return element_; }

private:
    std::string file_;
    std::string element_;
};

} // namespace glint::scene
