#pragma once
// Images as the metrics see them: linear RGB, row-major, top row first.
//
// PNG input follows the official FLIP tool (NVlabs, v1.6):
// stb_image, 3 channels (alpha dropped, not composited; 16-bit reduced to
// 8-bit; gAMA/iCCP ignored), each value v/255 treated as sRGB and linearised
// with the piecewise sRGB curve in float.

#include <glm/vec3.hpp>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace glint::metrics {

struct Image {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<glm::vec3> linear;  // width * height, linear RGB (8-bit input: [0,1])
    std::string name;               // file or label, for error messages
};

// sRGB transfer curve (IEC 61966-2-1), float as the official tool computes it.
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

// 8-bit sRGB values, `channels` (3 or 4; a fourth is ignored) per pixel.
Image imageFromSrgb8(uint32_t width, uint32_t height, std::span<const uint8_t> pixels, uint32_t channels,
                     std::string name);

// Raw 8-bit RGB of a PNG (or any format stb_image reads), 3 per pixel.
// Throws std::runtime_error naming the file.
std::vector<uint8_t> loadRgb8(const std::filesystem::path& path, uint32_t& width, uint32_t& height);

// PNG to linear RGB; throws std::runtime_error naming the file.
Image loadPng(const std::filesystem::path& path);

// Throws std::invalid_argument naming both images and their sizes unless
// they have the same, non-zero size.
void requireSameSize(const Image& reference, const Image& test);

} // namespace glint::metrics
