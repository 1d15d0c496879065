// SSLR's hits lit as the ray sees them (passes/sslr.h, SslrSettings::
// relightHits) on a real device, validation on. The G-buffer lights a
// surface for the camera; a reflection ray sees it from elsewhere. In a
// mirror floor, the ray that meets a wall point comes from the camera's
// mirror image below the floor, so the wall as that image sees it (a
// G-buffer rendered from there) is what each hit must show: on a glossy
// wall whose sun highlight faces the image, not the camera, the two differ
// many times over.
#include "sslr_harness.h"

#include <sstream>

using namespace glint;
using namespace glint::sslr_test;

namespace {

// The wall's roughness: a highlight broad enough to vary smoothly over a
// texel of the image's view, narrow enough that the camera, 18 degrees off
// its peak, sees a few per cent of it. One the G-buffer's 8 bits hold
// exactly: SSLR re-lights with the stored roughness, the G-buffer lit
// with the material's, and at 0.3 (stored as 76/255) the re-lit peak came
// out 2.8% too high.
constexpr float kGlossyWall = 76.0f / 255.0f;
// The camera's mirror image in the floor (y = -1).
constexpr glm::vec3 kMirroredCamera{0.0f, -2.0f, 0.0f};

// mirrorScene's wall, glossy, under a sun mirrored about the wall's normal
// from the direction the wall's centre sees kMirroredCamera in: the
// highlight's peak faces the image.
scene::Scene glossyWallScene() {
    scene::Scene s = mirrorScene(kGlossyWall);
    const glm::vec3 toImage = glm::normalize(kMirroredCamera - glm::vec3(0.0f, 0.0f, -kWallDistance));
    s.sun.directionToLight = glm::vec3(-toImage.x, -toImage.y, toImage.z);
    return s;
}

// The mirror image's view is rendered this many times finer than the
// test's image, so that a bilinear lookup between its texels follows the
// highlight's peak (at the test's size it flattened it by 5%).
constexpr uint32_t kImageScale = 4;
constexpr uint32_t kImageSize = kSize * kImageScale;

// The G-buffer's lit colour as the camera's mirror image sees the scene,
// kImageSize texels square.
std::vector<glm::vec4> litFromImage(test::GpuTest& gpu, const scene::Scene& scene) {
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    scene::Camera camera = test::testCamera(kMirroredCamera);
    camera.resolution = {kImageSize, kImageSize};
    rg::HostReadback readback(ctx, size_t(kImageSize) * kImageSize * 8, "sslr_relight_test.lit");
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    readback.copy(graph, resources, gbuf.lit);
    const rg::Plan plan = graph.compile(executor.compileOptions());
    executor.run(plan, resources);
    executor.waitIdle();
    std::vector<glm::vec4> lit(size_t(kImageSize) * kImageSize);
    const std::span<const uint16_t> halves = readback.as<uint16_t>();
    for (size_t i = 0; i < lit.size(); ++i) {
        for (int c = 0; c < 4; ++c) lit[i][c] = glm::unpackHalf1x16(halves[4 * i + c]);
    }
    return lit;
}

// Bilinear between texel centres of a square image at a continuous texel
// position.
glm::vec3 bilinear(const std::vector<glm::vec4>& image, uint32_t size, glm::vec2 position) {
    const glm::vec2 p = position - 0.5f;
    const glm::ivec2 base = glm::ivec2(glm::floor(p));
    const glm::vec2 w = p - glm::vec2(base);
    const auto at = [&](int x, int y) {
        x = std::clamp(x, 0, int(size) - 1);
        y = std::clamp(y, 0, int(size) - 1);
        return glm::vec3(image[size_t(y) * size + size_t(x)]);
    };
    return glm::mix(glm::mix(at(base.x, base.y), at(base.x + 1, base.y), w.x),
                    glm::mix(at(base.x, base.y + 1), at(base.x + 1, base.y + 1), w.x), w.y);
}

struct Comparison {
    uint32_t hits = 0;
    // Hits in the highlight: where the image's view is at least 1.5x the
    // camera's at the same point.
    uint32_t highlight = 0;
    float largestError = 0.0f;  // |SSLR - the image's view| / |the image's view|
    std::string worst;          // where it is, what each view gives
};

glm::uvec2 sslrHitTexelOf(glm::vec2 uv) { return shader::sslrHitTexel(uv, glm::uvec2(kSize)); }

Comparison compare(const SslrFrame& f, const std::vector<glm::vec4>& mirrored) {
    Comparison c;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const size_t i = f.at(x, y);
            if (f.classes[i] != shader::kPixelHybrid || f.radiance[i].a != shader::kSslrHitRay ||
                !(f.confidence[i] >= passes::kDefaultConfidenceThreshold)) {
                continue;
            }
            // Where the pixel's mirror ray meets the wall, seen from the
            // image (the same 90-degree camera moved down by 2: y - 2 in its
            // view). Not the hit texel's centre: SSLR re-lights for the
            // ray's direction, and under a directional sun a flat wall's
            // light depends on nothing else.
            const glm::vec2 hit = wallHit(x, y);
            const glm::vec3 point{hit.x, hit.y, -kWallDistance};
            // Away from the wall's edges, where a bilinear tap leaves it.
            if (std::abs(point.x) > 4.0f || point.y < -0.6f || point.y > 0.6f) continue;
            const glm::vec2 imageNdc{point.x / kWallDistance, -(point.y - kMirroredCamera.y) / kWallDistance};
            const glm::vec3 expected = bilinear(mirrored, kImageSize, (imageNdc * 0.5f + 0.5f) * float(kImageSize));
            // The camera's view of the same point: the hit texel's own.
            const glm::vec3 camera = f.lit[size_t(sslrHitTexelOf(f.hit[i]).y) * kSize + sslrHitTexelOf(f.hit[i]).x];
            const glm::vec3 got = f.radiance[i];
            REQUIRE(glm::length(expected) > 0.0f);
            const float error = glm::length(got - expected) / glm::length(expected);
            if (error > c.largestError) {
                c.largestError = error;
                std::ostringstream where;
                where << "pixel " << x << ", " << y << ": wall point " << point.x << ", " << point.y << "; SSLR "
                      << got.r << " " << got.g << " " << got.b << ", from the image " << expected.r << " "
                      << expected.g << " " << expected.b << ", from the camera " << camera.r << " " << camera.g
                      << " " << camera.b;
                c.worst = where.str();
            }
            if (glm::length(expected) >= 1.5f * glm::length(camera)) ++c.highlight;
            ++c.hits;
        }
    }
    return c;
}

} // namespace

TEST_CASE("a glossy wall's highlight in a mirror floor is the wall as the camera's mirror image sees it") {
    test::GpuTest gpu;
    const scene::Scene scene = glossyWallScene();
    const std::vector<glm::vec4> mirrored = litFromImage(gpu, scene);
    passes::SslrSettings settings;
    REQUIRE(settings.relightHits);
    const Comparison relit = compare(traceScene(gpu, scene, 3, settings), mirrored);
    INFO("re-lit: " << relit.hits << " hits, " << relit.highlight << " in the highlight, largest error "
                    << relit.largestError << " at " << relit.worst);
    CHECK(relit.hits > 150);
    CHECK(relit.highlight > 20);
    CHECK(relit.largestError < 0.015f);
    // The lit colour as it is, the camera's: the highlight is missing.
    settings.relightHits = false;
    const Comparison asLit = compare(traceScene(gpu, scene, 3, settings), mirrored);
    INFO("as lit: largest error " << asLit.largestError << " at " << asLit.worst);
    CHECK(asLit.largestError > 0.3f);
}
