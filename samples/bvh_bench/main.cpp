// glint-bvh-bench: what the BVH update costs per scene, measured with GPU
// timestamps around its one graph pass (executor.timings()):
//   first   the first frame: every BLAS in range built, plus the TLAS;
//   steady  median over the animated frames that follow: the round-robin
//           rebuilds (skinned, first-person) plus the TLAS;
//   tlas    median over frames with no BLAS work at all (the TLAS, its
//           instance copy and the offset table), where a scene has them;
// the memory the manager holds after the run, and the first frame's scratch
// request. Scenes:
// the built-in plaza, then every glTF under ../shared/scenes (or --scenes
// a,b,c: built-in names or paths). The last line is machine-readable:
//   bvh_first_ms_plaza=<ms> bvh_steady_ms_plaza=<ms> bvh_mib_plaza=<MiB>
//
// --overlap: what running the builds on the async compute queue wins. Each
// frame declares
//   (a) the BVH update pass (between two timestamp markers on its queue),
//   (b) a stand-in graphics workload that does not need the TLAS: a chain of
//       --busy-passes compute passes (shaders/test/busy_work.comp) over
//       transient buffers of --busy-mib MiB on the graphics queue, its
//       arithmetic calibrated on the device so that the chain costs about
//       what the BVH update costs (--busy-iterations overrides),
//   (c) a TLAS consumer on the graphics queue after both: --rays² camera
//       rays through the TLAS, reading the primitive pool (the bvh_probe
//       shaders; ray query, or the ray tracing pipeline where there is none),
// and is run with the BVH pass on AsyncCompute, then on Graphics (one
// BvhManager each), same scene (plaza unless --scenes), animated, with a
// still camera. Per mode: --warmup frames, then --frames frames one at a
// time; the frame's GPU time is from its first timestamp to its last, over
// both queues (one device clock). Then the same frames again with the
// executor's frames in flight, timed on the host. The last line:
//   overlap_frame_ms_async=<ms> overlap_frame_ms_graphics=<ms> overlap_saving_pct=<%>

#include "common/app.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/passes/bvh_update.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/bvh_planner.h"

#include "glint/bvh_shared.h"

#include <glm/glm.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

using namespace glint;

