#include "glint/passes/smoke_trace.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/gpu/timestamps.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace glint::passes {

const char* backendName(RayBackend backend) {
    return backend == RayBackend::RayQuery ? "ray-query" : "rt-pipeline";
}

std::vector<RayBackend> availableBackends(const gpu::Context& ctx) {
    std::vector<RayBackend> out;
    if (ctx.caps().rayQuery) out.push_back(RayBackend::RayQuery);
    if (ctx.caps().rayTracingPipeline) out.push_back(RayBackend::Pipeline);
    return out;
}

SmokeComparison compareSmokeHits(const std::vector<shader::SmokeHit>& a, const std::vector<shader::SmokeHit>& b) {
    if (a.size() != b.size()) {
        throw gpu::GpuError("smoke comparison: " + std::to_string(a.size()) + " vs " + std::to_string(b.size()) + " pixels");
    }
    SmokeComparison c;
    c.pixels = a.size();
    for (size_t i = 0; i < a.size(); ++i) {
        const auto& x = a[i];
        const auto& y = b[i];
        if (std::memcmp(&x, &y, sizeof(x)) != 0) {
            ++c.bitMismatches;
        }
        if (x.hit != y.hit) {
            ++c.hitMaskMismatches;
        } else if (x.hit) {
            if (x.instance != y.instance || x.geometry != y.geometry || x.primitive != y.primitive) {
                ++c.identityMismatches;
                continue;
            }
            c.maxBarycentricDiff = std::max({c.maxBarycentricDiff, std::abs(x.u - y.u), std::abs(x.v - y.v)});
            c.maxRelativeTDiff = std::max(c.maxRelativeTDiff, std::abs(x.t - y.t) / std::max(std::abs(x.t), 1e-6f));
        }
    }
    return c;
}

std::vector<uint8_t> smokeImage(const std::vector<shader::SmokeHit>& hits, uint32_t width, uint32_t height) {
    std::vector<uint8_t> rgba(size_t(width) * height * 4);
    auto to8 = [](float v) { return static_cast<uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const auto& h = hits[size_t(y) * width + x];
            glm::vec3 c;
            if (h.hit) {
                const glm::vec3 bary(1.0f - h.u - h.v, h.u, h.v);
                const glm::vec3 tint = h.instance == 0 ? glm::vec3(0.9f) : h.instance == 10 ? glm::vec3(1.0f, 0.6f, 0.4f)
                                                                                              : glm::vec3(0.4f, 0.7f, 1.0f);
                // Darken with distance so depth reads in the picture.
                c = (0.35f + 0.65f * bary) * tint * (1.0f / (1.0f + 0.04f * h.t));
            } else {
                const float k = float(y) / float(height);
                c = glm::mix(glm::vec3(0.35f, 0.55f, 0.9f), glm::vec3(0.85f, 0.9f, 1.0f), k);
            }
            uint8_t* p = &rgba[(size_t(y) * width + x) * 4];
            p[0] = to8(c.r);
            p[1] = to8(c.g);
            p[2] = to8(c.b);
            p[3] = 255;
        }
    }
    return rgba;
}

namespace {
constexpr VkBufferUsageFlags kBuildInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
} // namespace

SmokeTracer::SmokeTracer(gpu::Context& ctx, const scene::SmokeScene& scene) : ctx_(ctx), scene_(scene) {
    // One BLAS per object; each geometry's positions (and indices) in buffers of their own.
    for (size_t b = 0; b < scene_.blases.size(); ++b) {
        std::vector<gpu::TriangleGeometry> geometries;
        for (size_t g = 0; g < scene_.blases[b].geometries.size(); ++g) {
            const auto& geo = scene_.blases[b].geometries[g];
            const std::string name = "smoke.blas" + std::to_string(b) + ".geometry" + std::to_string(g);
            gpu::TriangleGeometry t;
            geometryBuffers_.push_back(gpu::createBufferWithData(
                ctx, {geo.positions.size() * sizeof(glm::vec3), kBuildInput, gpu::MemoryUsage::DeviceLocal, name + ".positions"},
                geo.positions.data()));
            t.vertices = geometryBuffers_.back().address();
            t.vertexCount = static_cast<uint32_t>(geo.positions.size());
            if (!geo.indices.empty()) {
                geometryBuffers_.push_back(gpu::createBufferWithData(
                    ctx, {geo.indices.size() * sizeof(uint32_t), kBuildInput, gpu::MemoryUsage::DeviceLocal, name + ".indices"},
                    geo.indices.data()));
                t.indices = geometryBuffers_.back().address();
            }
            t.triangleCount = geo.triangleCount();
            geometries.push_back(t);
        }
        auto build = gpu::AccelBuild::bottomLevel(ctx, geometries, VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR);
        blases_.push_back(gpu::buildNow(ctx, build, "smoke.blas" + std::to_string(b)));
    }

    std::vector<VkAccelerationStructureInstanceKHR> instances;
    for (const auto& inst : scene_.instances) {
        const auto transform = scene::rowMajor3x4(inst.transform);
        instances.push_back(gpu::makeInstance(blases_.at(inst.blas), transform.data(), inst.customIndex));
    }
    instances_ = gpu::createBufferWithData(
        ctx, {instances.size() * sizeof(VkAccelerationStructureInstanceKHR), kBuildInput, gpu::MemoryUsage::DeviceLocal,
              "smoke.instances"},
        instances.data());
    auto build = gpu::AccelBuild::topLevel(ctx, instances_.address(), static_cast<uint32_t>(instances.size()),
                                           VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR);
    tlas_ = gpu::buildNow(ctx, build, "smoke.tlas");
    spdlog::debug("smoke: {} BLAS, {} instances", blases_.size(), instances.size());
}

