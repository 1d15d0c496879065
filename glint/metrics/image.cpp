#include "glint/metrics/image.h"

// The implementation is compiled into libstb (libstb-dev); only declarations here.
#include <stb_image.h>

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace glint::metrics {

float srgbToLinear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float linear) {
    return linear <= 0.0031308f ? linear * 12.92f : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

Image imageFromSrgb8(uint32_t width, uint32_t height, std::span<const uint8_t> pixels, uint32_t channels,
                     std::string name) {
    if (channels != 3 && channels != 4) {
        throw std::invalid_argument(name + ": " + std::to_string(channels) + " channels, expected 3 or 4");
    }
    const size_t count = size_t(width) * height;
    if (pixels.size() != count * channels) {
        throw std::invalid_argument(name + ": " + std::to_string(pixels.size()) + " bytes for " +
                                    std::to_string(width) + "x" + std::to_string(height) + "x" +
                                    std::to_string(channels));
    }
    // v / 255 in float, then the curve: the same float the official tool gets.
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int v = 0; v < 256; ++v) t[size_t(v)] = srgbToLinear(float(v) / 255.0f);
        return t;
    }();
    Image image;
    image.width = width;
    image.height = height;
    image.name = std::move(name);
    image.linear.resize(count);
    for (size_t i = 0; i < count; ++i) {
        const uint8_t* p = &pixels[i * channels];
        image.linear[i] = {table[p[0]], table[p[1]], table[p[2]]};
    }
    return image;
}

std::vector<uint8_t> loadRgb8(const std::filesystem::path& path, uint32_t& width, uint32_t& height) {
    int w = 0, h = 0, comp = 0;
    std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load(path.string().c_str(), &w, &h, &comp, 3),
                                                     stbi_image_free);
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        throw std::runtime_error("cannot read image '" + path.string() + "': " + (reason ? reason : "unknown error"));
    }
    width = uint32_t(w);
    height = uint32_t(h);
    return {pixels.get(), pixels.get() + size_t(width) * height * 3};
}

Image loadPng(const std::filesystem::path& path) {
    uint32_t width = 0, height = 0;
    const std::vector<uint8_t> rgb = loadRgb8(path, width, height);
    return imageFromSrgb8(width, height, rgb, 3, path.string());
}

void requireSameSize(const Image& reference, const Image& test) {
    const auto describe = [](const Image& image) {
        return "'" + image.name + "' is " + std::to_string(image.width) + "x" + std::to_string(image.height);
    };
    if (reference.width != test.width || reference.height != test.height) {
        throw std::invalid_argument("image sizes differ: reference " + describe(reference) + ", test " +
                                    describe(test));
    }
    if (reference.width == 0 || reference.height == 0) {
        throw std::invalid_argument("empty images: reference " + describe(reference) + ", test " + describe(test));
    }
    const size_t count = size_t(reference.width) * reference.height;
    if (reference.linear.size() != count || test.linear.size() != count) {
        throw std::invalid_argument("pixel count does not match the size: reference " + describe(reference) +
                                    " with " + std::to_string(reference.linear.size()) + " pixels, test " +
                                    describe(test) + " with " + std::to_string(test.linear.size()));
    }
}

} // namespace glint::metrics
