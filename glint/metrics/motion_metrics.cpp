#include "glint/metrics/motion_metrics.h"

#include <glm/common.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace glint::metrics {

namespace {

void requireSize(const Image& image, size_t pixels, const char* what) {
    if (image.linear.size() != pixels || pixels == 0) {
        throw std::invalid_argument(std::string(what) + ": '" + image.name + "' has " +
                                    std::to_string(image.linear.size()) + " pixels, expected " +
                                    std::to_string(pixels));
    }
}

} // namespace

float luminance(const glm::vec3& rgb) { return 0.2126f * rgb.r + 0.7152f * rgb.g + 0.0722f * rgb.b; }

std::vector<uint8_t> footprint(const Image& withObject, const Image& without, float threshold) {
    requireSameSize(withObject, without);
    std::vector<uint8_t> inside(withObject.linear.size(), 0);
    for (size_t i = 0; i < inside.size(); ++i) {
        inside[i] = std::abs(luminance(withObject.linear[i]) - luminance(without.linear[i])) > threshold ? 1 : 0;
    }
    return inside;
}

double ghostEnergy(const Image& reference, const Image& test, std::span<const uint8_t> inside) {
    requireSameSize(reference, test);
    if (inside.size() != reference.linear.size()) {
        throw std::invalid_argument("ghostEnergy: the footprint has " + std::to_string(inside.size()) +
                                    " pixels, the images " + std::to_string(reference.linear.size()));
    }
    double objectEnergy = 0.0, trail = 0.0;
    for (size_t i = 0; i < inside.size(); ++i) {
        const double ref = luminance(reference.linear[i]);
        if (inside[i] != 0) {
            objectEnergy += ref;
        } else {
            trail += std::max(0.0, double(luminance(test.linear[i])) - ref);
        }
    }
    if (!(objectEnergy > 0.0)) {
        throw std::invalid_argument("ghostEnergy: the reference '" + reference.name +
                                    "' has no luminance inside the footprint");
    }
    return trail / objectEnergy;
}

double lagPixels(const Image& reference, const Image& test, const Image& without) {
    requireSameSize(reference, test);
    requireSameSize(reference, without);
    const auto centroid = [&](const Image& image) {
        double sum = 0.0, x = 0.0, y = 0.0;
        for (uint32_t row = 0; row < image.height; ++row) {
            for (uint32_t col = 0; col < image.width; ++col) {
                const size_t i = size_t(row) * image.width + col;
                const double w = std::abs(double(luminance(image.linear[i])) - luminance(without.linear[i]));
                sum += w;
                x += w * (col + 0.5);
                y += w * (row + 0.5);
            }
        }
        if (!(sum > 0.0)) {
            throw std::invalid_argument("lagPixels: '" + image.name + "' does not differ from '" + without.name +
                                        "' anywhere");
        }
        return std::array<double, 2>{x / sum, y / sum};
    };
    const std::array<double, 2> a = centroid(reference), b = centroid(test);
    return std::hypot(a[0] - b[0], a[1] - b[1]);
}

double flicker(std::span<const Image> frames) {
    if (frames.size() < 2) throw std::invalid_argument("flicker: needs at least two frames");
    const size_t pixels = frames[0].linear.size();
    double sum = 0.0;
    for (size_t f = 1; f < frames.size(); ++f) {
        requireSize(frames[f], pixels, "flicker");
        for (size_t i = 0; i < pixels; ++i) {
            const glm::vec3 d = glm::abs(frames[f].linear[i] - frames[f - 1].linear[i]);
            sum += double(d.r) + d.g + d.b;
        }
    }
    return sum / (double(pixels) * 3.0 * double(frames.size() - 1));
}

size_t roughnessBand(float roughness) {
    size_t band = 0;
    while (band < kRoughnessBandEdges.size() && roughness >= kRoughnessBandEdges[band]) ++band;
    return band;
}

std::array<BandError, kRoughnessBands> flipByRoughness(const FlipResult& error, std::span<const float> roughness) {
    if (roughness.size() != error.errorMap.size()) {
        throw std::invalid_argument("flipByRoughness: " + std::to_string(roughness.size()) +
                                    " roughness values for an error map of " + std::to_string(error.errorMap.size()) +
                                    " pixels");
    }
    std::array<double, kRoughnessBands> sums{};
    std::array<BandError, kRoughnessBands> bands{};
    for (size_t i = 0; i < roughness.size(); ++i) {
        if (!(roughness[i] >= 0.0f)) continue;
        const size_t band = roughnessBand(roughness[i]);
        sums[band] += error.errorMap[i];
        ++bands[band].pixels;
    }
    for (size_t b = 0; b < kRoughnessBands; ++b) {
        bands[b].flipMean = bands[b].pixels > 0 ? sums[b] / double(bands[b].pixels)
                                                : std::numeric_limits<double>::quiet_NaN();
    }
    return bands;
}

} // namespace glint::metrics
