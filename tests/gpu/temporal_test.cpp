// Temporal accumulation (passes/temporal.h) and composite / debug views
// (passes/composite.h) on a real device, validation on, behind the real
// G-buffer, with the reflection radiance and hit distance uploaded by the
// test (so nothing depends on the passes between). Frames run back to back
// with two in flight; every frame has its own upload and readback buffers.
// Known answers: noise around a known mean shrinks like an average; NaN,
// Inf and 1e30 never reach a later frame; a disoccluded pixel shows the new
// surface in its first frame; reflection motion equals the closed-form
// motion of the virtual point (and of the surface when rough); a reset
// forgets; the composite matches a CPU reference of the documented maths;
// debug views map known values to known colours.
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/composite.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/temporal.h"
#include "glint/scene/animation.h"

#include "glint/ray_generation_shared.h"
#include "glint/temporal_shared.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/type_precision.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr size_t kPixels = size_t(kSize) * kSize;
using test::square;
using test::testCamera;

constexpr rg::BoundaryState kHostWrite =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

size_t at(uint32_t x, uint32_t y) { return size_t(y) * kSize + x; }

bool finite(glm::vec4 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

// Host buffers that outlive the frames using them (one per use: frames in
// flight never share one).
class Staging {
public:
    explicit Staging(gpu::Context& ctx) : ctx_(ctx) {}

    const gpu::Buffer& upload(const void* data, size_t bytes) {
        buffers_.emplace_back(ctx_, gpu::BufferDesc{bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                                    "temporal_test.upload"});
        std::memcpy(buffers_.back().mapped(), data, bytes);
        return buffers_.back();
    }
    const rg::HostReadback& readback(size_t bytes, const std::string& name) {
        return readbacks_.emplace_back(ctx_, bytes, "readback." + name);
    }

private:
    gpu::Context& ctx_;
    std::deque<gpu::Buffer> buffers_;
    std::deque<rg::HostReadback> readbacks_;
};

// A kSize x kSize texture of `format` filled from `data` by a copy inside
// the graph.
rg::Texture uploadTexture(rg::Graph& graph, rg::FrameResources& resources, Staging& staging, const std::string& name,
                          VkFormat format, const void* texels) {
    const gpu::Buffer& source = staging.upload(texels, kPixels * gpu::bytesPerTexel(format));
    const rg::Buffer imported = graph.importBuffer(
        name + ".staging", {{source.size()}, kHostWrite, rg::BoundaryState::of(rg::Access::TransferSrc)});
    resources.bind(imported, source);
    struct Data {
        rg::Buffer source;
        rg::Texture texture;
    };
    const Data& d = graph.addPass<Data>(
        "upload." + name, rg::Queue::Graphics,
        [&](rg::Builder& b, Data& data) {
            data.source = b.read(imported, rg::Access::TransferSrc);
            data.texture = b.write(b.createTexture(name, {.width = kSize, .height = kSize, .format = format}),
                                   rg::Access::TransferDst);
        },
        [](const Data& data, rg::PassContext& pc) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {kSize, kSize, 1};
            vkCmdCopyBufferToImage(pc.cmd(), pc.buffer(data.source).handle(), pc.image(data.texture).handle(),
                                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        });
    return d.texture;
}

// Copies a kSize x kSize texture into a new host buffer inside the graph.
const gpu::Buffer& readTexture(rg::Graph& graph, rg::FrameResources& resources, Staging& staging, rg::Texture texture,
                               VkFormat format, const std::string& name) {
    const rg::HostReadback& target = staging.readback(kPixels * gpu::bytesPerTexel(format), name);
    target.copy(graph, resources, texture);
    return target.buffer();
}

std::vector<glm::vec4> halves(const gpu::Buffer& b, int components) {
    std::vector<glm::vec4> out(kPixels, glm::vec4(0.0f));
    const uint16_t* h = reinterpret_cast<const uint16_t*>(b.mapped());
    for (size_t i = 0; i < kPixels; ++i) {
        for (int c = 0; c < components; ++c) out[i][c] = glm::unpackHalf1x16(h[i * components + c]);
    }
    return out;
}

std::vector<glm::u8vec4> bytes4(const gpu::Buffer& b) {
    std::vector<glm::u8vec4> out(kPixels);
    std::memcpy(out.data(), b.mapped(), kPixels * 4);
    return out;
}

// ---------------------------------------------------------------- scenes

scene::Material material(float roughness, float metallic, glm::vec3 albedo = glm::vec3(0.8f)) {
    scene::Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    m.roughnessFactor = roughness;
    m.metallicFactor = metallic;
    return m;
}

// One instance per geometry, so a test can move each.
scene::Scene makeScene(std::vector<scene::Geometry> geometries, std::vector<scene::Material> materials) {
    scene::Scene s;
    s.name = "temporal-test";
    s.materials = std::move(materials);
    for (size_t i = 0; i < geometries.size(); ++i) {
        scene::Mesh mesh;
        mesh.name = "object" + std::to_string(i);
        mesh.lods.push_back({{std::move(geometries[i])}});
        scene::Instance inst;
        inst.name = mesh.name;
        s.meshes.push_back(std::move(mesh));
        inst.mesh = uint32_t(i);
        s.instances.push_back(inst);
    }
    scene::prepareScene(s);
    return s;
}

constexpr float kWallDistance = 5.0f;

// A wall filling the image at z = -kWallDistance, facing the camera.
scene::Scene wallScene(const scene::Material& m) {
    return makeScene({square({0, 0, -kWallDistance}, {1, 0, 0}, {0, 1, 0}, 50.0f, 0)}, {m});
}

// ---------------------------------------------------------------- the temporal rig

struct FrameInput {
    std::vector<glm::vec4> radiance = std::vector<glm::vec4>(kPixels, glm::vec4(0.0f));  // uploaded as RGBA32F
    std::vector<float> hitDistance = std::vector<float>(kPixels, 2.0f);
    scene::Camera camera = testCamera();
    bool reset = false;
    // TemporalInputs::sharedRayRoughness (above 1: no pixel shares rays).
    float sharedRayRoughness = 2.0f;
    // Called before the frame's G-buffer is declared (moves objects).
    std::function<void(scene::Scene&)> update;
};

struct FrameOutput {
    std::vector<glm::vec4> resolved;
    std::vector<glm::vec2> motion;
    std::vector<float> length;
};

// Each run has a device of its own: the 1.3.239 layer's synchronization
// validation cannot see the host waits between independent executors, and
// takes memory reused across them for a race.
std::vector<FrameOutput> runTemporal(scene::Scene& scene, const std::vector<FrameInput>& frames,
                                     const passes::TemporalSettings& settings = {}) {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx, 2);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::TemporalPipelines pipelines(ctx);
    Staging staging(ctx);
    std::vector<std::array<const gpu::Buffer*, 3>> readbacks;
    for (size_t f = 0; f < frames.size(); ++f) {
        const FrameInput& in = frames[f];
        if (in.update) in.update(scene);
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {in.camera});
        const rg::Texture radiance = uploadTexture(graph, resources, staging, "test.radiance",
                                                   VK_FORMAT_R32G32B32A32_SFLOAT, in.radiance.data());
        const rg::Texture hit =
            uploadTexture(graph, resources, staging, "test.hit", VK_FORMAT_R32_SFLOAT, in.hitDistance.data());
        passes::TemporalInputs inputs{gbuf, radiance, hit, in.camera, uint64_t(f), in.reset};
        inputs.sharedRayRoughness = in.sharedRayRoughness;
        const passes::TemporalOutputs out = passes::addTemporalPass(graph, pipelines, inputs, settings);
        REQUIRE(out.width == kSize);
        readbacks.push_back({&readTexture(graph, resources, staging, out.resolved, passes::kTemporalResolvedFormat,
                                          "resolved"),
                             &readTexture(graph, resources, staging, out.reflectionMotion,
                                          passes::kTemporalMotionFormat, "motion"),
                             &readTexture(graph, resources, staging, out.historyLength,
                                          passes::kTemporalHistoryLengthFormat, "length")});
        const rg::Plan plan = graph.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor.run(plan, resources);
    }
    executor.waitIdle();
    std::vector<FrameOutput> outputs;
    for (const auto& r : readbacks) {
        FrameOutput o;
        o.resolved = halves(*r[0], 4);
        for (const glm::vec4& m : halves(*r[1], 2)) o.motion.emplace_back(m.x, m.y);
        for (const glm::vec4& l : halves(*r[2], 1)) o.length.push_back(l.x);
        outputs.push_back(std::move(o));
    }
    return outputs;
}

