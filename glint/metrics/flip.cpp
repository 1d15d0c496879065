#include "glint/metrics/flip.h"

#include <glm/common.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

// Section numbers refer to the FLIP paper (HPG 2020). Everything per pixel
// is float, as in the official tool, so the printed statistics agree to the
// last digits the tool prints.

namespace glint::metrics {

namespace {

// Section 4.1: the colour difference is raised to q_c, then values below
// p_c * cmax are stretched to [0, p_t) and the rest squeezed into [p_t, 1].
constexpr float kColorExponent = 0.7f;  // q_c
constexpr float kColorCutoff = 0.4f;    // p_c
constexpr float kColorKnee = 0.95f;     // p_t
// Section 4.2: feature detectors are Gaussian derivatives whose standard
// deviation is half of w = 0.082 degrees; the difference is raised to q_f.
constexpr float kFeatureWidthDegrees = 0.082f;  // w
constexpr float kFeatureExponent = 0.5f;        // q_f

constexpr float kPi = std::numbers::pi_v<float>;

// Contrast sensitivity functions (section 4.1), in the spatial domain each a
// sum of two Gaussians a * sqrt(pi / b) * exp(-pi^2 x^2 / b), x in degrees.
struct CsfTerm {
    float a;
    float b;
};
struct Csf {
    CsfTerm first;
    CsfTerm second;
};
constexpr Csf kCsfAchromatic{{1.0f, 0.0047f}, {0.0f, 1e-5f}};
constexpr Csf kCsfRedGreen{{1.0f, 0.0053f}, {0.0f, 1e-5f}};
constexpr Csf kCsfBlueYellow{{34.1f, 0.04f}, {13.5f, 0.025f}};
constexpr float kCsfLargestB = 0.04f;

// ---- colour spaces ----------------------------------------------------------

// Linear sRGB <-> CIE XYZ from the sRGB primaries and the D65 white point;
// the reference white is RGB (1,1,1). D65 is taken at the five decimals of
// CIE 15 (0.31271, 0.32902), which is the matrix the official tool uses;
// the sRGB standard's rounded (0.3127, 0.3290) moves every pooled FLIP value
// of EXPECTED.md's pair by about -3e-6 (measured).
struct ColorSpace {
    glm::mat3 rgbToXyz;
    glm::mat3 xyzToRgb;
    glm::vec3 white;
};

const ColorSpace& colorSpace() {
    static const ColorSpace space = [] {
        const auto xyzOf = [](double x, double y) { return glm::dvec3(x / y, 1.0, (1.0 - x - y) / y); };
        const glm::dmat3 primaries(xyzOf(0.64, 0.33), xyzOf(0.30, 0.60), xyzOf(0.15, 0.06));  // columns
        const glm::dvec3 scale = glm::inverse(primaries) * xyzOf(0.31271, 0.32902);
        glm::dmat3 m = primaries;
        for (int c = 0; c < 3; ++c) m[c] *= scale[c];
        ColorSpace s;
        s.rgbToXyz = glm::mat3(m);
        s.xyzToRgb = glm::mat3(glm::inverse(m));
        s.white = s.rgbToXyz * glm::vec3(1.0f);
        return s;
    }();
    return space;
}

// YyCxCz (section 4.1): the linearised L*a*b* of Rajashekar et al.
glm::vec3 xyzToYcxcz(glm::vec3 xyz) {
    const glm::vec3 n = xyz / colorSpace().white;
    return {116.0f * n.y - 16.0f, 500.0f * (n.x - n.y), 200.0f * (n.y - n.z)};
}

glm::vec3 ycxczToXyz(glm::vec3 c) {
    const float y = (c.x + 16.0f) / 116.0f;
    return glm::vec3(y + c.y / 500.0f, y, y - c.z / 200.0f) * colorSpace().white;
}

float labCurve(float t) {
    constexpr float delta = 6.0f / 29.0f;
    return t > delta * delta * delta ? std::cbrt(t) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
}

// CIE L*a*b* with the Hunt effect applied: chroma scaled by 0.01 L*.
glm::vec3 huntLab(glm::vec3 linearRgb) {
    const glm::vec3 n = (colorSpace().rgbToXyz * linearRgb) / colorSpace().white;
    const float fx = labCurve(n.x), fy = labCurve(n.y), fz = labCurve(n.z);
    const float lightness = 116.0f * fy - 16.0f;
    return {lightness, 0.01f * lightness * 500.0f * (fx - fy), 0.01f * lightness * 200.0f * (fy - fz)};
}

// HyAB: city-block in lightness, Euclidean in the chroma plane.
float hyab(glm::vec3 a, glm::vec3 b) {
    const glm::vec3 d = a - b;
    return std::abs(d.x) + std::sqrt(d.y * d.y + d.z * d.z);
}

// ---- filters ----------------------------------------------------------------

using Plane = std::vector<float>;
using Kernel = std::vector<float>;

// Clamp-to-edge convolution along rows.
void filterRows(const Plane& src, Plane& dst, uint32_t width, uint32_t height, const Kernel& kernel) {
    const int radius = int(kernel.size() / 2);
    std::vector<float> padded(width + 2 * size_t(radius));
    dst.resize(src.size());
    for (uint32_t y = 0; y < height; ++y) {
        const float* row = &src[size_t(y) * width];
        for (size_t i = 0; i < padded.size(); ++i) {
            padded[i] = row[std::clamp(int(i) - radius, 0, int(width) - 1)];
        }
        float* out = &dst[size_t(y) * width];
        for (uint32_t x = 0; x < width; ++x) {
            float sum = 0.0f;
            for (size_t k = 0; k < kernel.size(); ++k) sum += kernel[k] * padded[x + k];
            out[x] = sum;
        }
    }
}

// Clamp-to-edge convolution along columns.
void filterColumns(const Plane& src, Plane& dst, uint32_t width, uint32_t height, const Kernel& kernel) {
    const int radius = int(kernel.size() / 2);
    dst.assign(src.size(), 0.0f);
    for (uint32_t y = 0; y < height; ++y) {
        float* out = &dst[size_t(y) * width];
        for (size_t k = 0; k < kernel.size(); ++k) {
            const int row = std::clamp(int(y) + int(k) - radius, 0, int(height) - 1);
            const float* in = &src[size_t(row) * width];
            const float weight = kernel[k];
            for (uint32_t x = 0; x < width; ++x) out[x] += weight * in[x];
        }
    }
}

// A 2D filter that is a sum of (at most two) separable terms row(x) * column(y)
// with the same 1D kernel in both directions.
struct SeparableFilter {
    std::vector<Kernel> terms;
};

int colorRadius(float ppd) {
    return int(std::ceil(3.0f * std::sqrt(kCsfLargestB / (2.0f * kPi * kPi)) * ppd));
}

// The 2D CSF filter sum over terms of a sqrt(pi/b) exp(-pi^2 (x^2+y^2) / b)
// on the (2r+1)^2 pixel window, normalised to sum 1. Each term is separable:
// its 1D kernel is sqrt(a sqrt(pi/b) / S) exp(-pi^2 x^2 / b), S the 2D sum.
SeparableFilter csfFilter(const Csf& csf, float ppd) {
    const int radius = colorRadius(ppd);
    std::vector<Kernel> profiles;
    std::vector<float> amplitudes;
    float total = 0.0f;
    for (const CsfTerm& term : {csf.first, csf.second}) {
        if (term.a == 0.0f) continue;
        Kernel profile(size_t(2 * radius + 1));
        float sum = 0.0f;
        for (int i = -radius; i <= radius; ++i) {
            const float x = float(i) / ppd;
            profile[size_t(i + radius)] = std::exp(-kPi * kPi * x * x / term.b);
            sum += profile[size_t(i + radius)];
        }
        const float amplitude = term.a * std::sqrt(kPi / term.b);
        total += amplitude * sum * sum;
        profiles.push_back(std::move(profile));
        amplitudes.push_back(amplitude);
    }
    SeparableFilter filter;
    for (size_t t = 0; t < profiles.size(); ++t) {
        const float scale = std::sqrt(amplitudes[t] / total);
        for (float& v : profiles[t]) v *= scale;
        filter.terms.push_back(std::move(profiles[t]));
    }
    return filter;
}

Plane applySeparable(const Plane& src, uint32_t width, uint32_t height, const SeparableFilter& filter) {
    Plane result(src.size(), 0.0f), rows, columns;
    for (const Kernel& kernel : filter.terms) {
        filterRows(src, rows, width, height, kernel);
        filterColumns(rows, columns, width, height, kernel);
        for (size_t i = 0; i < result.size(); ++i) result[i] += columns[i];
    }
    return result;
}

float featureSigma(float ppd) { return 0.5f * kFeatureWidthDegrees * ppd; }

int featureRadius(float ppd) { return int(std::ceil(3.0f * featureSigma(ppd))); }

// Section 4.2: the edge detector is the first and the point detector the
// second derivative of a Gaussian (sigma = w/2 degrees). The smoothing
// Gaussian sums to 1; each derivative's positive weights sum to 1 and its
// negative weights to -1, so a flat image gives no response.
struct FeatureKernels {
    Kernel gaussian, firstDerivative, secondDerivative;
};

FeatureKernels featureKernels(float ppd) {
    const float sigma = featureSigma(ppd);
    const int radius = featureRadius(ppd);
    FeatureKernels k;
    for (int i = -radius; i <= radius; ++i) {
        const float x = float(i);
        const float g = std::exp(-x * x / (2.0f * sigma * sigma));
        k.gaussian.push_back(g);
        k.firstDerivative.push_back(-x * g);
        k.secondDerivative.push_back((x * x / (sigma * sigma) - 1.0f) * g);
    }
    const auto normalise = [](Kernel& kernel, bool signedWeights) {
        float positive = 0.0f, negative = 0.0f;
        for (float v : kernel) (v > 0.0f ? positive : negative) += std::abs(v);
        for (float& v : kernel) v /= !signedWeights || v > 0.0f ? positive : negative;
    };
    normalise(k.gaussian, false);
    normalise(k.firstDerivative, true);
    normalise(k.secondDerivative, true);
    return k;
}

// ---- per image --------------------------------------------------------------

struct Prepared {
    std::vector<glm::vec3> huntLab;  // of the CSF-filtered image
    Plane edges;                     // |gradient| of the achromatic channel
    Plane points;                    // |second derivatives| of the achromatic channel
};

Prepared prepare(const Image& image, const SeparableFilter (&csf)[3], const FeatureKernels& features) {
    const uint32_t w = image.width, h = image.height;
    const size_t count = image.linear.size();
    Plane channels[3], achromatic(count);
    for (Plane& c : channels) c.resize(count);
    for (size_t i = 0; i < count; ++i) {
        const glm::vec3 rgb = glm::clamp(image.linear[i], 0.0f, 1.0f);
        const glm::vec3 ycxcz = xyzToYcxcz(colorSpace().rgbToXyz * rgb);
        for (int c = 0; c < 3; ++c) channels[c][i] = ycxcz[c];
        achromatic[i] = (ycxcz.x + 16.0f) / 116.0f;  // normalised luminance in [0,1]
    }

    Prepared p;
    Plane filtered[3];
    for (int c = 0; c < 3; ++c) filtered[c] = applySeparable(channels[c], w, h, csf[c]);
    p.huntLab.resize(count);
    for (size_t i = 0; i < count; ++i) {
        const glm::vec3 xyz = ycxczToXyz({filtered[0][i], filtered[1][i], filtered[2][i]});
        p.huntLab[i] = huntLab(glm::clamp(colorSpace().xyzToRgb * xyz, 0.0f, 1.0f));
    }

    Plane smooth, first, second, a, b;
    filterRows(achromatic, smooth, w, h, features.gaussian);
    filterRows(achromatic, first, w, h, features.firstDerivative);
    filterRows(achromatic, second, w, h, features.secondDerivative);
    p.edges.resize(count);
    p.points.resize(count);
    filterColumns(first, a, w, h, features.gaussian);         // d/dx
    filterColumns(smooth, b, w, h, features.firstDerivative);  // d/dy
    for (size_t i = 0; i < count; ++i) p.edges[i] = std::sqrt(a[i] * a[i] + b[i] * b[i]);
    filterColumns(second, a, w, h, features.gaussian);          // d2/dx2
    filterColumns(smooth, b, w, h, features.secondDerivative);  // d2/dy2
    for (size_t i = 0; i < count; ++i) p.points[i] = std::sqrt(a[i] * a[i] + b[i] * b[i]);
    return p;
}

} // namespace

int flipColorFilterRadius(double pixelsPerDegree) { return colorRadius(float(pixelsPerDegree)); }

int flipFeatureFilterRadius(double pixelsPerDegree) { return featureRadius(float(pixelsPerDegree)); }

FlipStats poolFlipErrors(std::span<const float> errors) {
    FlipStats stats;
    if (errors.empty()) return stats;
    float total = 0.0f;
    float lowest = errors[0], highest = errors[0];
    for (float e : errors) {
        total += e;
        lowest = std::min(lowest, e);
        highest = std::max(highest, e);
    }
    stats.mean = double(total) / double(errors.size());
    stats.min = lowest;
    stats.max = highest;

    std::vector<float> sorted(errors.begin(), errors.end());
    std::sort(sorted.begin(), sorted.end());
    const float percents[3] = {0.25f, 0.5f, 0.75f};
    float found[3] = {sorted.back(), sorted.back(), sorted.back()};
    int next = 0;
    float running = 0.0f;
    for (size_t i = 0; i < sorted.size() && next < 3; ++i) {
        running += sorted[i];
        while (next < 3 && running > percents[next] * total) found[next++] = sorted[i];
    }
    stats.weightedQ1 = found[0];
    stats.weightedMedian = found[1];
    stats.weightedQ3 = found[2];
    return stats;
}

FlipResult flip(const Image& reference, const Image& test, double pixelsPerDegree) {
    requireSameSize(reference, test);
    if (!(pixelsPerDegree > 0.0) || !std::isfinite(pixelsPerDegree)) {
        throw std::invalid_argument("FLIP: pixels per degree must be positive, got " + std::to_string(pixelsPerDegree));
    }
    const float ppd = float(pixelsPerDegree);
    const SeparableFilter csf[3] = {csfFilter(kCsfAchromatic, ppd), csfFilter(kCsfRedGreen, ppd),
                                    csfFilter(kCsfBlueYellow, ppd)};
    const FeatureKernels features = featureKernels(ppd);
    const Prepared ref = prepare(reference, csf, features);
    const Prepared tst = prepare(test, csf, features);

    // The largest colour difference between two colours of the gamut: green
    // and blue (section 4.1).
    const float cmax = std::pow(hyab(huntLab({0.0f, 1.0f, 0.0f}), huntLab({0.0f, 0.0f, 1.0f})), kColorExponent);
    const float knee = kColorCutoff * cmax;

    FlipResult result;
    result.width = reference.width;
    result.height = reference.height;
    result.errorMap.resize(reference.linear.size());
    for (size_t i = 0; i < result.errorMap.size(); ++i) {
        const float color = std::pow(hyab(ref.huntLab[i], tst.huntLab[i]), kColorExponent);
        const float colorError = color < knee ? kColorKnee / kColorCutoff * (color / cmax)
                                              : kColorKnee + (color - knee) / (cmax - knee) * (1.0f - kColorKnee);
        const float featureDifference =
            std::max(std::abs(ref.edges[i] - tst.edges[i]), std::abs(ref.points[i] - tst.points[i]));
        const float featureError = std::pow(featureDifference / std::numbers::sqrt2_v<float>, kFeatureExponent);
        // Section 4.3: features sharpen the colour error, e_c^(1 - e_f).
        result.errorMap[i] = std::pow(colorError, 1.0f - featureError);
    }
    result.stats = poolFlipErrors(result.errorMap);
    return result;
}

} // namespace glint::metrics
