#pragma once
// Error maps as images: FLIP values through the magma colour ramp, as the
// FLIP tool shows them.

#include <glm/vec3.hpp>

#include <cstdint>
#include <filesystem>
#include <span>

namespace glint::metrics {

// Magma (matplotlib) at t in [0,1] (clamped), sRGB-encoded in [0,1]:
// Matt Zucker's degree-6 polynomial fit (https://www.shadertoy.com/view/WlfXRN,
// CC0), within about 0.01 of the 256-entry matplotlib table.
glm::vec3 magma(float t);

// `errors` (width * height, row-major, values in [0,1]) as an 8-bit RGB PNG
// through magma. Creates the folder; throws std::runtime_error naming the
// file on failure.
void writeErrorMap(const std::filesystem::path& path, std::span<const float> errors, uint32_t width,
                   uint32_t height);

} // namespace glint::metrics
