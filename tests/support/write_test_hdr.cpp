// Writes the equirectangular .hdr the glint-render environment test renders
// with: a sky gradient above the horizon, a darker ground, a small bright
// sun spot (a firefly for a prefilter without filtered importance
// sampling) and one NaN texel (stb writes it as black RGBE, so the file
// stays valid; the prefilter's own NaN handling is tested in
// tests/gpu/environment_test.cpp).
//   glint_write_test_hdr OUT.hdr WIDTH
#include <stb_image_write.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: glint_write_test_hdr OUT.hdr WIDTH\n");
        return 1;
    }
    const std::filesystem::path out = argv[1];
    const int width = std::atoi(argv[2]);
    if (width < 2 || width % 2 != 0) {
        std::fprintf(stderr, "glint_write_test_hdr: WIDTH must be even and at least 2\n");
        return 1;
    }
    const int height = width / 2;
    std::vector<float> rgb(size_t(width) * height * 3);
    for (int y = 0; y < height; ++y) {
        const float up = std::cos((float(y) + 0.5f) / float(height) * 3.14159265f);
        for (int x = 0; x < width; ++x) {
            float* t = &rgb[(size_t(y) * width + x) * 3];
            if (up >= 0.0f) {
                t[0] = 0.3f + 0.4f * (1.0f - up);
                t[1] = 0.5f + 0.3f * (1.0f - up);
                t[2] = 1.2f - 0.2f * (1.0f - up);
            } else {
                t[0] = 0.15f;
                t[1] = 0.12f;
                t[2] = 0.1f;
            }
        }
    }
    // The sun: 2x2 texels at 30 degrees elevation, 2000 times the sky.
    for (int y = height / 3 - 1; y <= height / 3; ++y) {
        for (int x = width / 4; x <= width / 4 + 1; ++x) {
            float* t = &rgb[(size_t(y) * width + x) * 3];
            t[0] = t[1] = t[2] = 2000.0f;
        }
    }
    rgb[(size_t(height / 2 + 3) * width + 5) * 3] = std::numeric_limits<float>::quiet_NaN();
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
    if (!stbi_write_hdr(out.string().c_str(), width, height, 3, rgb.data())) {
        std::fprintf(stderr, "glint_write_test_hdr: cannot write %s\n", out.string().c_str());
        return 1;
    }
    return 0;
}
