#pragma once
// Reflections in motion, measured against per-frame references: the trail a
// moving object leaves (ghosting), how far a reflection lags behind where
// it should be, and how much a still image shimmers (flicker); and the
// error of a reflection split by the roughness of the surface that
// reflects it, so a cutoff or a filter is judged where it acts.
//
// All on linear RGB images of one size (image.h); luminance is Rec. 709's
// (0.2126 R + 0.7152 G + 0.0722 B).

#include "glint/metrics/flip.h"
#include "glint/metrics/image.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace glint::metrics {

float luminance(const glm::vec3& rgb);

// Pixels where `withObject` differs from `without` (the same frame rendered
// without the moving object) by more than `threshold` in luminance: where
// the object, or its reflection, is. Throws std::invalid_argument unless
// the sizes agree.
std::vector<uint8_t> footprint(const Image& withObject, const Image& without, float threshold = 1e-3f);

// The trail: the luminance `test` has in excess of `reference` outside the
// object's true footprint (`inside`, one byte per pixel, non-zero inside),
// as a fraction of the luminance the reference has inside it. 0 when the
// object's reflection is only where it belongs; 0.05 when 5% of its energy
// is left behind. Throws std::invalid_argument on mismatched sizes or an
// empty footprint.
double ghostEnergy(const Image& reference, const Image& test, std::span<const uint8_t> inside);

// How far the object's reflection in `test` is from where the reference
// has it, in pixels: the distance between the luminance-weighted centroids
// of |image - without| over the two images. Throws std::invalid_argument on
// mismatched sizes or where an image differs nowhere from `without`.
double lagPixels(const Image& reference, const Image& test, const Image& without);

// Mean absolute change from one frame to the next over pixels, channels
// and frame pairs (linear values): 0 for a converged reference with a still
// camera. Throws std::invalid_argument on fewer than two frames or
// mismatched sizes.
double flicker(std::span<const Image> frames);

// Perceptual roughness bands: mirror [0, 0.05), glossy [0.05, 0.22),
// rough [0.22, 0.5), very rough [0.5, 1].
inline constexpr std::array<float, 3> kRoughnessBandEdges = {0.05f, 0.22f, 0.5f};
inline constexpr size_t kRoughnessBands = kRoughnessBandEdges.size() + 1;
size_t roughnessBand(float roughness);

struct BandError {
    double flipMean = 0.0;  // NaN where the band has no pixel
    uint64_t pixels = 0;
};

// FLIP's per-pixel error pooled per roughness band of the reflecting
// surface (`roughness`, one value per pixel; negative: no surface, e.g.
// sky, left out). Throws std::invalid_argument on mismatched sizes.
std::array<BandError, kRoughnessBands> flipByRoughness(const FlipResult& error, std::span<const float> roughness);

} // namespace glint::metrics