// A smooth mean per pixel (so neighbourhoods are nearly flat) and uniform
// noise of +-amplitude per channel, new every frame, from a fixed seed.
glm::vec4 meanRadiance(uint32_t x, uint32_t y) {
    return {0.4f + 0.4f * float(x) / kSize, 0.5f, 0.9f - 0.4f * float(y) / kSize, 1.0f};
}

std::vector<FrameInput> noisyFrames(uint32_t count, float amplitude, uint32_t seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-amplitude, amplitude);
    std::vector<FrameInput> frames(count);
    for (FrameInput& f : frames) {
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const glm::vec4 m = meanRadiance(x, y);
                f.radiance[at(x, y)] = {m.x + noise(rng), m.y + noise(rng), m.z + noise(rng), 1.0f};
            }
        }
    }
    return frames;
}

// Root-mean-square error of rgb against the mean over the image.
float rmsError(const std::vector<glm::vec4>& image) {
    double sum = 0.0;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const glm::vec3 d = glm::vec3(image[at(x, y)]) - glm::vec3(meanRadiance(x, y));
            sum += glm::dot(d, d) / 3.0;
        }
    }
    return float(std::sqrt(sum / kPixels));
}

} // namespace

// ---------------------------------------------------------------- temporal

TEST_CASE("noisy reflections of a static mirror converge towards their mean like an average of the frames") {
    scene::Scene scene = wallScene(material(0.05f, 1.0f));
    constexpr uint32_t kFrames = 24;
    const std::vector<FrameInput> frames = noisyFrames(kFrames, 0.3f);
    const std::vector<FrameOutput> out = runTemporal(scene, frames);

    const float single = rmsError(frames[0].radiance);
    // The first frame has no history: it is the input (a mirror: no blur).
    CHECK(rmsError(out[0].resolved) == doctest::Approx(single).epsilon(0.01));
    for (size_t i = 0; i < kPixels; ++i) {
        REQUIRE(out[0].length[i] == 1.0f);
        REQUIRE(out.back().length[i] == float(kFrames));
        REQUIRE(out.back().resolved[i].w == 1.0f);
    }
    // A plain average of 24 frames leaves 1 / sqrt(24) = 0.20 of the noise;
    // the clamp may cost a little of that.
    const float converged = rmsError(out.back().resolved);
    MESSAGE("single-frame rms " << single << ", after " << kFrames << " frames " << converged);
    CHECK(converged < 0.3f * single);
    // Without a bias: the mean error over the image is far below the
    // per-pixel noise left (a history that rounds would drift darker).
    glm::dvec3 bias(0.0);
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            bias += glm::dvec3(glm::vec3(out.back().resolved[at(x, y)]) - glm::vec3(meanRadiance(x, y)));
        }
    }
    bias /= double(kPixels);
    MESSAGE("mean error " << bias.x << " " << bias.y << " " << bias.z);
    CHECK(glm::length(bias) < 0.003);
    // And it shrinks on the way.
    CHECK(rmsError(out[3].resolved) < 0.65f * single);
    CHECK(rmsError(out[11].resolved) < rmsError(out[3].resolved));
}

