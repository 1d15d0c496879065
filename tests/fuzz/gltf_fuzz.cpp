// libFuzzer target: the input as a glTF file (.glb when it starts with the
// binary container's magic, else .gltf; a .gltf may name external buffers
// and images beside it, which are then missing), loaded by the scene
// loader. It must load or throw a SceneError; anything else (a crash,
// another exception, a sanitizer report) aborts: a finding.
#include "glint/scene/error.h"
#include "glint/scene/gltf_loader.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    // One folder per process, its file rewritten for every input and
    // removed at exit.
    struct Folder {
        std::filesystem::path path =
            std::filesystem::temp_directory_path() / ("glint-gltf-fuzz-" + std::to_string(getpid()));
        Folder() { std::filesystem::create_directories(path); }
        ~Folder() {
            std::error_code ignored;
            std::filesystem::remove_all(path, ignored);
        }
    };
    static const Folder folder;
    const std::filesystem::path file = folder.path / (binary ? "input.glb" : "input.gltf");
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    try {
        glint::scene::loadGltf(file);
    } catch (const glint::scene::SceneError&) {
        // Bad input, said so: what the loader must do.
    }
    return 0;
}
