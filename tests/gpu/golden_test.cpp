// Golden images of the whole reflection frame (passes/reflection_frame.h,
// run as glint-render runs it): 128x128 renders of the plaza and of a
// scene from ../shared/scenes (DamagedHelmet) in each mode, after four frames (so the
// feedback, history and motion paths have run), compared with the images
// under tests/golden/ within tolerances that allow other CPUs' LLVM code
// generation (lavapipe) but not a changed technique:
//   - mean absolute difference at most kMaxMeanDiff (8-bit units), and
//   - at most kMaxOutlierShare of the pixels differing by more than
//     kOutlierDiff in any channel.
// A failure keeps the actual image and a difference image (x8) under
// <build>/test-out/golden/. GLINT_UPDATE_GOLDEN=1 rewrites the goldens
// (review them before committing: they are what every later change is
// held to).
#include "support/gpu_test.h"

#include "common/reflection_run.h"
#include "glint/scene/builtin_scenes.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kSize = 128;
constexpr uint32_t kFrames = 4;
constexpr double kMaxMeanDiff = 1.0;
constexpr int kOutlierDiff = 24;
constexpr double kMaxOutlierShare = 0.005;

const std::filesystem::path kGoldenDir = GLINT_GOLDEN_DIR;
const std::filesystem::path kOutDir = GLINT_TEST_OUT_DIR;

std::vector<uint8_t> render(test::GpuTest& gpu, scene::Scene& scene, passes::ReflectionMode mode, float startSeconds) {
    app::ReflectionRunOptions options;
    options.width = kSize;
    options.height = kSize;
    options.frames = kFrames;
    options.startSeconds = startSeconds;
    options.frame.mode = mode;
    const app::ReflectionRunResult result = app::runReflections(gpu.ctx(), scene, options);
    REQUIRE(result.rgba.size() == size_t(kSize) * kSize * 4);
    return result.rgba;
}

void writePng(const std::filesystem::path& path, const std::vector<uint8_t>& rgba) {
    std::filesystem::create_directories(path.parent_path());
    REQUIRE(stbi_write_png(path.string().c_str(), kSize, kSize, 4, rgba.data(), kSize * 4) != 0);
}

void compareWithGolden(const std::string& name, const std::vector<uint8_t>& actual) {
    const std::filesystem::path golden = kGoldenDir / (name + ".png");
    if (const char* update = std::getenv("GLINT_UPDATE_GOLDEN"); update && std::string(update) == "1") {
        writePng(golden, actual);
        MESSAGE("updated " << golden.string());
        return;
    }
    int w = 0, h = 0, channels = 0;
    stbi_uc* pixels = stbi_load(golden.string().c_str(), &w, &h, &channels, 4);
    REQUIRE_MESSAGE(pixels != nullptr, "cannot read golden image " << golden.string()
                                                                   << " (GLINT_UPDATE_GOLDEN=1 writes it)");
    const std::vector<uint8_t> expected(pixels, pixels + size_t(w) * h * 4);
    stbi_image_free(pixels);
    REQUIRE(w == int(kSize));
    REQUIRE(h == int(kSize));

    double sum = 0.0;
    size_t outliers = 0;
    std::vector<uint8_t> diff(actual.size(), 255);
    for (size_t p = 0; p < size_t(kSize) * kSize; ++p) {
        int worst = 0;
        for (size_t c = 0; c < 3; ++c) {
            const int d = std::abs(int(actual[p * 4 + c]) - int(expected[p * 4 + c]));
            sum += d;
            worst = std::max(worst, d);
            diff[p * 4 + c] = uint8_t(std::min(255, d * 8));
        }
        outliers += worst > kOutlierDiff ? 1u : 0u;
    }
    const double mean = sum / (double(kSize) * kSize * 3);
    const double outlierShare = double(outliers) / (double(kSize) * kSize);
    INFO(name << ": mean difference " << mean << " (8-bit units), " << outliers << " pixels off by more than "
              << kOutlierDiff);
    const bool ok = mean <= kMaxMeanDiff && outlierShare <= kMaxOutlierShare;
    if (!ok) {
        writePng(kOutDir / (name + ".actual.png"), actual);
        writePng(kOutDir / (name + ".diff.png"), diff);
        MESSAGE("kept " << (kOutDir / (name + ".actual.png")).string() << " and the difference image");
    }
    CHECK(mean <= kMaxMeanDiff);
    CHECK(outlierShare <= kMaxOutlierShare);
}

void goldenModes(const std::string& sceneName, const std::string& stem, float startSeconds) {
    for (const passes::ReflectionMode mode :
         {passes::ReflectionMode::Hybrid, passes::ReflectionMode::Ssr, passes::ReflectionMode::Rt}) {
        const std::string name = stem + "_" + std::string(passes::modeName(mode));
        CAPTURE(name);
        test::GpuTest gpu;
        scene::Scene scene = scene::loadScene(sceneName);
        compareWithGolden(name, render(gpu, scene, mode, startSeconds));
    }
}

} // namespace

TEST_CASE("golden: the plaza in every mode") {
    // 3 s along the path: the view down the plaza past the puddles, as glint-render's default.
    goldenModes("plaza", "plaza", 3.0f);
}

TEST_CASE("golden: DamagedHelmet in every mode") {
    // Textured, metallic and rough at once: its pixels split between the
    // RT, hybrid and environment classes (the shared Cornell boxes are all
    // rougher than the cutoff, the spheres all within the near-RT band).
    const std::filesystem::path file = std::filesystem::path(GLINT_SCENES_DIR) / "DamagedHelmet" / "DamagedHelmet.gltf";
    REQUIRE_MESSAGE(std::filesystem::exists(file), "shared scene missing: " << file.string());
    goldenModes(file.string(), "helmet", 0.0f);
}