TEST_CASE("the spatial filter smooths a rough reflection in its first frame and leaves a mirror alone") {
    const std::vector<FrameInput> frames = noisyFrames(1, 0.3f);
    const float single = rmsError(frames[0].radiance);
    scene::Scene rough = wallScene(material(0.5f, 1.0f));
    const std::vector<FrameOutput> blurred = runTemporal(rough, frames);
    scene::Scene mirror = wallScene(material(0.0f, 1.0f));
    const std::vector<FrameOutput> sharp = runTemporal(mirror, frames);
    MESSAGE("rms: input " << single << ", rough " << rmsError(blurred[0].resolved) << ", mirror "
                          << rmsError(sharp[0].resolved));
    // A 5x5 Gaussian of sigma 1.5 averages ~20 pixels' worth of noise.
    CHECK(rmsError(blurred[0].resolved) < 0.4f * single);
    for (size_t i = 0; i < kPixels; ++i) {
        const glm::vec3 d = glm::vec3(sharp[0].resolved[i]) - glm::vec3(frames[0].radiance[i]);
        REQUIRE(glm::length(d) < 2e-3f);  // half-float rounding
    }
}

TEST_CASE("NaN, Inf and 1e30 injected in one frame leave every later frame finite and bounded") {
    scene::Scene scene = wallScene(material(0.05f, 1.0f));
    constexpr uint32_t kFrames = 10;
    constexpr uint32_t kBad = 4;
    std::vector<FrameInput> frames = noisyFrames(kFrames, 0.3f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    FrameInput& bad = frames[kBad];
    bad.radiance[at(20, 20)] = {nan, nan, nan, 1.0f};
    bad.radiance[at(40, 40)] = {1e30f, 1e30f, 1e30f, 1.0f};
    bad.radiance[at(41, 40)] = {0.5f, -1e30f, 0.5f, 1.0f};
    bad.radiance[at(10, 50)] = {inf, 0.5f, 0.5f, 1.0f};
    bad.radiance[at(50, 10)] = {0.5f, 0.5f, -inf, 1.0f};
    bad.radiance[at(30, 5)] = {0.5f, 0.5f, 0.5f, nan};  // not even the mask is a number
    bad.hitDistance[at(30, 30)] = nan;
    bad.hitDistance[at(31, 30)] = -inf;
    bad.hitDistance[at(32, 30)] = 1e30f;
    // The G-buffer's motion is finite; the pass must not trust that either,
    // but it cannot be injected without editing the G-buffer.
    const std::vector<FrameOutput> out = runTemporal(scene, frames);
    // Every clean input lies below 0.8 + 0.3 = 1.1.
    for (uint32_t f = 0; f < kFrames; ++f) {
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("frame " << f << " pixel " << x << ", " << y);
                const glm::vec4 v = out[f].resolved[at(x, y)];
                REQUIRE(finite(v));
                REQUIRE(std::isfinite(out[f].length[at(x, y)]));
                REQUIRE(std::isfinite(out[f].motion[at(x, y)].x));
                REQUIRE(std::isfinite(out[f].motion[at(x, y)].y));
                REQUIRE(v.x >= 0.0f);
                REQUIRE(v.y >= 0.0f);
                REQUIRE(v.z >= 0.0f);
                if (f > kBad) {
                    // The next frame clips the spike to its neighbourhood.
                    REQUIRE(std::max({v.x, v.y, v.z}) <= 1.2f);
                }
                // From the bad frame on, every pixel is an average of at
                // least five frames near its mean (max error of ~12k
                // samples of sigma 0.17 / sqrt(5): ~0.3), but for the
                // spiked, zeroed and unmasked pixels of the bad frame.
                const bool excused = f == kBad && (at(x, y) == at(40, 40) || at(x, y) == at(41, 40) ||
                                                   at(x, y) == at(30, 5));
                if (f >= kBad && !excused) {
                    const glm::vec3 error = glm::abs(glm::vec3(v) - glm::vec3(meanRadiance(x, y)));
                    REQUIRE(std::max({error.x, error.y, error.z}) < 0.45f);
                }
            }
        }
    }
    // The NaN pixel took its neighbours' mean in the bad frame.
    const glm::vec3 nanPixel = out[kBad].resolved[at(20, 20)];
    CHECK(glm::length(nanPixel - glm::vec3(meanRadiance(20, 20))) < 0.3f);
    // The pixel whose mask was NaN reflects nothing that frame.
    CHECK(out[kBad].resolved[at(30, 5)] == glm::vec4(0.0f));
    CHECK(out[kBad].length[at(30, 5)] == 0.0f);
    // Several frames later the spiked pixel is back near its mean.
    CHECK(glm::length(glm::vec3(out.back().resolved[at(40, 40)]) - glm::vec3(meanRadiance(40, 40))) < 0.3f);
}

