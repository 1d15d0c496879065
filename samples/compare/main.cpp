// glint-compare: compares two images as the metrics library sees them and
// prints one line of numbers: FLIP (pooled as the official tool prints
// them), relMSE, PSNR and SSIM. --map writes the FLIP error map in magma.

#include "common/app.h"
#include "glint/metrics/error_map.h"
#include "glint/metrics/flip.h"
#include "glint/metrics/pixel_metrics.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr const char* kUsage =
    "glint-compare REF.png TEST.png: one line of image metrics\n"
    "  prints: flip_mean=... flip_weighted_median=... flip_q1=... flip_q3=... flip_min=... flip_max=...\n"
    "          relmse=... psnr=... ssim=...\n"
    "  PNG values are sRGB, linearised as the official FLIP tool does.\n"
    "  flip_*  LDR-FLIP (Andersson et al. 2020) at --ppd pixels per degree (default 67.020645,\n"
    "          a 0.7 m wide 3840-pixel display at 0.7 m); median and quartiles are weighted by error\n"
    "  relmse  mean over pixels and channels of (test - ref)^2 / (ref^2 + 0.01), linear RGB (epsilon 0.01)\n"
    "  psnr    10 log10(1 / MSE) on sRGB values in [0,1] (inf for identical images)\n"
    "  ssim    mean SSIM, 11x11 Gaussian window (sigma 1.5), K1 0.01, K2 0.03, per R/G/B channel, averaged";

double parsePpd(const std::string& text) {
    try {
        size_t used = 0;
        const double ppd = std::stod(text, &used);
        if (used == text.size() && std::isfinite(ppd) && ppd > 0.0) return ppd;
    } catch (const std::exception&) {
    }
    throw std::runtime_error("--ppd " + text + ": not a positive number of pixels per degree");
}

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-compare", [&] {
        // REF and TEST are positional; everything starting with '-' (and the
        // value of a flag that takes one) goes to Args, which rejects what it
        // does not know, e.g. the official tool's "-ppd".
        std::vector<char*> flagArgv{argv[0]};
        std::vector<std::string> files;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            if (a.empty() || a[0] != '-') {
                files.push_back(a);
                continue;
            }
            flagArgv.push_back(argv[i]);
            const bool takesValue = a == "--ppd" || a == "--map" || a == "--device" || a == "--log";
            if (takesValue && i + 1 < argc) flagArgv.push_back(argv[++i]);
        }
        const app::Args args(int(flagArgv.size()), flagArgv.data(), kUsage,
                             {{"ppd", "FLIP's pixels per degree (default 67.020645)"},
                              {"map", "FLIP.png: the FLIP error map through the magma colour ramp"}},
                             {});
        if (files.size() != 2) {
            throw std::runtime_error("expected two images, REF.png and TEST.png, got " + std::to_string(files.size()) +
                                     "\n" + kUsage);
        }
        const double ppd = parsePpd(args.get("ppd", std::to_string(metrics::kDefaultPpd)));

        const metrics::Image reference = metrics::loadPng(files[0]);
        const metrics::Image test = metrics::loadPng(files[1]);
        const metrics::FlipResult f = metrics::flip(reference, test, ppd);
        const double relMse = metrics::relMse(reference, test);
        const double psnr = metrics::psnr(reference, test);
        const double ssim = metrics::ssim(reference, test);
        if (args.has("map")) metrics::writeErrorMap(args.get("map", ""), f.errorMap, f.width, f.height);

        const std::string psnrText = std::isinf(psnr) ? "inf" : std::to_string(psnr);
        std::printf("flip_mean=%.6f flip_weighted_median=%.6f flip_q1=%.6f flip_q3=%.6f flip_min=%.6f flip_max=%.6f "
                    "relmse=%.6g psnr=%s ssim=%.6f\n",
                    f.stats.mean, f.stats.weightedMedian, f.stats.weightedQ1, f.stats.weightedQ3, f.stats.min,
                    f.stats.max, relMse, psnrText.c_str(), ssim);
        return 0;
    });
}
