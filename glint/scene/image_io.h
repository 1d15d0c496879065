#pragma once
// Files and images with limits: every size is checked before memory is
// allocated for it, so a corrupt header cannot ask for gigabytes.

#include "glint/scene/scene.h"

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace glint::scene {

struct ImageLimits {
    uint32_t maxDimension = 16384;   // the largest 2D image Vulkan guarantees on current desktop GPUs
    uint64_t maxBytes = 1ull << 30;  // decoded size
};

// Whole file, refusing files larger than `maxBytes`. Errors name `file` and
// `element` (e.g. the glTF buffer that refers to the file).
std::vector<uint8_t> readFileLimited(const std::filesystem::path& path, uint64_t maxBytes, const std::string& file,
                                     const std::string& element);

// PNG, JPEG, BMP, TGA, ... (stb_image) to RGBA8. The header is read first
// and checked against `limits` before any pixel memory exists.
Texture decodeImageRgba8(std::span<const uint8_t> bytes, const ImageLimits& limits, const std::string& file,
                         const std::string& element);

// Radiance .hdr (or any stb_image format, converted) to RGBA32F.
Texture decodeImageRgba32f(std::span<const uint8_t> bytes, const ImageLimits& limits, const std::string& file,
                           const std::string& element);

// An equirectangular environment as Environment::image expects it.
Environment loadEquirectangularEnvironment(const std::filesystem::path& path, const ImageLimits& limits = {});

// Writes width x height RGBA8 pixels (rows top to bottom) as a PNG, making
// the folder if needed. Throws SceneError naming the file.
void writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, std::span<const uint8_t> rgba);

} // namespace glint::scene