TEST_CASE("a disoccluded surface shows its own radiance in its first frame, without a ghost of the occluder") {
    // A small square 4 units in front of the camera covers pixels 24..39 in
    // x and y of a wall at 10 units, then jumps out of view.
    constexpr uint32_t kMoveFrame = 8;
    constexpr uint32_t kFrames = 11;
    const glm::vec4 objectRadiance(1.0f, 0.2f, 0.1f, 1.0f);
    const glm::vec4 wallRadiance(0.1f, 0.3f, 1.0f, 1.0f);
    const auto covered = [](uint32_t x, uint32_t y) { return x >= 24 && x < 40 && y >= 24 && y < 40; };
    for (const bool clamp : {false, true}) {
        CAPTURE(clamp);
        scene::Scene scene = makeScene({square({0, 0, -10}, {1, 0, 0}, {0, 1, 0}, 50.0f, 0),
                                        square({0, 0, -4}, {1, 0, 0}, {0, 1, 0}, 1.0f, 0)},
                                       {material(0.05f, 1.0f)});
        std::vector<FrameInput> frames(kFrames);
        for (uint32_t f = 0; f < kFrames; ++f) {
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    frames[f].radiance[at(x, y)] = f < kMoveFrame && covered(x, y) ? objectRadiance : wallRadiance;
                }
            }
        }
        const glm::mat4 away = glm::translate(glm::mat4(1.0f), glm::vec3(100.0f, 0.0f, 0.0f));
        frames[kMoveFrame].update = [away](scene::Scene& s) {
            s.instances[1].previousTransform = s.instances[1].transform;
            s.instances[1].transform = away;
        };
        frames[kMoveFrame + 1].update = [away](scene::Scene& s) { s.instances[1].previousTransform = away; };
        passes::TemporalSettings settings;
        // Without the clamp only the history rejection can stop the ghost.
        settings.neighbourhoodClamp = clamp;
        const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);

        // Before the move the object's pixels hold the object.
        CHECK(glm::length(glm::vec3(out[kMoveFrame - 1].resolved[at(32, 32)] - objectRadiance)) < 0.01f);
        CHECK(out[kMoveFrame - 1].length[at(32, 32)] == float(kMoveFrame));
        for (uint32_t f = kMoveFrame; f < kFrames; ++f) {
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    INFO("frame " << f << " pixel " << x << ", " << y);
                    const glm::vec4 v = out[f].resolved[at(x, y)];
                    REQUIRE(glm::length(glm::vec3(v - wallRadiance)) < 0.01f);
                    if (covered(x, y)) {
                        // The history was rejected: it starts over.
                        REQUIRE(out[f].length[at(x, y)] == float(f - kMoveFrame + 1));
                    } else {
                        REQUIRE(out[f].length[at(x, y)] == float(f + 1));
                    }
                }
            }
        }
    }
}

TEST_CASE("reflection motion follows the reflected point for a mirror and the surface for a rough wall") {
    // The camera steps 0.5 to the right between two frames. A point at view
    // depth z moves 0.5 * 32 / z pixels to the right on the image (32 pixels
    // per unit at depth 1): last frame's pixel = this frame's + motion.
    // The virtual point of a wall pixel lies hitDistance further along the
    // view ray; a miss (kMissHitDistance) is a point at infinity, which a
    // translation does not move.
    constexpr float kStep = 0.5f;
    constexpr float kHit = 3.0f;
    for (const float roughness : {0.0f, 0.8f}) {
        CAPTURE(roughness);
        scene::Scene scene = wallScene(material(roughness, 1.0f));
        std::vector<FrameInput> frames(2);
        scene::Camera camera = testCamera();
        frames[0].camera = camera;
        camera.advance({{kStep, 0, 0}, {kStep, 0, -1}, {0, 1, 0}}, 1);
        frames[1].camera = camera;
        for (FrameInput& f : frames) {
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    f.radiance[at(x, y)] = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
                    f.hitDistance[at(x, y)] = x < kSize / 2 ? kHit : shader::kMissHitDistance;
                }
            }
        }
        const std::vector<FrameOutput> out = runTemporal(scene, frames);
        const FrameOutput& f = out[1];
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                INFO("pixel " << x << ", " << y);
                const glm::vec2 ndc = test::pixelNdc(x, y);
                // The wall point under the pixel, from the new camera, and the
                // unit view ray's z.
                const glm::vec3 ray = glm::normalize(glm::vec3(ndc.x, -ndc.y, -1.0f));
                const float depth = kWallDistance - kHit * ray.z;  // ray.z < 0: further
                float expected = kStep * 32.0f / kWallDistance;      // the surface
                if (roughness == 0.0f) {
                    expected = x < kSize / 2 ? kStep * 32.0f / depth : 0.0f;
                }
                const glm::vec2 motion = f.motion[at(x, y)];
                REQUIRE(std::abs(motion.x - expected) < 0.02f);
                REQUIRE(std::abs(motion.y) < 0.02f);
                // The history was found wherever last frame saw the point.
                if (x + 4 < kSize) {
                    REQUIRE(f.length[at(x, y)] == 2.0f);
                }
            }
        }
    }
}

TEST_CASE("a jittered camera keeps the history of a grazing floor") {
    // Rasterisation moves by a sub-pixel jitter every frame; positions are
    // reconstructed with the jittered matrices, so a floor seen at grazing
    // angles (depth changing fast across pixels) still lies on its own
    // plane frame after frame.
    constexpr uint32_t kFrames = 8;
    scene::Scene scene = makeScene({square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f, 0)}, {material(0.05f, 1.0f)});
    std::vector<FrameInput> frames(kFrames);
    scene::Camera camera = testCamera();
    camera.jitter = true;
    const scene::CameraPose pose{{0, 0, 0}, {0, 0, -1}, {0, 1, 0}};
    camera.reset(pose, 0);
    for (uint32_t f = 0; f < kFrames; ++f) {
        if (f > 0) camera.advance(pose, f);
        frames[f].camera = camera;
        std::fill(frames[f].radiance.begin(), frames[f].radiance.end(), glm::vec4(0.5f, 0.6f, 0.7f, 1.0f));
    }
    REQUIRE(frames[1].camera.jitterPixels != frames[2].camera.jitterPixels);
    const std::vector<FrameOutput> out = runTemporal(scene, frames);
    // The floor fills the lower half; a few rows below the horizon the
    // floor is still 5-10 units away at angles of a few degrees.
    for (uint32_t y = kSize / 2 + 2; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y);
            REQUIRE(out.back().length[at(x, y)] == float(kFrames));
            REQUIRE(glm::length(glm::vec3(out.back().resolved[at(x, y)]) - glm::vec3(0.5f, 0.6f, 0.7f)) < 2e-3f);
        }
    }
}

