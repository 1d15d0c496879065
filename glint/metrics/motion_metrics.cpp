#include "glint/metrics/motion_metrics.h"

#include <glm/common.hpp>

#include <algorithm>
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

namespace {

void requireSameSize(const Contribution& a, const Contribution& b) {
    if (a.width != b.width || a.height != b.height || a.luminance.size() != b.luminance.size() ||
        a.luminance.size() != size_t(a.width) * a.height || a.luminance.empty()) {
        throw std::invalid_argument("'" + a.name + "' is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                    ", '" + b.name + "' " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                                    ": expected two contributions of one non-empty size");
    }
}

} // namespace

Contribution contribution(const Image& withObject, const Image& without) {
    requireSameSize(withObject, without);
    Contribution c{withObject.width, withObject.height, std::vector<float>(withObject.linear.size()),
                   withObject.name + " - " + without.name};
    for (size_t i = 0; i < c.luminance.size(); ++i) {
        c.luminance[i] = luminance(withObject.linear[i]) - luminance(without.linear[i]);
    }
    return c;
}

std::vector<uint8_t> footprint(const Contribution& reference, float threshold, uint32_t dilation) {
    std::vector<uint8_t> inside(reference.luminance.size(), 0);
    for (size_t i = 0; i < inside.size(); ++i) inside[i] = std::abs(reference.luminance[i]) > threshold ? 1 : 0;
    if (dilation == 0 || inside.size() != size_t(reference.width) * reference.height) return inside;
    // Separable: rows, then columns.
    const int64_t w = reference.width, h = reference.height, r = dilation;
    std::vector<uint8_t> rows(inside.size(), 0);
    for (int64_t y = 0; y < h; ++y) {
        for (int64_t x = 0; x < w; ++x) {
            for (int64_t d = std::max<int64_t>(0, x - r); d <= std::min(w - 1, x + r) && !rows[y * w + x]; ++d) {
                rows[y * w + x] = inside[y * w + d];
            }
        }
    }
    std::vector<uint8_t> grown(inside.size(), 0);
    for (int64_t y = 0; y < h; ++y) {
        for (int64_t x = 0; x < w; ++x) {
            for (int64_t d = std::max<int64_t>(0, y - r); d <= std::min(h - 1, y + r) && !grown[y * w + x]; ++d) {
                grown[y * w + x] = rows[d * w + x];
            }
        }
    }
    return grown;
}

double ghostEnergy(const Contribution& reference, const Contribution& test, std::span<const uint8_t> inside) {
    requireSameSize(reference, test);
    if (inside.size() != reference.luminance.size()) {
        throw std::invalid_argument("ghostEnergy: the footprint has " + std::to_string(inside.size()) +
                                    " pixels, the contributions " + std::to_string(reference.luminance.size()));
    }
    double objectEnergy = 0.0, trail = 0.0;
    for (size_t i = 0; i < inside.size(); ++i) {
        const double ref = std::abs(double(reference.luminance[i]));
        if (inside[i] != 0) {
            objectEnergy += ref;
        } else {
            trail += std::max(0.0, std::abs(double(test.luminance[i])) - ref);
        }
    }
    if (!(objectEnergy > 0.0)) {
        throw std::invalid_argument("ghostEnergy: the reference '" + reference.name +
                                    "' contributes nothing inside the footprint");
    }
    return trail / objectEnergy;
}

double lagPixels(const Contribution& reference, const Contribution& test) {
    requireSameSize(reference, test);
    const auto centroid = [&](const Contribution& c) {
        double sum = 0.0, x = 0.0, y = 0.0;
        for (uint32_t row = 0; row < c.height; ++row) {
            for (uint32_t col = 0; col < c.width; ++col) {
                const double w = std::abs(double(c.luminance[size_t(row) * c.width + col]));
                sum += w;
                x += w * (col + 0.5);
                y += w * (row + 0.5);
            }
        }
        if (!(sum > 0.0)) {
            throw std::invalid_argument("lagPixels: '" + c.name + "' is zero everywhere");
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
