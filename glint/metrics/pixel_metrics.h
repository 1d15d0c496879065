#pragma once
// Per-pixel error metrics next to FLIP.
//
// Domains: relMSE compares linear RGB (radiance, as the rendering literature
// uses it); PSNR and SSIM compare display values, the sRGB encoding of the
// linear values clamped to [0,1], which for 8-bit input are exactly v/255.

#include "glint/metrics/image.h"

namespace glint::metrics {

// Rousselle et al.'s relative MSE: mean over pixels and channels of
// (t - r)^2 / (r^2 + epsilon), linear RGB.
inline constexpr double kRelMseEpsilon = 0.01;
double relMse(const Image& reference, const Image& test, double epsilon = kRelMseEpsilon);

// 10 log10(1 / MSE) over pixels and channels of display values in [0,1];
// +infinity for identical images.
double psnr(const Image& reference, const Image& test);

// Mean SSIM (Wang, Bovik, Sheikh, Simoncelli 2004): 11x11 Gaussian window
// with sigma 1.5, K1 = 0.01, K2 = 0.03, dynamic range 1, computed on each
// of R, G, B display values separately over the windows that lie inside the
// image, and averaged over windows and channels. An image smaller than 11
// pixels in a direction uses the largest odd window that fits (same sigma).
inline constexpr int kSsimWindowRadius = 5;
inline constexpr double kSsimSigma = 1.5;
double ssim(const Image& reference, const Image& test);

} // namespace glint::metrics
