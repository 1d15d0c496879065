#pragma once
// What the G-buffer's GPU tests share (gbuffer_test.cpp,
// gbuffer_occlusion_test.cpp, gbuffer_facet_test.cpp): every target of a
// frame read back inside the graph and decoded on the host, a renderer run
// over a camera path, and the check that two runs drew the same.
#include "support/gpu_test.h"

#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/gbuffer.h"

#include "glint/occlusion_shared.h"

#include <glm/gtc/packing.hpp>

#include <array>
#include <cstring>
#include <string>
#include <vector>

namespace glint::gbuffer_test {

// Every G-buffer target of one frame, decoded on the host.
struct GBufferImage {
    uint32_t width = 0, height = 0;
    std::vector<float> depth;
    std::vector<glm::vec4> normal;
    std::vector<glm::u8vec4> albedo;  // sRGB-encoded bytes
    std::vector<glm::u8vec4> roughnessMetal;
    std::vector<glm::vec2> motion;
    std::vector<glm::vec4> lit;

    size_t at(uint32_t x, uint32_t y) const { return size_t(y) * width + x; }
};

// Copies the G-buffer into host-visible buffers inside the graph (a transfer
// pass after the G-buffer), so the test reads what the graph produced under
// its own barriers.
class Readback {
public:
    Readback(gpu::Context& ctx, uint32_t width, uint32_t height) : width_(width), height_(height) {
        const uint32_t bytes[6] = {4, 8, 4, 4, 4, 8};
        for (size_t i = 0; i < 6; ++i) {
            buffers_.emplace_back(ctx, VkDeviceSize(width) * height * bytes[i],
                                  "gbuffer_test.readback" + std::to_string(i));
        }
    }

    void add(rg::Graph& graph, const passes::GBufferOutputs& gbuf, rg::FrameResources& frame) const {
        const std::array<rg::Texture, 6> sources = {gbuf.depth, gbuf.normal, gbuf.albedo,
                                                    gbuf.roughnessMetal, gbuf.motion, gbuf.lit};
        for (size_t i = 0; i < sources.size(); ++i) buffers_[i].copy(graph, frame, sources[i]);
    }

    GBufferImage decode() const {
        GBufferImage out;
        out.width = width_;
        out.height = height_;
        const size_t n = size_t(width_) * height_;
        out.depth.resize(n);
        std::memcpy(out.depth.data(), buffers_[0].bytes().data(), n * sizeof(float));
        const auto halves = [](const rg::HostReadback& b, size_t i, int components) {
            const uint16_t* h = b.as<uint16_t>().data() + i * components;
            glm::vec4 v(0.0f);
            for (int c = 0; c < components; ++c) v[c] = glm::unpackHalf1x16(h[c]);
            return v;
        };
        out.normal.resize(n);
        out.albedo.resize(n);
        out.roughnessMetal.resize(n);
        out.motion.resize(n);
        out.lit.resize(n);
        std::memcpy(out.albedo.data(), buffers_[2].bytes().data(), n * 4);
        std::memcpy(out.roughnessMetal.data(), buffers_[3].bytes().data(), n * 4);
        for (size_t i = 0; i < n; ++i) {
            out.normal[i] = halves(buffers_[1], i, 4);
            out.motion[i] = glm::vec2(halves(buffers_[4], i, 2));
            out.lit[i] = halves(buffers_[5], i, 4);
        }
        return out;
    }

private:
    uint32_t width_, height_;
    std::vector<rg::HostReadback> buffers_;
};


// Every target bit for bit: what a cull that changes only the raster work
// must leave.
inline void checkSameTargets(const GBufferImage& a, const GBufferImage& b) {
    CHECK(a.depth == b.depth);
    CHECK(a.normal == b.normal);
    CHECK(a.albedo == b.albedo);
    CHECK(a.roughnessMetal == b.roughnessMetal);
    CHECK(a.motion == b.motion);
    CHECK(a.lit == b.lit);
}

// Runs the G-buffer over `frames` (one frame each, waiting for each) and
// returns the last frame's targets; `stats` gets the renderer's counts and
// `occlusion` the last frame's occlusion cull counts (shader::kOcclusionStat*;
// empty where the cull did not run).
inline GBufferImage render(test::GpuTest& gpu, const scene::Scene& scene, const std::vector<scene::Camera>& frames,
                           passes::GBufferStats* stats = nullptr, const passes::GBufferSettings& settings = {},
                           std::vector<uint32_t>* occlusion = nullptr) {
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    passes::GBufferRenderer renderer(ctx, scene);
    Readback readback(ctx, frames.front().resolution.x, frames.front().resolution.y);
    const rg::HostReadback occlusionCounts(ctx, shader::kOcclusionStatWords * 4u, "gbuffer_test.occlusion");
    bool culled = false;  // the last frame ran the occlusion cull
    for (const scene::Camera& camera : frames) {
        rg::Graph graph(executor.queueCaps());
        rg::FrameResources resources;
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer, {camera}, settings);
        readback.add(graph, gbuf, resources);
        culled = gbuf.occlusionStats.valid();
        if (culled) occlusionCounts.copy(graph, resources, gbuf.occlusionStats);
        const rg::Plan plan = graph.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor.run(plan, resources);
        executor.waitIdle();
    }
    if (stats) *stats = renderer.stats();
    if (occlusion) {
        occlusion->clear();
        const auto words = occlusionCounts.as<uint32_t>();
        if (culled) occlusion->assign(words.begin(), words.begin() + shader::kOcclusionStatWords);
    }
    return readback.decode();
}

} // namespace glint::gbuffer_test