TEST_CASE("a reset discards the history; without it the history lingers") {
    constexpr uint32_t kFrames = 6;
    const glm::vec4 before(1.0f, 0.0f, 0.0f, 1.0f);
    const glm::vec4 after(0.0f, 0.0f, 1.0f, 1.0f);
    for (const bool reset : {true, false}) {
        CAPTURE(reset);
        scene::Scene scene = wallScene(material(0.05f, 1.0f));
        std::vector<FrameInput> frames(kFrames);
        for (uint32_t f = 0; f < kFrames; ++f) {
            std::fill(frames[f].radiance.begin(), frames[f].radiance.end(), f + 1 < kFrames ? before : after);
        }
        frames.back().reset = reset;
        passes::TemporalSettings settings;
        settings.neighbourhoodClamp = false;
        const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);
        const glm::vec4 v = out.back().resolved[at(32, 32)];
        if (reset) {
            CHECK(glm::length(glm::vec3(v - after)) < 1e-3f);
            CHECK(out.back().length[at(32, 32)] == 1.0f);
        } else {
            // One new frame of six.
            CHECK(glm::length(glm::vec3(v) - glm::mix(glm::vec3(before), glm::vec3(after), 1.0f / 6.0f)) < 2e-3f);
            CHECK(out.back().length[at(32, 32)] == 6.0f);
        }
    }
}

TEST_CASE("the clip box spans 5x5 where rays are shared, 3x3 where each pixel has its own") {
    // A history of 0.5; then a frame of 0.1 in the 3x3 around the centre
    // and 0.9 beyond. The 3x3 box holds only 0.1: the history is clipped to
    // it. The 5x5 box also holds sixteen 0.9s, wide enough for 0.5 to
    // stand: the new frame takes half (two frames of history).
    constexpr uint32_t kCentre = 32;
    for (const bool shared : {false, true}) {
        CAPTURE(shared);
        scene::Scene scene = wallScene(material(0.05f, 1.0f));
        std::vector<FrameInput> frames(2);
        std::fill(frames[0].radiance.begin(), frames[0].radiance.end(), glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const bool inner = std::max(std::abs(int(x) - int(kCentre)), std::abs(int(y) - int(kCentre))) <= 1;
                const float v = inner ? 0.1f : 0.9f;
                frames[1].radiance[at(x, y)] = glm::vec4(v, v, v, 1.0f);
            }
        }
        for (FrameInput& f : frames) f.sharedRayRoughness = shared ? 0.0f : 2.0f;
        passes::TemporalSettings settings;
        settings.clampRadius = 2;
        const std::vector<FrameOutput> out = runTemporal(scene, frames, settings);
        const float v = out.back().resolved[at(kCentre, kCentre)].g;
        CHECK(out.back().length[at(kCentre, kCentre)] == 2.0f);
        if (shared) {
            CHECK(v == doctest::Approx(0.3f).epsilon(0.01));
        } else {
            CHECK(v == doctest::Approx(0.1f).epsilon(0.01));
        }
    }
}

TEST_CASE("temporal settings out of range are an error naming the pass") {
    test::GpuTest gpu;
    passes::TemporalPipelines pipelines(gpu.ctx());
    rg::Graph graph;
    passes::GBufferOutputs gbuf;
    gbuf.width = kSize;
    gbuf.height = kSize;
    const rg::Texture fake = graph.createTexture("fake", {.width = kSize, .height = kSize,
                                                          .format = VK_FORMAT_R16G16B16A16_SFLOAT});
    passes::TemporalSettings settings;
    settings.maxHistoryFrames = 0.0f;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("addTemporalPass"), gpu::GpuError);
    settings = {};
    settings.spatialRadius = 9;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("addTemporalPass"), gpu::GpuError);
    settings = {};
    settings.clampRadius = shader::kTemporalMaxClampRadius + 1;
    CHECK_THROWS_WITH_AS(passes::addTemporalPass(graph, pipelines, {gbuf, fake, fake, testCamera()}, settings),
                         doctest::Contains("clampRadius <= 3"), gpu::GpuError);
}

// ---------------------------------------------------------------- composite

