// The temporal rig that glint_temporal_gpu_tests' temporal cases share
// (temporal_test.cpp, spatial_filter_test.cpp): a run of frames through the
// real G-buffer and passes/temporal.h, each with the reflection radiance
// and hit distance the test uploads, read back as the resolved image (and
// the motion and history length); noisy frames around a known mean and
// their error against it; a camera step.
#pragma once

#include "support/gpu_test.h"
#include "temporal_harness.h"

#include "glint/graph/executor.h"
#include "glint/graph/verify.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/temporal.h"

#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

namespace glint::temporal_test {

inline bool finite(glm::vec4 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

struct FrameInput {
    std::vector<glm::vec4> radiance = std::vector<glm::vec4>(kPixels, glm::vec4(0.0f));  // uploaded as RGBA32F
    std::vector<float> hitDistance = std::vector<float>(kPixels, 2.0f);
    scene::Camera camera = testCamera();
    bool reset = false;
    // TemporalInputs::sharedRayRoughness (above 1: no pixel shares rays).
    float sharedRayRoughness = 2.0f;
    // TemporalInputs::environmentRoughness (above 1: no pixel takes the
    // environment alone).
    float environmentRoughness = 2.0f;
    // TemporalInputs::debugOutputs: off, the motion and length are not read back.
    bool debugOutputs = true;
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
inline std::vector<FrameOutput> runTemporal(scene::Scene& scene, const std::vector<FrameInput>& frames,
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
        inputs.environmentRoughness = in.environmentRoughness;
        inputs.debugOutputs = in.debugOutputs;
        const passes::TemporalOutputs out = passes::addTemporalPass(graph, pipelines, inputs, settings);
        REQUIRE(out.width == kSize);
        REQUIRE(out.reflectionMotion.valid() == in.debugOutputs);
        REQUIRE(out.historyLength.valid() == in.debugOutputs);
        readbacks.push_back(
            {&readTexture(graph, resources, staging, out.resolved, passes::kTemporalResolvedFormat, "resolved"),
             in.debugOutputs ? &readTexture(graph, resources, staging, out.reflectionMotion,
                                            passes::kTemporalMotionFormat, "motion")
                             : nullptr,
             in.debugOutputs ? &readTexture(graph, resources, staging, out.historyLength,
                                            passes::kTemporalHistoryLengthFormat, "length")
                             : nullptr});
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
        if (r[1]) {
            for (const glm::vec4& m : halves(*r[1], 2)) o.motion.emplace_back(m.x, m.y);
            for (const glm::vec4& l : halves(*r[2], 1)) o.length.push_back(l.x);
        }
        outputs.push_back(std::move(o));
    }
    return outputs;
}

// A smooth mean per pixel (so neighbourhoods are nearly flat) and uniform
// noise of +-amplitude per channel, new every frame, from a fixed seed.
inline glm::vec4 meanRadiance(uint32_t x, uint32_t y) {
    return {0.4f + 0.4f * float(x) / kSize, 0.5f, 0.9f - 0.4f * float(y) / kSize, 1.0f};
}

inline std::vector<FrameInput> noisyFrames(uint32_t count, float amplitude, uint32_t seed = 7) {
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
inline float rmsError(const std::vector<glm::vec4>& image) {
    double sum = 0.0;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const glm::vec3 d = glm::vec3(image[at(x, y)]) - glm::vec3(meanRadiance(x, y));
            sum += glm::dot(d, d) / 3.0;
        }
    }
    return float(std::sqrt(sum / kPixels));
}

// Two frames whose camera steps `step` to the right, still facing the wall.
inline std::vector<FrameInput> cameraStepFrames(float step) {
    std::vector<FrameInput> frames(2);
    scene::Camera camera = testCamera();
    frames[0].camera = camera;
    camera.advance({{step, 0, 0}, {step, 0, -1}, {0, 1, 0}}, 1);
    frames[1].camera = camera;
    return frames;
}

} // namespace glint::temporal_test