const gpu::Pipeline& SmokeTracer::pipelineFor(RayBackend backend) {
    if (backend == RayBackend::RayQuery) {
        if (!ctx_.caps().rayQuery) {
            throw gpu::GpuError("smoke trace: device '" + ctx_.caps().deviceName + "' has no ray query");
        }
        if (!queryPipeline_) {
            queryPipeline_ = gpu::createComputePipeline(
                ctx_, {"smoke/trace_query.comp", {}, sizeof(shader::SmokeCamera), "smoke.trace_query"});
        }
        return *queryPipeline_;
    }
    if (!rtPipeline_) {
        rtPipeline_ = gpu::createRayTracingPipeline(
            ctx_, {"smoke/trace.rgen", {"smoke/trace.rmiss"}, {{"smoke/trace.rchit", ""}}, {},
                   sizeof(shader::SmokeCamera), 1, "smoke.trace_pipeline"});
        sbt_.emplace(ctx_, *rtPipeline_, 1, 1);
    }
    return *rtPipeline_;
}

SmokeTraceResult SmokeTracer::trace(RayBackend backend, uint32_t width, uint32_t height) {
    if (width == 0 || height == 0) {
        throw gpu::GpuError("smoke trace: image size " + std::to_string(width) + "x" + std::to_string(height));
    }
    const gpu::Pipeline& pipeline = pipelineFor(backend);
    const shader::SmokeCamera camera = scene::smokeCamera(scene_, width, height);
    // Device-local: writing host memory from the shader would time the bus, not the trace.
    gpu::Buffer hits(ctx_, {VkDeviceSize(width) * height * sizeof(shader::SmokeHit),
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                            gpu::MemoryUsage::DeviceLocal, std::string("smoke.hits.") + backendName(backend)});
    gpu::TimestampQueries timer(ctx_, 1);
    const VkPipelineStageFlags2 stage = backend == RayBackend::RayQuery ? VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT
                                                                        : VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR;

    gpu::submitAndWait(ctx_, ctx_.graphicsQueue(), std::string("smoke trace ") + backendName(backend),
                       [&](VkCommandBuffer cmd) {
        gpu::ScopedLabel label(ctx_, cmd, std::string("smoke.trace.") + backendName(backend));
        pipeline.bind(cmd);
        gpu::PushDescriptors(pipeline)
            .accelerationStructure("tlas", tlas_.handle())
            .storageBuffer("Hits", hits)
            .push(ctx_, cmd);
        pipeline.pushConstants(cmd, camera);
        timer.begin(cmd, 0);
        if (backend == RayBackend::RayQuery) {
            vkCmdDispatch(cmd, (width + shader::kSmokeGroupSize - 1) / shader::kSmokeGroupSize,
                          (height + shader::kSmokeGroupSize - 1) / shader::kSmokeGroupSize, 1);
        } else {
            sbt_->traceRays(ctx_, cmd, width, height);
        }
        timer.end(cmd, 0);
        gpu::bufferBarrier(cmd, hits, stage, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                           VK_ACCESS_2_TRANSFER_READ_BIT);
    });
    SmokeTraceResult result;
    result.hits = gpu::readbackBufferAs<shader::SmokeHit>(ctx_, hits);
    result.gpuMilliseconds = timer.readMilliseconds()[0];
    return result;
}

} // namespace glint::passes
