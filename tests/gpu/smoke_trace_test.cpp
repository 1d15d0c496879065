// Both ray backends trace the smoke scene; each must match a double-precision
// CPU reference, and on the same device they must agree with each other.
#include "support/gpu_test.h"

#include "glint/passes/smoke_trace.h"

#include <cmath>

using namespace glint;

namespace {

constexpr uint32_t kSize = 96;

// Every pixel the reference calls unambiguous must match: same hit, same
// triangle, t and barycentrics within float precision.
void checkAgainstReference(const std::vector<shader::SmokeHit>& hits, const scene::SmokeReference& ref,
                           const char* backend) {
    INFO("backend " << backend);
    REQUIRE(hits.size() == ref.hits.size());
    size_t checked = 0, hitCount = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
        if (ref.ambiguous[i]) {
            continue;
        }
        ++checked;
        const auto& g = hits[i];
        const auto& r = ref.hits[i];
        INFO("pixel " << i % kSize << "," << i / kSize);
        REQUIRE(g.hit == r.hit);
        if (!r.hit) {
            continue;
        }
        ++hitCount;
        REQUIRE(g.instance == r.instance);
        REQUIRE(g.geometry == r.geometry);
        REQUIRE(g.primitive == r.primitive);
        REQUIRE(std::abs(g.t - r.t) <= 1e-4f * r.t);
        REQUIRE(std::abs(g.u - r.u) <= 1e-3f);
        REQUIRE(std::abs(g.v - r.v) <= 1e-3f);
    }
    // The scene fills most of the frame; the check must not be vacuous.
    CHECK(checked > hits.size() * 95 / 100);
    CHECK(hitCount > hits.size() / 2);
}

} // namespace

TEST_CASE("each ray backend matches the CPU reference on the smoke scene") {
    test::GpuTest gpu;
    const auto scene = scene::makeSmokeScene();
    const auto ref = scene::traceSmokeReference(scene, scene::smokeCamera(scene, kSize, kSize));
    passes::SmokeTracer tracer(gpu.ctx(), scene);
    const auto backends = passes::availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    for (auto backend : backends) {
        checkAgainstReference(tracer.trace(backend, kSize, kSize).hits, ref, passes::backendName(backend));
    }
}

TEST_CASE("ray query and the ray tracing pipeline agree on hit mask and barycentrics") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    if (!(ctx.caps().rayQuery && ctx.caps().rayTracingPipeline)) {
        MESSAGE("device '" << ctx.caps().deviceName << "' has one backend; nothing to compare");
        return;
    }
    passes::SmokeTracer tracer(ctx, scene::makeSmokeScene());
    const auto query = tracer.trace(passes::RayBackend::RayQuery, kSize, kSize);
    const auto pipeline = tracer.trace(passes::RayBackend::Pipeline, kSize, kSize);
    const auto cmp = passes::compareSmokeHits(query.hits, pipeline.hits);
    CHECK(cmp.hitMaskMismatches == 0);
    CHECK(cmp.identityMismatches == 0);
    CHECK(cmp.maxBarycentricDiff <= 1e-6f);
    // lavapipe runs both backends through the same traversal code: every
    // record must be bit for bit the same there.
    if (ctx.caps().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
        CHECK(cmp.identical());
    }
}

TEST_CASE("the ray tracing pipeline path runs alone when ray query is off (as on NVIDIA)") {
    gpu::ContextOptions o;
    o.disableRayQuery = true;
    test::GpuTest gpu(o);
    REQUIRE(gpu.ctx().caps().rayTracingPipeline);
    const auto backends = passes::availableBackends(gpu.ctx());
    REQUIRE(backends.size() == 1);
    CHECK(backends[0] == passes::RayBackend::Pipeline);
    const auto scene = scene::makeSmokeScene();
    passes::SmokeTracer tracer(gpu.ctx(), scene);
    checkAgainstReference(tracer.trace(passes::RayBackend::Pipeline, kSize, kSize).hits,
                          scene::traceSmokeReference(scene, scene::smokeCamera(scene, kSize, kSize)), "rt-pipeline");
}
