// glint-make-blue-noise OUT.bin: writes the blue noise the reflections
// sample (sampling/blue_noise.h): four channels of 64 x 64 x 32 scalar
// spatiotemporal blue noise. Run by the build; deterministic.
#include "glint/sampling/blue_noise.h"

#include <chrono>
#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: glint-make-blue-noise OUT.bin\n");
        return 2;
    }
    try {
        const auto start = std::chrono::steady_clock::now();
        const glint::sampling::BlueNoiseTexture texture =
            glint::sampling::makeBlueNoiseTexture({64, 64, 32}, 4, 0x5EEDB1E5u);
        glint::sampling::writeBlueNoise(argv[1], texture);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf("glint-make-blue-noise: %s (64x64x32, 4 channels) in %.1f s\n", argv[1], seconds);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glint-make-blue-noise: %s\n", e.what());
        return 1;
    }
    return 0;
}