namespace {

struct SceneResult {
    std::string name;
    uint64_t triangles = 0;  // in the pool after the first frame
    uint32_t blases = 0;
    uint32_t tlasInstances = 0;
    double firstMs = 0;
    std::optional<double> steadyMs;
    double steadyRebuilds = 0;  // mean BLAS rebuilds of the steady frames
    std::optional<double> tlasOnlyMs;
    passes::BvhGpuStats memory;
};

std::optional<double> median(std::vector<double> v) {
    if (v.empty()) return std::nullopt;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

double passMilliseconds(const rg::Executor& executor) {
    for (const rg::PassTiming& t : executor.timings()) {
        if (t.name == "bvh_update") {
            if (!t.milliseconds) throw std::runtime_error("the device's queue has no timestamps");
            return *t.milliseconds;
        }
    }
    throw std::runtime_error("no timing for the bvh_update pass");
}

SceneResult measure(gpu::Context& ctx, const std::string& name, uint32_t frames,
                    const scene::GltfLoadOptions& loadOptions) {
    scene::Scene s = scene::loadScene(name, loadOptions);
    scene::BvhPlanner planner;
    rg::Executor executor(ctx);
    passes::BvhManager bvh(ctx, s);
    SceneResult r;
    r.name = std::filesystem::path(name).filename().string();
    std::vector<double> steady, tlasOnly;
    uint64_t rebuilds = 0;
    for (uint32_t f = 0; f < frames; ++f) {
        scene::advanceScene(s, f / 30.0);  // 30 Hz animation
        const scene::CameraPose pose = s.cameraPath.atFrame(0, 1);  // a still camera: BLAS work only from animation
        const scene::BvhPlan plan = planner.plan(s, pose.position, f);
        rg::Graph graph(executor.queueCaps());
        const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, plan);
        rg::FrameResources resources;
        bvh.bind(resources, out);
        executor.run(graph.compile(executor.compileOptions()), resources);
        // One frame at a time: the timestamps then belong to this frame.
        executor.waitIdle();
        const double ms = passMilliseconds(executor);
        if (f == 0) {
            r.firstMs = ms;
            r.triangles = plan.poolTriangles;
            r.blases = plan.stats.residentBlases;
            r.tlasInstances = plan.stats.tlasInstances;
            r.memory.scratchBytes = bvh.stats().scratchBytes;  // the largest request: every BLAS at once
        } else if (plan.builds.empty()) {
            tlasOnly.push_back(ms);
        } else {
            steady.push_back(ms);
            rebuilds += plan.builds.size();
        }
    }
    // Held after the run: static BLASes' build positions are released by then.
    const uint64_t scratch = r.memory.scratchBytes;
    r.memory = bvh.stats();
    r.memory.scratchBytes = scratch;
    r.steadyMs = median(steady);
    r.steadyRebuilds = steady.empty() ? 0.0 : double(rebuilds) / double(steady.size());
    r.tlasOnlyMs = median(tlasOnly);
    return r;
}

std::vector<std::string> defaultScenes() {
    std::vector<std::string> scenes = {"plaza"};
    std::vector<std::string> files;
    std::error_code ec;
    for (const auto& dir : std::filesystem::directory_iterator(GLINT_SCENES_DIR, ec)) {
        for (const auto& entry : std::filesystem::directory_iterator(dir.path(), ec)) {
            const std::string ext = entry.path().extension().string();
            if (ext == ".gltf" || ext == ".glb") files.push_back(entry.path().string());
        }
    }
    std::sort(files.begin(), files.end());
    scenes.insert(scenes.end(), files.begin(), files.end());
    return scenes;
}

std::string ms(const std::optional<double>& v) {
    char buf[32];
    if (!v) return "-";
    std::snprintf(buf, sizeof buf, "%.3f", *v);
    return buf;
}

double mib(uint64_t bytes) { return double(bytes) / (1024.0 * 1024.0); }


// ---------------------------------------------------------------------------
// --overlap
// ---------------------------------------------------------------------------

struct OverlapSettings {
    std::string scene = "plaza";
    uint32_t warmup = 30;
    uint32_t frames = 200;
    uint32_t raysSide = 256;       // the consumer traces raysSide² rays
    uint64_t busyBytes = 0;        // per busy buffer
    uint32_t busyPasses = 4;
    uint32_t busyIterations = 0;   // 0: calibrate
    bool pipelineOnly = false;     // the ray tracing pipeline even where ray query exists
};

struct OverlapResult {
    double frameMs = 0;        // median, first timestamp to last over both queues, one frame at a time
    double bvhMs = 0;          // median, the BVH markers
    double bvhPassMs = 0;      // median, the executor's own timing of the bvh_update pass
    double bvhStartMs = 0;     // median, from the frame's first timestamp to the BVH's begin marker
    double busyMs = 0;         // median, the busy chain
    double consumerMs = 0;     // median, the trace
    double hostMsPerFrame = 0; // frames in flight, wall time / frames
    double rebuilds = 0;       // mean BLAS builds per measured frame
    uint32_t buildFrames = 0;  // measured frames with BLAS builds
};

struct BusyPush {
    uint32_t count, iterations, useSrc;
};

// Timestamp slots of one frame.
enum Stamp : uint32_t { kBvhBegin, kBvhEnd, kBusyBegin, kBusyEnd, kTraceBegin, kTraceEnd, kStampCount };

class OverlapRig {
public:
    OverlapRig(gpu::Context& ctx, const OverlapSettings& settings) : ctx_(ctx), settings_(settings) {
        const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
        busy_ = gpu::createComputePipeline(
            ctx, {"test/busy_work.comp",
                  {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, cs}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, cs}},
                  sizeof(BusyPush), "bench.busy_work"});
        const VkShaderStageFlags all =
            VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
        const std::vector<gpu::Binding> bindings = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, all},
                                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all},
                                                    {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all},
                                                    {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all},
                                                    {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, all}};
        rayQuery_ = ctx.caps().rayQuery && !settings.pipelineOnly;
        if (rayQuery_) {
            trace_ = gpu::createComputePipeline(ctx, {"test/bvh_probe_query.comp", bindings, 4, "bench.trace_query"});
        } else if (ctx.caps().rayTracingPipeline) {
            trace_ = gpu::createRayTracingPipeline(
                ctx, {"test/bvh_probe.rgen", {"test/bvh_probe.rmiss"}, {{"test/bvh_probe.rchit", ""}}, bindings, 4, 1,
                      "bench.trace_pipeline"});
            sbt_.emplace(ctx, trace_, 1, 1);
        } else {
            throw std::runtime_error("--overlap needs ray query or the ray tracing pipeline");
        }
        if (!ctx.caps().timestamps) throw std::runtime_error("--overlap needs timestamps");
        VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        info.queryType = VK_QUERY_TYPE_TIMESTAMP;
        info.queryCount = kStampCount;
        gpu::check(vkCreateQueryPool(ctx.device(), &info, nullptr, &queries_), "vkCreateQueryPool (overlap)");
    }
    ~OverlapRig() { vkDestroyQueryPool(ctx_.device(), queries_, nullptr); }
    OverlapRig(const OverlapRig&) = delete;
    OverlapRig& operator=(const OverlapRig&) = delete;

    const char* backend() const { return rayQuery_ ? "ray query" : "ray tracing pipeline"; }

    // Runs one mode. `iterations` sizes the busy chain; with `calibrate` only
    // the warm-up runs and the result holds the executor's pass times.
    OverlapResult run(rg::Queue bvhQueue, uint32_t iterations, bool calibrate = false) {
        scene::Scene s = scene::loadScene(settings_.scene);
        scene::BvhPlanner planner;
        rg::Executor executor(ctx_);
        passes::BvhUpdateOptions options;
        options.queue = bvhQueue;
        passes::BvhManager bvh(ctx_, s, 2, options);
        const scene::CameraPose pose = s.cameraPath.atFrame(0, 1);  // a still camera: BLAS work only from animation
        writeRays(pose);

        OverlapResult r;
        std::vector<double> frame, bvhMs, busyMs, traceMs, bvhPassMs, bvhStartMs;
        uint64_t rebuilds = 0;
        const uint32_t measured = calibrate ? 0 : settings_.frames;
        const uint32_t total = settings_.warmup + 2 * measured;
        auto start = std::chrono::steady_clock::now();
        for (uint32_t f = 0; f < total; ++f) {
            // Warm-up and timestamped frames one at a time; then the same
            // number with frames in flight, timed on the host.
            const bool pipelined = f >= settings_.warmup + measured;
            const bool stamped = !pipelined && f >= settings_.warmup;
            if (f == settings_.warmup + measured) {
                executor.waitIdle();
                start = std::chrono::steady_clock::now();
            }
            scene::advanceScene(s, f / 30.0);  // 30 Hz animation
            const scene::BvhPlan plan = planner.plan(s, pose.position, f);
            rg::Graph graph(executor.queueCaps());
            rg::FrameResources resources;
            declare(graph, resources, bvh, plan, bvhQueue, iterations, stamped);
            if (stamped) vkResetQueryPool(ctx_.device(), queries_, 0, kStampCount);
            executor.run(graph.compile(executor.compileOptions()), resources);
            if (pipelined) continue;
            executor.waitIdle();
            if (calibrate && f > 0) {  // the first frame builds everything
                double busy = 0;
                for (const rg::PassTiming& t : executor.timings()) {
                    if (t.name == "bvh_update" && t.milliseconds) bvhMs.push_back(*t.milliseconds);
                    if (t.name.rfind("busy", 0) == 0 && t.milliseconds) busy += *t.milliseconds;
                }
                busyMs.push_back(busy);
            }
            if (!stamped) continue;
            uint64_t ts[kStampCount];
            gpu::check(vkGetQueryPoolResults(ctx_.device(), queries_, 0, kStampCount, sizeof ts, ts, sizeof(uint64_t),
                                             VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                       "vkGetQueryPoolResults (overlap)");
            const double period = ctx_.caps().timestampPeriodNs * 1e-6;
            const auto span = [&](uint64_t a, uint64_t b) { return double(int64_t(b - a)) * period; };
            const uint64_t first = std::min(ts[kBvhBegin], ts[kBusyBegin]);
            const uint64_t last = std::max({ts[kBvhEnd], ts[kBusyEnd], ts[kTraceEnd]});
            frame.push_back(span(first, last));
            bvhMs.push_back(span(ts[kBvhBegin], ts[kBvhEnd]));
            bvhStartMs.push_back(span(first, ts[kBvhBegin]));
            bvhPassMs.push_back(passMilliseconds(executor));
            busyMs.push_back(span(ts[kBusyBegin], ts[kBusyEnd]));
            traceMs.push_back(span(ts[kTraceBegin], ts[kTraceEnd]));
            rebuilds += plan.builds.size();
            r.buildFrames += plan.builds.empty() ? 0 : 1;
        }
        executor.waitIdle();
        if (measured > 0) {
            const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            r.hostMsPerFrame = wall / measured;
            r.rebuilds = double(rebuilds) / measured;
        }
        r.frameMs = median(frame).value_or(0.0);
        r.bvhMs = median(bvhMs).value_or(0.0);
        r.bvhPassMs = median(bvhPassMs).value_or(0.0);
        r.bvhStartMs = median(bvhStartMs).value_or(0.0);
        r.busyMs = median(busyMs).value_or(0.0);
        r.consumerMs = median(traceMs).value_or(0.0);
        return r;
    }

private:
    void writeRays(const scene::CameraPose& pose) {
        const uint32_t side = settings_.raysSide;
        const VkDeviceSize bytes = VkDeviceSize(side) * side * sizeof(shader::BvhProbeRay);
        if (!rays_ || rays_.size() < bytes) {
            rays_ = gpu::Buffer(ctx_, {bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Upload,
                                       "bench.rays", false});
        }
        const glm::vec3 forward = glm::normalize(pose.target - pose.position);
        const glm::vec3 right = glm::normalize(glm::cross(forward, pose.up));
        const glm::vec3 up = glm::cross(right, forward);
        const float tanHalf = std::tan(0.5f * 1.0471976f);
        std::vector<shader::BvhProbeRay> rays(size_t(side) * side);
        for (uint32_t y = 0; y < side; ++y) {
            for (uint32_t x = 0; x < side; ++x) {
                const float u = (2.0f * (float(x) + 0.5f) / float(side) - 1.0f) * tanHalf;
                const float v = (1.0f - 2.0f * (float(y) + 0.5f) / float(side)) * tanHalf;
                rays[size_t(y) * side + x] = {pose.position, 1.0e-3f, glm::normalize(forward + u * right + v * up),
                                              1.0e4f};
            }
        }
        std::memcpy(rays_.mapped(), rays.data(), bytes);
    }

    void stampPass(rg::Graph& graph, const char* name, rg::Queue queue, Stamp stamp, VkPipelineStageFlags2 stage,
                   bool stamped) {
        graph.addPass(
            name, queue, [](rg::Builder& b) { b.markSideEffects(); },
            [this, stamp, stage, stamped](rg::PassContext& pc) {
                if (stamped) vkCmdWriteTimestamp2(pc.cmd(), stage, queries_, stamp);
            });
    }

    void declare(rg::Graph& graph, rg::FrameResources& resources, passes::BvhManager& bvh, const scene::BvhPlan& plan,
                 rg::Queue bvhQueue, uint32_t iterations, bool stamped) {
        // (a) the builds, between markers on their queue (passes of one queue
        // keep their declaration order).
        stampPass(graph, "bvh_begin", bvhQueue, kBvhBegin, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, stamped);
        const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, plan);
        bvh.bind(resources, out);
        stampPass(graph, "bvh_end", bvhQueue, kBvhEnd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, stamped);

        // (b) graphics work that does not need the TLAS.
        const uint32_t count = uint32_t(settings_.busyBytes / 16);
        const rg::BufferDesc desc{uint64_t(count) * 16};
        rg::Buffer previous;
        for (uint32_t i = 0; i < settings_.busyPasses; ++i) {
            struct Data {
                rg::Buffer src, dst;
            };
            const bool firstPass = i == 0, lastPass = i + 1 == settings_.busyPasses;
            const Data& d = graph.addPass<Data>(
                "busy " + std::to_string(i), rg::Queue::Graphics,
                [&](rg::Builder& b, Data& data) {
                    if (previous.valid()) data.src = b.read(previous, rg::Access::StorageRead);
                    data.dst = b.write(b.createBuffer("busy." + std::to_string(i), desc), rg::Access::StorageWrite);
                },
                [this, count, iterations, stamped, firstPass, lastPass](const Data& data, rg::PassContext& pc) {
                    if (stamped && firstPass)
                        vkCmdWriteTimestamp2(pc.cmd(), VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, queries_, kBusyBegin);
                    gpu::PushDescriptors(busy_)
                        .storageBuffer(0, pc.buffer(data.src.valid() ? data.src : data.dst))
                        .storageBuffer(1, pc.buffer(data.dst))
                        .push(pc.gpu(), pc.cmd());
                    busy_.pushConstants(pc.cmd(), BusyPush{count, iterations, data.src.valid() ? 1u : 0u});
                    pc.dispatch(busy_, (count + 255) / 256);
                    if (stamped && lastPass)
                        vkCmdWriteTimestamp2(pc.cmd(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries_, kBusyEnd);
                });
            previous = d.dst;
        }

        // (c) the TLAS consumer, after both.
        const uint32_t rayCount = settings_.raysSide * settings_.raysSide;
        constexpr rg::BoundaryState kHostWritten =
            rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
        const rg::Buffer rays = graph.importBuffer("bench.rays", {{rays_.size()}, kHostWritten, kHostWritten});
        resources.bind(rays, rays_);
        struct Trace {
            rg::AccelStruct tlas;
            rg::Buffer pool, offsets, rays, shaded, hits;
        };
        graph.addPass<Trace>(
            "trace", rg::Queue::Graphics,
            [&](rg::Builder& b, Trace& d) {
                b.setPipeline(rayQuery_ ? rg::Pipeline::Compute : rg::Pipeline::RayTracing);
                d.tlas = b.read(out.tlas, rg::Access::AccelRead);
                d.pool = b.read(out.primitivePool, rg::Access::StorageRead);
                d.offsets = b.read(out.primitiveOffsets, rg::Access::StorageRead);
                d.rays = b.read(rays, rg::Access::StorageRead);
                // Stands for the G-buffer the reflections read: orders the
                // trace after the busy chain too.
                d.shaded = b.read(previous, rg::Access::StorageRead);
                d.hits = b.write(b.createBuffer("bench.hits", {uint64_t(rayCount) * sizeof(shader::BvhProbeHit)}),
                                 rg::Access::StorageWrite);
                b.markSideEffects();
            },
            [this, rayCount, stamped](const Trace& d, rg::PassContext& pc) {
                if (stamped) vkCmdWriteTimestamp2(pc.cmd(), VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, queries_, kTraceBegin);
                trace_.bind(pc.cmd());
                gpu::PushDescriptors(trace_)
                    .accelerationStructure(0, pc.accel(d.tlas).handle())
                    .storageBuffer(1, pc.buffer(d.pool))
                    .storageBuffer(2, pc.buffer(d.offsets))
                    .storageBuffer(3, pc.buffer(d.rays))
                    .storageBuffer(4, pc.buffer(d.hits))
                    .push(pc.gpu(), pc.cmd());
                trace_.pushConstants(pc.cmd(), rayCount);
                if (rayQuery_) {
                    vkCmdDispatch(pc.cmd(), (rayCount + shader::kBvhProbeGroupSize - 1) / shader::kBvhProbeGroupSize, 1, 1);
                } else {
                    sbt_->traceRays(pc.gpu(), pc.cmd(), rayCount, 1);
                }
                if (stamped) vkCmdWriteTimestamp2(pc.cmd(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries_, kTraceEnd);
            });
    }

    gpu::Context& ctx_;
    OverlapSettings settings_;
    bool rayQuery_ = false;
    gpu::Pipeline busy_, trace_;
    std::optional<gpu::ShaderBindingTable> sbt_;
    gpu::Buffer rays_;
    VkQueryPool queries_ = VK_NULL_HANDLE;
};

int runOverlap(gpu::Context& ctx, const app::Args& args) {
    OverlapSettings st;
    const bool cpu = ctx.caps().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    if (args.has("scenes")) st.scene = args.get("scenes", "plaza");
    st.warmup = args.getUint("warmup", cpu ? 5 : 30);
    st.frames = args.getUint("frames", cpu ? 20 : 200);
    st.raysSide = args.getUint("rays", cpu ? 64 : 256);
    st.busyBytes = uint64_t(args.getUint("busy-mib", cpu ? 1 : 16)) << 20;
    st.busyPasses = args.getUint("busy-passes", 4);
    st.busyIterations = args.getUint("busy-iterations", 0);
    st.pipelineOnly = args.common().pipelineOnly;
    if (st.warmup < 2 || st.frames < 1 || st.frames > 10000 || st.raysSide < 1 || st.raysSide > 4096 ||
        st.busyBytes < 16 || st.busyBytes / 16 / 256 > 65535 || st.busyPasses < 1 || st.busyPasses > 64) {
        throw std::runtime_error("--overlap: --warmup >= 2, --frames 1..10000, --rays 1..4096, --busy-mib 1..255, "
                                 "--busy-passes 1..64");
    }
    const bool async = ctx.caps().hasAsyncCompute();
    OverlapRig rig(ctx, st);
    std::printf("glint-bvh-bench --overlap on %s (%s), scene %s, %s\n", ctx.caps().deviceName.c_str(),
                ctx.caps().driverName.c_str(), st.scene.c_str(),
                async ? "with a separate async compute family" : "no separate compute family");
    if (!async) {
        std::printf("the device has no separate compute family: AsyncCompute passes run on the graphics queue, so "
                    "both modes compile to the same plan\n");
    }
    std::printf("timestampPeriod %.3f ns; frame = first timestamp to last over both queues, one frame at a time\n",
                ctx.caps().timestampPeriodNs);

    uint32_t iterations = st.busyIterations;
    if (iterations == 0) {
        // Busy chain ~ the BVH update: measure both on one queue; the
        // chain's time is about fixed + k * iterations, so after two points
        // solve for the iterations (secant steps), and stop within 10%.
        iterations = 16;
        double prevIterations = 0, prevMs = 0;
        for (int step = 0; step < 4; ++step) {
            const OverlapResult c = rig.run(rg::Queue::Graphics, iterations, true);
            std::printf("calibration: %u iterations: busy chain %.3f ms, bvh_update %.3f ms\n", iterations, c.busyMs,
                        c.bvhMs);
            if (c.busyMs <= 0 || c.bvhMs <= 0) break;
            if (std::abs(c.busyMs - c.bvhMs) < 0.1 * c.bvhMs) break;
            double next = double(iterations) * c.bvhMs / c.busyMs;
            if (step > 0 && c.busyMs != prevMs) {
                const double slope = (c.busyMs - prevMs) / (double(iterations) - prevIterations);
                if (slope > 0) next = double(iterations) + (c.bvhMs - c.busyMs) / slope;
            }
            prevIterations = iterations;
            prevMs = c.busyMs;
            const uint32_t clamped = uint32_t(std::clamp(next, 1.0, 1.0e6));
            if (clamped == iterations) break;
            iterations = clamped;
        }
    }
    std::printf("workload: %u busy passes x %.1f MiB x %u iterations, %u x %u rays (%s); %u warm-up + %u frames per "
                "mode\n",
                st.busyPasses, mib(st.busyBytes), iterations, st.raysSide, st.raysSide, rig.backend(), st.warmup,
                st.frames);

    const OverlapResult a = rig.run(rg::Queue::AsyncCompute, iterations);
    const OverlapResult g = rig.run(rg::Queue::Graphics, iterations);
    // bvh_ms: the markers around the pass; pass_ms: the executor's timing of
    // the pass alone; bvh_at: when the markers began, from the frame's start.
    std::printf("%-16s %9s %9s %9s %9s %9s %9s %12s %9s\n", "bvh_update on", "frame_ms", "bvh_ms", "pass_ms", "bvh_at",
                "busy_ms", "trace_ms", "host_ms/frm", "rebuilds");
    for (const auto& [name, r] : {std::pair{"async compute", a}, std::pair{"graphics", g}}) {
        std::printf("%-16s %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %12.3f %9.1f\n", name, r.frameMs, r.bvhMs, r.bvhPassMs,
                    r.bvhStartMs, r.busyMs, r.consumerMs, r.hostMsPerFrame, r.rebuilds);
    }
    const double saving = g.frameMs > 0 ? 100.0 * (g.frameMs - a.frameMs) / g.frameMs : 0.0;
    const double hostSaving = g.hostMsPerFrame > 0 ? 100.0 * (g.hostMsPerFrame - a.hostMsPerFrame) / g.hostMsPerFrame : 0.0;
    std::printf("overlap: async compute saves %.3f ms of %.3f ms GPU frame time (%.1f%%); host, frames in flight: "
                "%.1f%%\n",
                g.frameMs - a.frameMs, g.frameMs, saving, hostSaving);
    ctx.waitIdle();
    const bool clean = app::validationClean(ctx);
    std::printf("overlap_frame_ms_async=%.3f overlap_frame_ms_graphics=%.3f overlap_saving_pct=%.1f "
                "overlap_host_ms_async=%.3f overlap_host_ms_graphics=%.3f\n",
                a.frameMs, g.frameMs, saving, a.hostMsPerFrame, g.hostMsPerFrame);
    return clean ? 0 : 2;
}

} // namespace

