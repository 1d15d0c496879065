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
#include <string>
#include <vector>

namespace glint::metrics {

float luminance(const glm::vec3& rgb);

// What an object adds to an image: the luminance of the frame rendered with
// it minus the same frame without it, per pixel (negative where it hides
// something brighter). Comparing contributions, not images, leaves out
// whatever else a renderer gets wrong (noise, bias) alike with and without
// the object. Throws std::invalid_argument unless the sizes agree.
struct Contribution {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> luminance;
    std::string name;
};
Contribution contribution(const Image& withObject, const Image& without);

// Pixels where the contribution exceeds `threshold` in magnitude: where the
// object, or its reflection, is; grown by `dilation` pixels each way (a
// square), so an edge a pixel off counts as in place rather than as trail.
std::vector<uint8_t> footprint(const Contribution& reference, float threshold = 1e-3f, uint32_t dilation = 0);

// The trail: the magnitude `test` contributes beyond `reference` outside the
// object's true footprint (`inside`, one byte per pixel, non-zero inside),
// as a fraction of what the reference contributes inside it. 0 when the
// object's reflection is only where it belongs; 0.05 when 5% of its energy
// is left behind. Throws std::invalid_argument on mismatched sizes or a
// reference that contributes nothing inside the footprint.
double ghostEnergy(const Contribution& reference, const Contribution& test, std::span<const uint8_t> inside);

// How far the object's reflection in `test` is from where the reference
// has it, in pixels: the distance between the centroids of the two
// contributions' magnitudes. Throws std::invalid_argument on mismatched
// sizes or a contribution that is zero everywhere.
double lagPixels(const Contribution& reference, const Contribution& test);

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
