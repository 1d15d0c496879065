// glint-info: what the Vulkan device offers Glint (device, driver, queue
// families, ray tracing), and with --smoke a trace of the smoke scene with
// every ray backend the device has, compared against each other.

#include "common/app.h"
#include "glint/passes/smoke_trace.h"

#include <spdlog/spdlog.h>

#include <cstdio>

using namespace glint;

namespace {

void printCapabilities(const gpu::Context& ctx) {
    const auto& c = ctx.caps();
    std::printf("device:        %s (%s)\n", c.deviceName.c_str(), gpu::deviceTypeName(c.deviceType));
    std::printf("driver:        %s %s\n", c.driverName.c_str(), c.driverInfo.c_str());
    std::printf("vulkan:        %s\n", gpu::versionString(c.apiVersion).c_str());
    std::printf("queue families:\n");
    for (const auto& f : c.queueFamilies) {
        std::string role;
        if (f.index == c.graphicsFamily) role = "  <- graphics queue";
        if (c.computeFamily && f.index == *c.computeFamily) role = "  <- async compute queue";
        std::printf("  %u: %-28s x%-2u timestamp bits %u%s\n", f.index, gpu::queueFlagsString(f.flags).c_str(),
                    f.queueCount, f.timestampValidBits, role.c_str());
    }
    std::printf("async compute: %s\n",
                c.computeFamily ? ("yes (family " + std::to_string(*c.computeFamily) + ")").c_str()
                                : "no (async passes run on the graphics queue)");
    std::printf("acceleration structures: %s\n", c.accelerationStructure ? "yes" : "no");
    std::printf("ray query:               %s\n", c.rayQuery ? "yes" : "no");
    std::printf("ray tracing pipeline:    %s", c.rayTracingPipeline ? "yes" : "no");
    if (c.rayTracingPipeline) {
        std::printf(" (handle %u B, base alignment %u, max recursion %u)", c.rayTracing.shaderGroupHandleSize,
                    c.rayTracing.shaderGroupBaseAlignment, c.rayTracing.maxRayRecursionDepth);
    }
    std::printf("\ntimestamps:    %s (period %.3f ns)\n", c.timestamps ? "yes" : "no", c.timestampPeriodNs);
    std::printf("push descriptors: %u, subgroup size %u\n", c.maxPushDescriptors, c.subgroupSize);
}

// Traces the smoke scene with each backend; false when they disagree.
bool smokeCheck(gpu::Context& ctx, uint32_t size) {
    passes::SmokeTracer tracer(ctx, scene::makeSmokeScene());
    std::vector<std::pair<passes::RayBackend, passes::SmokeTraceResult>> results;
    for (auto backend : passes::availableBackends(ctx)) {
        auto r = tracer.trace(backend, size, size);
        size_t hits = 0;
        for (const auto& h : r.hits) hits += h.hit;
        std::printf("smoke %-11s %ux%u: %zu hits, GPU %s\n", passes::backendName(backend), size, size, hits,
                    r.gpuMilliseconds ? (std::to_string(*r.gpuMilliseconds) + " ms").c_str() : "n/a");
        results.emplace_back(backend, std::move(r));
    }
    if (results.size() < 2) {
        std::printf("smoke: one backend on this device, nothing to compare\n");
        return true;
    }
    const auto cmp = passes::compareSmokeHits(results[0].second.hits, results[1].second.hits);
    std::printf("smoke backends: hit-mask mismatches %zu, identity mismatches %zu, bit-identical pixels %zu/%zu, "
                "max |d bary| %.3g, max rel |d t| %.3g\n",
                cmp.hitMaskMismatches, cmp.identityMismatches, cmp.pixels - cmp.bitMismatches, cmp.pixels,
                cmp.maxBarycentricDiff, cmp.maxRelativeTDiff);
    return cmp.hitMaskMismatches == 0 && cmp.identityMismatches == 0;
}

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-info", [&] {
        app::Args args(argc, argv, "glint-info: the device, its driver, queue families and ray tracing support",
                       {{"size", "N: the smoke trace's image size (default 64)"}},
                       {{"smoke", "trace the smoke scene with every ray backend and compare them"}});
        // Reports on devices without ray tracing too (contextOptions does
        // not require it).
        gpu::Context ctx(args.contextOptions());
        printCapabilities(ctx);
        bool ok = true;
        if (args.has("smoke")) {
            if (passes::availableBackends(ctx).empty()) {
                throw std::runtime_error("--smoke: device '" + ctx.caps().deviceName +
                                         "' has neither ray query nor a ray tracing pipeline");
            }
            ok = smokeCheck(ctx, args.getUint("size", 128));
        }
        ctx.waitIdle();
        const bool clean = app::validationClean(ctx);
        return !ok ? 1 : clean ? 0 : 2;
    });
}