namespace {

// Independent CPU versions of the documented maths (passes/composite.h).
float srgbEncode(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

float srgbDecode(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

glm::vec3 khronosPbrNeutral(glm::vec3 c) {
    const float x = std::min({c.r, c.g, c.b});
    const float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
    c -= offset;
    const float peak = std::max({c.r, c.g, c.b});
    const float start = 0.76f;
    if (peak < start) return c;
    const float d = 1.0f - start;
    const float newPeak = 1.0f - d * d / (peak + d - start);
    c *= newPeak / peak;
    const float g = 1.0f - 1.0f / (0.15f * (peak - newPeak) + 1.0f);
    return glm::mix(c, glm::vec3(newPeak), g);
}

glm::vec3 acesFitted(glm::vec3 x) {
    return glm::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

glm::vec3 tonemap(glm::vec3 c, passes::Tonemap op) {
    c = glm::max(c, glm::vec3(0.0f));
    switch (op) {
    case passes::Tonemap::AcesFitted: return acesFitted(c);
    case passes::Tonemap::Clamp: return glm::clamp(c, 0.0f, 1.0f);
    default: return glm::clamp(khronosPbrNeutral(c), 0.0f, 1.0f);
    }
}

glm::ivec3 toBytes(glm::vec3 display) {
    return {int(std::lround(255.0f * srgbEncode(display.r))), int(std::lround(255.0f * srgbEncode(display.g))),
            int(std::lround(255.0f * srgbEncode(display.b)))};
}

// Karis 2014, EnvBRDFApprox.
glm::vec3 envBrdf(glm::vec3 f0, float roughness, float NoV) {
    const glm::vec4 r =
        roughness * glm::vec4(-1.0f, -0.0275f, -0.572f, 0.022f) + glm::vec4(1.0f, 0.0425f, 1.04f, -0.04f);
    const float a004 = std::min(r.x * r.x, std::exp2(-9.28f * NoV)) * r.x + r.y;
    const float scale = -1.04f * a004 + r.z;
    const float bias = 1.04f * a004 + r.w;
    return f0 * scale + bias;
}

bool near(glm::u8vec4 got, glm::ivec3 expected, int tolerance = 1) {
    return std::abs(int(got.r) - expected.r) <= tolerance && std::abs(int(got.g) - expected.g) <= tolerance &&
           std::abs(int(got.b) - expected.b) <= tolerance && got.a == 255;
}

// One composite per settings, with and without reflections, all in one
// graph over one G-buffer.
struct CompositeRun {
    std::vector<std::vector<glm::u8vec4>> withReflections;     // per settings
    std::vector<std::vector<glm::u8vec4>> withoutReflections;  // per settings
    std::vector<glm::vec4> lit;
    std::vector<glm::u8vec4> albedo;
    std::vector<glm::u8vec4> roughnessMetal;
};

CompositeRun runComposite(const scene::Scene& scene, const std::vector<glm::vec4>& reflections,
                          const std::vector<passes::CompositeSettings>& settings) {
    test::GpuTest gpu;  // one device per run, as runTemporal
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::CompositePipelines pipelines(ctx);
    Staging staging(ctx);
    const scene::Camera camera = testCamera();
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    const rg::Texture refl = uploadTexture(graph, resources, staging, "test.reflections",
                                           VK_FORMAT_R32G32B32A32_SFLOAT, reflections.data());
    std::vector<const gpu::Buffer*> with, without;
    for (size_t i = 0; i < settings.size(); ++i) {
        const passes::CompositeOutputs a =
            passes::addCompositePass(graph, pipelines, {gbuf, refl, camera}, settings[i]);
        const passes::CompositeOutputs b = passes::addCompositePass(graph, pipelines, {gbuf, {}, camera}, settings[i]);
        REQUIRE(a.width == kSize);
        with.push_back(&readTexture(graph, resources, staging, a.color, passes::kCompositeFormat,
                                    "with" + std::to_string(i)));
        without.push_back(&readTexture(graph, resources, staging, b.color, passes::kCompositeFormat,
                                       "without" + std::to_string(i)));
    }
    const gpu::Buffer& lit = readTexture(graph, resources, staging, gbuf.lit, passes::kGBufferLitFormat, "lit");
    const gpu::Buffer& albedo =
        readTexture(graph, resources, staging, gbuf.albedo, passes::kGBufferAlbedoFormat, "albedo");
    const gpu::Buffer& rm = readTexture(graph, resources, staging, gbuf.roughnessMetal,
                                        passes::kGBufferRoughnessMetalFormat, "roughness_metal");
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const auto report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    executor.run(plan, resources);
    executor.waitIdle();
    CompositeRun run{{}, {}, halves(lit, 4), bytes4(albedo), bytes4(rm)};
    for (const gpu::Buffer* b : with) run.withReflections.push_back(bytes4(*b));
    for (const gpu::Buffer* b : without) run.withoutReflections.push_back(bytes4(*b));
    return run;
}

} // namespace

TEST_CASE("the composite adds the reflection times the environment BRDF, then exposure, tonemap and sRGB") {
    const scene::Scene scene = wallScene(material(0.4f, 0.3f, {0.8f, 0.5f, 0.2f}));
    // Reflections everywhere but the left quarter (a = 0 there: lit only).
    std::vector<glm::vec4> reflections(kPixels);
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            reflections[at(x, y)] = x < kSize / 4 ? glm::vec4(5.0f, 5.0f, 5.0f, 0.0f)
                                                  : glm::vec4(0.6f + 0.02f * float(y), 0.9f, 1.2f, 1.0f);
        }
    }
    std::vector<passes::CompositeSettings> settings;
    for (const passes::Tonemap op :
         {passes::Tonemap::KhronosPbrNeutral, passes::Tonemap::AcesFitted, passes::Tonemap::Clamp}) {
        for (const float exposure : {1.0f, 3.0f}) settings.push_back({exposure, op});
    }
    const CompositeRun run = runComposite(scene, reflections, settings);
    for (size_t k = 0; k < settings.size(); ++k) {
        CAPTURE(int(settings[k].tonemap));
        CAPTURE(settings[k].exposure);
        for (const bool withReflections : {true, false}) {
            CAPTURE(withReflections);
            const std::vector<glm::u8vec4>& image =
                withReflections ? run.withReflections[k] : run.withoutReflections[k];
            for (uint32_t y = 0; y < kSize; ++y) {
                for (uint32_t x = 0; x < kSize; ++x) {
                    INFO("pixel " << x << ", " << y);
                    const size_t i = at(x, y);
                    glm::vec3 color = run.lit[i];
                    if (withReflections && reflections[i].w > 0.0f) {
                        // The wall point under the pixel, seen from the origin.
                        const glm::vec2 ndc = test::pixelNdc(x, y);
                        const glm::vec3 p(ndc.x * kWallDistance, -ndc.y * kWallDistance, -kWallDistance);
                        const float NoV = glm::dot(glm::vec3(0, 0, 1), glm::normalize(-p));
                        const glm::vec3 albedo(srgbDecode(run.albedo[i].r / 255.0f),
                                               srgbDecode(run.albedo[i].g / 255.0f),
                                               srgbDecode(run.albedo[i].b / 255.0f));
                        const float roughness = run.roughnessMetal[i].r / 255.0f;
                        const float metallic = run.roughnessMetal[i].g / 255.0f;
                        const float reflectance = run.roughnessMetal[i].b / 255.0f;
                        const glm::vec3 f0 = glm::mix(glm::vec3(0.16f * reflectance * reflectance), albedo, metallic);
                        color += glm::vec3(reflections[i]) * envBrdf(f0, roughness, NoV);
                    }
                    const glm::ivec3 expected = toBytes(tonemap(color * settings[k].exposure, settings[k].tonemap));
                    REQUIRE_MESSAGE(near(image[i], expected),
                                    "got " << int(image[i].r) << " " << int(image[i].g) << " " << int(image[i].b)
                                           << ", expected " << expected.r << " " << expected.g << " "
                                           << expected.b);
                }
            }
        }
    }
}

TEST_CASE("the environment BRDF fit gives the split-sum values it is known for") {
    // Sanity of the CPU reference itself: at normal incidence a smooth
    // surface reflects F0 (scale ~1, bias ~0), at grazing angles it tends
    // to 1, and a rough surface reflects less at grazing angles.
    const glm::vec3 f0(0.04f);
    CHECK(envBrdf(f0, 0.0f, 1.0f).x == doctest::Approx(0.04f).epsilon(0.1));
    CHECK(envBrdf(f0, 0.0f, 0.0f).x > 0.9f);
    CHECK(envBrdf(f0, 1.0f, 0.0f).x < envBrdf(f0, 0.0f, 0.0f).x);
}

// ---------------------------------------------------------------- debug views

namespace {

struct DebugViewJob {
    VkFormat format;
    const void* texels;
    passes::DebugViewSettings settings;
};

// Every job's source uploaded and shown, all in one graph.
std::vector<std::vector<glm::u8vec4>> runDebugViews(const std::vector<DebugViewJob>& jobs) {
    test::GpuTest gpu;  // one device per run, as runTemporal
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::CompositePipelines pipelines(ctx);
    Staging staging(ctx);
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    std::vector<const gpu::Buffer*> colors;
    for (size_t i = 0; i < jobs.size(); ++i) {
        const std::string name = "test.source" + std::to_string(i);
        const rg::Texture source = uploadTexture(graph, resources, staging, name, jobs[i].format, jobs[i].texels);
        const passes::CompositeOutputs out =
            passes::addDebugViewPass(graph, pipelines, source, kSize, kSize, jobs[i].settings);
        colors.push_back(&readTexture(graph, resources, staging, out.color, passes::kCompositeFormat,
                                      "color" + std::to_string(i)));
    }
    const rg::Plan plan = graph.compile(executor.compileOptions());
    const auto report = rg::verify(plan);
    REQUIRE_MESSAGE(report.ok(), report.text());
    executor.run(plan, resources);
    executor.waitIdle();
    std::vector<std::vector<glm::u8vec4>> out;
    for (const gpu::Buffer* c : colors) out.push_back(bytes4(*c));
    return out;
}

std::vector<glm::u8vec4> runDebugView(VkFormat format, const void* texels, const passes::DebugViewSettings& settings) {
    return runDebugViews({{format, texels, settings}}).front();
}

// The viridis stops of passes/composite.h, as bytes.
const std::array<glm::ivec3, 5> kViridis = {glm::ivec3(68, 1, 84), glm::ivec3(59, 82, 139), glm::ivec3(33, 145, 140),
                                            glm::ivec3(94, 201, 98), glm::ivec3(253, 231, 37)};

glm::ivec3 viridis(float t) {
    const float s = std::clamp(t, 0.0f, 1.0f) * 4.0f;
    const int i = std::min(int(std::floor(s)), 3);
    const glm::vec3 c = glm::mix(glm::vec3(kViridis[i]), glm::vec3(kViridis[i + 1]), s - float(i));
    return {int(std::lround(c.r)), int(std::lround(c.g)), int(std::lround(c.b))};
}

} // namespace

TEST_CASE("a scalar debug view maps values through viridis over [min, max], and NaN and Inf to magenta") {
    constexpr float kMin = 2.0f, kMax = 10.0f;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<float> values(kPixels);
    std::vector<glm::ivec3> expected(kPixels);
    const std::array<float, 9> probes = {kMin - 5.0f, kMin, 3.0f, 4.0f, 6.0f, 8.5f, kMax, kMax + 100.0f, 7.3f};
    for (size_t i = 0; i < kPixels; ++i) {
        const float v = probes[i % probes.size()];
        values[i] = v;
        expected[i] = viridis((v - kMin) / (kMax - kMin));
    }
    values[100] = nan;
    values[101] = inf;
    values[102] = -inf;
    for (const size_t i : {100, 101, 102}) expected[i] = {255, 0, 255};
    passes::DebugViewSettings settings;
    settings.kind = passes::DebugViewKind::Scalar;
    settings.minValue = kMin;
    settings.maxValue = kMax;
    const std::vector<glm::u8vec4> out = runDebugView(VK_FORMAT_R32_SFLOAT, values.data(), settings);
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i << " value " << values[i]);
        REQUIRE(near(out[i], expected[i]));
    }
    // The stops themselves, exactly.
    CHECK(near(out[1], kViridis[0], 0));
    CHECK(near(out[3], kViridis[1], 0));
    CHECK(near(out[4], kViridis[2], 0));
    CHECK(near(out[6], kViridis[4], 0));
}

