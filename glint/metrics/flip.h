#pragma once
// LDR-FLIP (Andersson, Nilsson, Akenine-Moller, Oskarsson, Astrom, Fairchild,
// "FLIP: A Difference Evaluator for Alternating Images", HPG 2020), written
// from the paper. Per pixel error in [0,1]; the pooled statistics follow the
// official tool's printout (NVlabs flip, v1.6; tests/metrics checks ours
// against its recorded output).

#include "glint/metrics/image.h"

#include <numbers>
#include <span>
#include <vector>

namespace glint::metrics {

// The official tool's default viewing condition: a 0.7 m wide 3840-pixel
// monitor seen from 0.7 m, 3840 * pi / 180 pixels per degree (67.020645 as
// the tool's float).
inline constexpr double kDefaultPpd = 3840.0 * std::numbers::pi / 180.0;

struct FlipStats {
    double mean = 0.0;            // float running sum in row-major order / pixel count
    double weightedMedian = 0.0;  // weighted percentiles: each pixel weighted by its own error
    double weightedQ1 = 0.0;
    double weightedQ3 = 0.0;
    double min = 0.0;
    double max = 0.0;
};

struct FlipResult {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> errorMap;  // width * height, row-major
    FlipStats stats;
};

// Pools an error map as the official tool prints it: the mean is a float
// sum in the given (row-major) order; a weighted percentile p is the first
// value, in ascending order, at which a float running sum becomes strictly
// greater than p times the float total.
FlipStats poolFlipErrors(std::span<const float> errors);

// Both images linear RGB in [0,1] (values outside are clamped) of the same
// size; throws std::invalid_argument naming both otherwise.
FlipResult flip(const Image& reference, const Image& test, double pixelsPerDegree = kDefaultPpd);

// Filter radii in pixels (for tests and documentation): the colour
// (contrast sensitivity) filters and the feature (edge/point) filters.
int flipColorFilterRadius(double pixelsPerDegree);
int flipFeatureFilterRadius(double pixelsPerDegree);

} // namespace glint::metrics
