#include "glint/metrics/pixel_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace glint::metrics {

namespace {

float displayValue(float linear) { return linearToSrgb(std::clamp(linear, 0.0f, 1.0f)); }

using Plane = std::vector<double>;

// Gaussian-weighted means over every window inside the image ("valid"
// filtering, as Wang et al.'s reference code does). Output is
// (width - 2r) x (height - 2r).
Plane windowMeans(const Plane& src, uint32_t width, uint32_t height, const std::vector<double>& kernel) {
    const uint32_t r = uint32_t(kernel.size() / 2);
    const uint32_t ow = width - 2 * r, oh = height - 2 * r;
    Plane rows(size_t(ow) * height), out(size_t(ow) * oh, 0.0);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < ow; ++x) {
            double sum = 0.0;
            for (size_t k = 0; k < kernel.size(); ++k) sum += kernel[k] * src[size_t(y) * width + x + k];
            rows[size_t(y) * ow + x] = sum;
        }
    }
    for (uint32_t y = 0; y < oh; ++y) {
        for (size_t k = 0; k < kernel.size(); ++k) {
            for (uint32_t x = 0; x < ow; ++x) out[size_t(y) * ow + x] += kernel[k] * rows[(y + k) * ow + x];
        }
    }
    return out;
}

} // namespace

double relMse(const Image& reference, const Image& test, double epsilon) {
    requireSameSize(reference, test);
    double sum = 0.0;
    for (size_t i = 0; i < reference.linear.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            const double r = reference.linear[i][c], t = test.linear[i][c];
            sum += (t - r) * (t - r) / (r * r + epsilon);
        }
    }
    return sum / (3.0 * double(reference.linear.size()));
}

double psnr(const Image& reference, const Image& test) {
    requireSameSize(reference, test);
    double sum = 0.0;
    for (size_t i = 0; i < reference.linear.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            const double d = double(displayValue(test.linear[i][c])) - double(displayValue(reference.linear[i][c]));
            sum += d * d;
        }
    }
    const double mse = sum / (3.0 * double(reference.linear.size()));
    return mse == 0.0 ? std::numeric_limits<double>::infinity() : -10.0 * std::log10(mse);
}

double ssim(const Image& reference, const Image& test) {
    requireSameSize(reference, test);
    const uint32_t w = reference.width, h = reference.height;
    const int radius = std::min<int>(kSsimWindowRadius, int((std::min(w, h) - 1) / 2));
    std::vector<double> kernel;
    double kernelSum = 0.0;
    for (int i = -radius; i <= radius; ++i) {
        kernel.push_back(std::exp(-double(i * i) / (2.0 * kSsimSigma * kSsimSigma)));
        kernelSum += kernel.back();
    }
    for (double& k : kernel) k /= kernelSum;  // 1D weights; the 2D window is their product and sums to 1

    constexpr double c1 = (0.01 * 1.0) * (0.01 * 1.0);  // (K1 L)^2, L = 1
    constexpr double c2 = (0.03 * 1.0) * (0.03 * 1.0);  // (K2 L)^2
    const size_t count = reference.linear.size();
    double total = 0.0;
    size_t windows = 0;
    for (int c = 0; c < 3; ++c) {
        Plane x(count), y(count), xx(count), yy(count), xy(count);
        for (size_t i = 0; i < count; ++i) {
            x[i] = displayValue(reference.linear[i][c]);
            y[i] = displayValue(test.linear[i][c]);
            xx[i] = x[i] * x[i];
            yy[i] = y[i] * y[i];
            xy[i] = x[i] * y[i];
        }
        const Plane mx = windowMeans(x, w, h, kernel), my = windowMeans(y, w, h, kernel);
        const Plane mxx = windowMeans(xx, w, h, kernel), myy = windowMeans(yy, w, h, kernel);
        const Plane mxy = windowMeans(xy, w, h, kernel);
        for (size_t i = 0; i < mx.size(); ++i) {
            const double varX = mxx[i] - mx[i] * mx[i];
            const double varY = myy[i] - my[i] * my[i];
            const double cov = mxy[i] - mx[i] * my[i];
            total += (2.0 * mx[i] * my[i] + c1) * (2.0 * cov + c2) /
                     ((mx[i] * mx[i] + my[i] * my[i] + c1) * (varX + varY + c2));
        }
        windows += mx.size();
    }
    return total / double(windows);
}

} // namespace glint::metrics