TEST_CASE("an unsigned-integer texture shows through the scalar view") {
    std::vector<uint32_t> values(kPixels);
    for (size_t i = 0; i < kPixels; ++i) values[i] = uint32_t(i % 5);
    passes::DebugViewSettings settings;
    settings.kind = passes::DebugViewKind::Scalar;
    settings.minValue = 0.0f;
    settings.maxValue = 4.0f;
    const std::vector<glm::u8vec4> out = runDebugView(VK_FORMAT_R32_UINT, values.data(), settings);
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i);
        REQUIRE(near(out[i], kViridis[values[i]], 0));
    }
}

TEST_CASE("a colour debug view tonemaps HDR values; a raw view passes display colours through") {
    std::vector<glm::vec4> hdr(kPixels);
    for (size_t i = 0; i < kPixels; ++i) {
        hdr[i] = glm::vec4(0.05f + 0.01f * float(i % 97), 0.3f, 4.0f * float(i % 7) / 7.0f, 1.0f);
    }
    std::vector<glm::u8vec4> classes(kPixels);
    for (size_t i = 0; i < kPixels; ++i) {
        classes[i] = glm::u8vec4(uint8_t(i * 7), uint8_t(255 - i), uint8_t(i / 16), 200);
    }
    const std::array<passes::Tonemap, 2> ops = {passes::Tonemap::KhronosPbrNeutral, passes::Tonemap::AcesFitted};
    std::vector<DebugViewJob> jobs;
    for (const passes::Tonemap op : ops) {
        passes::DebugViewSettings settings;
        settings.kind = passes::DebugViewKind::Color;
        settings.exposure = 2.0f;
        settings.tonemap = op;
        jobs.push_back({VK_FORMAT_R32G32B32A32_SFLOAT, hdr.data(), settings});
    }
    passes::DebugViewSettings raw;
    raw.kind = passes::DebugViewKind::Raw;
    jobs.push_back({VK_FORMAT_R8G8B8A8_UNORM, classes.data(), raw});
    const std::vector<std::vector<glm::u8vec4>> out = runDebugViews(jobs);
    for (size_t k = 0; k < ops.size(); ++k) {
        for (size_t i = 0; i < kPixels; ++i) {
            INFO("tonemap " << int(ops[k]) << " texel " << i);
            REQUIRE(near(out[k][i], toBytes(tonemap(glm::vec3(hdr[i]) * 2.0f, ops[k]))));
        }
    }
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i);
        REQUIRE(near(out[2][i], glm::ivec3(classes[i].r, classes[i].g, classes[i].b), 0));
    }
}

