#include "glint/metrics/error_map.h"

#include <glm/common.hpp>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace glint::metrics {

glm::vec3 magma(float t) {
    // Coefficients c0..c6 of c0 + c1 t + ... + c6 t^6 per channel.
    static constexpr std::array<glm::vec3, 7> c = {
        glm::vec3(-0.002136485053939582f, -0.000749655052795221f, -0.005386127855323933f),
        glm::vec3(0.2516605407371642f, 0.6775232436837668f, 2.494026599312351f),
        glm::vec3(8.353717279216625f, -3.577719514958484f, 0.3144679030132573f),
        glm::vec3(-27.66873308576866f, 14.26473078096533f, -13.64921318813922f),
        glm::vec3(52.17613981234068f, -27.94360607168351f, 12.94416944238394f),
        glm::vec3(-50.76852536473588f, 29.04658282127291f, 4.23415299384598f),
        glm::vec3(18.65570506591883f, -11.48977351997711f, -5.601961508734096f),
    };
    t = std::isnan(t) ? 0.0f : std::clamp(t, 0.0f, 1.0f);
    glm::vec3 v = c[6];
    for (int i = 5; i >= 0; --i) v = c[size_t(i)] + t * v;
    return glm::clamp(v, 0.0f, 1.0f);
}

void writeErrorMap(const std::filesystem::path& path, std::span<const float> errors, uint32_t width,
                   uint32_t height) {
    if (errors.size() != size_t(width) * height || errors.empty()) {
        throw std::invalid_argument("error map for '" + path.string() + "': " + std::to_string(errors.size()) +
                                    " values for " + std::to_string(width) + "x" + std::to_string(height));
    }
    std::vector<uint8_t> rgb(errors.size() * 3);
    for (size_t i = 0; i < errors.size(); ++i) {
        const glm::vec3 colour = magma(errors[i]);
        for (int ch = 0; ch < 3; ++ch) rgb[i * 3 + size_t(ch)] = uint8_t(std::lround(colour[ch] * 255.0f));
    }
    const auto dir = path.parent_path();
    if (!dir.empty()) std::filesystem::create_directories(dir);
    if (!stbi_write_png(path.string().c_str(), int(width), int(height), 3, rgb.data(), int(width * 3))) {
        throw std::runtime_error("cannot write PNG '" + path.string() + "'");
    }
}

} // namespace glint::metrics
