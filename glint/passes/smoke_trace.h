#pragma once
// Traces the smoke scene with either ray backend: ray query in a compute
// shader, or a ray tracing pipeline (raygen + one closest hit + one miss).
// The two must agree; the tests and glint-info's smoke check compare them.

#include "glint/gpu/accel.h"
#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/scene/smoke_scene.h"

#include <optional>
#include <vector>

namespace glint::passes {

enum class RayBackend { RayQuery, Pipeline };
const char* backendName(RayBackend backend);
// Backends the device can run, ray query first.
std::vector<RayBackend> availableBackends(const gpu::Context& ctx);

struct SmokeTraceResult {
    std::vector<shader::SmokeHit> hits;
    std::optional<double> gpuMilliseconds;  // the trace alone, from timestamps
};

// How two traces of the same image differ.
struct SmokeComparison {
    size_t pixels = 0;
    size_t hitMaskMismatches = 0;    // hit in one, miss in the other
    size_t identityMismatches = 0;   // both hit, different instance/geometry/primitive
    size_t bitMismatches = 0;        // any field differs bit for bit
    float maxBarycentricDiff = 0.0f; // over pixels where both hit the same triangle
    float maxRelativeTDiff = 0.0f;
    bool identical() const { return bitMismatches == 0; }
};
SmokeComparison compareSmokeHits(const std::vector<shader::SmokeHit>& a, const std::vector<shader::SmokeHit>& b);

// A picture of a trace: barycentric colours on hits, tinted per instance;
// a sky gradient on misses. RGBA8, row 0 at the top.
std::vector<uint8_t> smokeImage(const std::vector<shader::SmokeHit>& hits, uint32_t width, uint32_t height);

class SmokeTracer {
public:
    // Uploads the scene and builds its BLASes and TLAS.
    SmokeTracer(gpu::Context& ctx, const scene::SmokeScene& scene);

    SmokeTraceResult trace(RayBackend backend, uint32_t width, uint32_t height);

private:
    const gpu::Pipeline& pipelineFor(RayBackend backend);

    gpu::Context& ctx_;
    scene::SmokeScene scene_;
    std::vector<gpu::Buffer> geometryBuffers_;
    std::vector<gpu::AccelerationStructure> blases_;
    gpu::Buffer instances_;
    gpu::AccelerationStructure tlas_;
    std::optional<gpu::Pipeline> queryPipeline_;
    std::optional<gpu::Pipeline> rtPipeline_;
    std::optional<gpu::ShaderBindingTable> sbt_;
};

} // namespace glint::passes