TEST_CASE("the G-buffer's depth shows through the scalar view") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const scene::Scene scene = wallScene(material(0.5f, 0.0f));
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::CompositePipelines pipelines(ctx);
    Staging staging(ctx);
    const scene::Camera camera = testCamera();
    rg::Graph graph(executor.queueCaps());
    rg::FrameResources resources;
    const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
    passes::DebugViewSettings settings;
    settings.kind = passes::DebugViewKind::Scalar;
    settings.maxValue = 0.1f;
    const passes::CompositeOutputs out = passes::addDebugViewPass(graph, pipelines, gbuf.depth, kSize, kSize, settings);
    const gpu::Buffer& color = readTexture(graph, resources, staging, out.color, passes::kCompositeFormat, "color");
    executor.run(graph.compile(executor.compileOptions()), resources);
    executor.waitIdle();
    const std::vector<glm::u8vec4> bytes = bytes4(color);
    // Reversed Z with an infinite far plane: depth = near / view depth, so
    // the wall is at 0.1 / 5 = 0.02, a fifth of the range.
    for (size_t i = 0; i < kPixels; ++i) {
        INFO("texel " << i);
        REQUIRE(near(bytes[i], viridis(0.2f)));
    }
}

TEST_CASE("a debug view refuses sources it cannot show, naming them") {
    test::GpuTest gpu;
    passes::CompositePipelines pipelines(gpu.ctx());
    rg::Graph graph;
    const rg::Texture ids = graph.createTexture("signed_ids", {.width = kSize, .height = kSize,
                                                               .format = VK_FORMAT_R32_SINT});
    CHECK_THROWS_WITH_AS(passes::addDebugViewPass(graph, pipelines, ids, kSize, kSize),
                         doctest::Contains("signed_ids"), gpu::GpuError);
    const rg::Texture small = graph.createTexture("small", {.width = 4, .height = 4,
                                                            .format = VK_FORMAT_R32_SFLOAT});
    CHECK_THROWS_WITH_AS(passes::addDebugViewPass(graph, pipelines, small, kSize, kSize),
                         doctest::Contains("small"), gpu::GpuError);
    rg::Graph other;
    CHECK_THROWS_AS(passes::addDebugViewPass(other, pipelines, small, 4, 4), gpu::GpuError);
}

// Not a check: GPU times of the passes at 1920x1080 on a wall of roughness
// 0.15 (both reprojections and the spatial filter active) under a moving
// camera. Run with --no-skip.
TEST_CASE("GPU time of temporal and composite at 1920x1080" * doctest::skip()) {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    scene::Scene scene = wallScene(material(0.15f, 1.0f));
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    passes::TemporalPipelines temporal(ctx);
    passes::CompositePipelines composite(ctx);
    scene::Camera camera = testCamera();
    camera.resolution = {1920, 1080};
    camera.reset({{0, 0, 0}, {0, 0, -1}, {0, 1, 0}}, 0);
    for (uint64_t frame = 0; frame < 16; ++frame) {
        if (frame > 0) camera.advance({{0.01f * float(frame), 0, 0}, {0.01f * float(frame), 0, -1}, {0, 1, 0}}, frame);
        rg::Graph graph(executor.queueCaps());
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera});
        struct Fill {
            rg::Texture radiance, hit;
        };
        const Fill& fill = graph.addPass<Fill>(
            "fill", rg::Queue::Graphics,
            [&](rg::Builder& b, Fill& d) {
                const auto make = [&](const char* name, VkFormat format) {
                    return b.write(b.createTexture(name, {.width = 1920, .height = 1080, .format = format}),
                                   rg::Access::TransferDst);
                };
                d.radiance = make("radiance", VK_FORMAT_R16G16B16A16_SFLOAT);
                d.hit = make("hit", VK_FORMAT_R32_SFLOAT);
            },
            [](const Fill& d, rg::PassContext& pc) {
                const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                const VkClearColorValue radiance{{0.5f, 0.6f, 0.7f, 1.0f}};
                const VkClearColorValue hit{{2.0f, 0.0f, 0.0f, 0.0f}};
                vkCmdClearColorImage(pc.cmd(), pc.image(d.radiance).handle(), pc.layout(d.radiance), &radiance, 1,
                                     &range);
                vkCmdClearColorImage(pc.cmd(), pc.image(d.hit).handle(), pc.layout(d.hit), &hit, 1, &range);
            });
        const passes::TemporalOutputs stable =
            passes::addTemporalPass(graph, temporal, {gbuf, fill.radiance, fill.hit, camera, frame});
        const passes::CompositeOutputs image =
            passes::addCompositePass(graph, composite, {gbuf, stable.resolved, camera});
        graph.markOutput(image.color);
        executor.run(graph.compile(executor.compileOptions()));
    }
    executor.waitIdle();
    for (const rg::PassTiming& t : executor.timings()) {
        MESSAGE(t.name << ": " << (t.milliseconds ? *t.milliseconds : -1.0) << " ms");
    }
}