int main(int argc, char** argv) {
    return app::runMain("glint-bvh-bench", [&] {
        app::Args args(argc, argv,
                       "glint-bvh-bench: the BVH update pass per scene (first frame, steady frames, TLAS-only "
                       "frames, memory), or with --overlap the frame time with the builds on async compute "
                       "against the graphics queue",
                       {{"scenes", "a,b,...: built-in names or glTF files (default: the plaza and the shared scenes)"},
                        {"frames", "frames measured"},
                        {"warmup", "--overlap: untimed frames first"},
                        {"rays", "--overlap: SIDE of the square traced beside the builds"},
                        {"busy-mib", "--overlap: MiB the graphics stand-in workload touches"},
                        {"busy-passes", "--overlap: passes of the stand-in workload"},
                        {"busy-iterations", "--overlap: iterations per stand-in pass"}},
                       {{"overlap", "measure builds on async compute against builds on the graphics queue"}});
        // Builds and traces BVHs: a device without ray tracing is refused.
        gpu::ContextOptions contextOptions = args.contextOptions();
        contextOptions.requireRayTracing = true;
        if (args.has("overlap")) {
            gpu::Context ctx(contextOptions);
            return runOverlap(ctx, args);
        }
        const uint32_t frames = args.getUint("frames", 31);
        if (frames < 2 || frames > 10000) {
            throw std::runtime_error("--frames " + std::to_string(frames) + ": must be 2..10000");
        }
        std::vector<std::string> scenes;
        if (args.has("scenes")) {
            std::stringstream list(args.get("scenes", ""));
            for (std::string item; std::getline(list, item, ',');) scenes.push_back(item);
        } else {
            scenes = defaultScenes();
        }

        gpu::Context ctx(contextOptions);
        std::printf("glint-bvh-bench on %s (%s), %u frames per scene, builds on %s\n", ctx.caps().deviceName.c_str(),
                    ctx.caps().driverName.c_str(), frames,
                    ctx.caps().hasAsyncCompute() ? "the async compute queue" : "the graphics queue (no async compute)");
        std::printf("%-34s %8s %5s %5s %9s %9s %8s %9s %8s %8s %8s %8s %8s\n", "scene", "tris", "blas", "tlas",
                    "first_ms", "steady_ms", "rebuilds", "tlas_ms", "blas_MiB", "tlas_MiB", "pool_MiB", "geom_MiB",
                    "scr_MiB");
        std::optional<SceneResult> plaza;
        for (const std::string& name : scenes) {
            const SceneResult r = measure(ctx, name, frames, args.gltfOptions());
            const passes::BvhGpuStats& m = r.memory;
            std::printf("%-34s %8llu %5u %5u %9.3f %9s %8.1f %9s %8.2f %8.2f %8.2f %8.2f %8.2f\n", r.name.c_str(),
                        static_cast<unsigned long long>(r.triangles), r.blases, r.tlasInstances, r.firstMs,
                        ms(r.steadyMs).c_str(), r.steadyRebuilds, ms(r.tlasOnlyMs).c_str(), mib(m.blasBytes),
                        mib(m.tlasBytes), mib(m.poolBytes), mib(m.geometryBytes + m.positionBytes), mib(m.scratchBytes));
            if (name == "plaza") plaza = r;
        }
        if (plaza) {
            const passes::BvhGpuStats& m = plaza->memory;
            std::printf("bvh_first_ms_plaza=%.3f bvh_steady_ms_plaza=%s bvh_mib_plaza=%.2f\n", plaza->firstMs,
                        ms(plaza->steadyMs).c_str(),
                        mib(m.blasBytes + m.tlasBytes + m.poolBytes + m.geometryBytes + m.positionBytes));
        }
        ctx.waitIdle();
        return app::validationClean(ctx) ? 0 : 2;
    });
}
