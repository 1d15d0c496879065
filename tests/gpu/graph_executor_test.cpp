// The render graph on a real device: plans compiled for this device's queues
// run with validation (synchronization validation on) and give the right
// numbers back, with aliasing active, across frames in flight.
#include "support/gpu_test.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/gpu/pipeline.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/skip.h"
#include "glint/graph/verify.h"

#include <set>

using namespace glint;

namespace {

constexpr uint32_t kCount = 1024;  // words per buffer
constexpr uint32_t kWidth = 32;    // the image is 32 x 32 words

struct OpPush {
    uint32_t count, mul, add, useSrc;
};

struct Pipelines {
    gpu::Pipeline op, imageWrite, imageRead;
    explicit Pipelines(gpu::Context& ctx) {
        const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
        op = gpu::createComputePipeline(ctx, {"test/graph_op.comp",
                                              {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, cs}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, cs}},
                                              sizeof(OpPush), "test.graph_op"});
        imageWrite = gpu::createComputePipeline(
            ctx, {"test/graph_image_write.comp",
                  {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, cs}, {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, cs}}, sizeof(OpPush),
                  "test.graph_image_write"});
        imageRead = gpu::createComputePipeline(
            ctx, {"test/graph_image_read.comp",
                  {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, cs}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, cs}}, sizeof(OpPush),
                  "test.graph_image_read"});
    }
};

// dst = (src or index) * mul + add, as a graph pass.
struct OpData {
    rg::Buffer src;
    rg::Buffer dst;
};

// `skip`: rg::Builder::skip() this frame (dst keeps what it held).
rg::Buffer addOp(rg::Graph& g, const Pipelines& p, const char* name, rg::Queue queue, rg::Buffer src, rg::Buffer dst,
                 uint32_t mul, uint32_t add, bool skip = false) {
    const OpData& data = g.addPass<OpData>(
        name, queue,
        [&](rg::Builder& b, OpData& d) {
            if (src.valid()) d.src = b.read(src, rg::Access::StorageRead);
            d.dst = b.write(dst, rg::Access::StorageWrite);
            if (skip) b.skip();
        },
        [&p, mul, add](const OpData& d, rg::PassContext& ctx) {
            // An unused source binding still needs a buffer: the destination.
            gpu::PushDescriptors(p.op)
                .storageBuffer(0, ctx.buffer(d.src.valid() ? d.src : d.dst))
                .storageBuffer(1, ctx.buffer(d.dst))
                .push(ctx.gpu(), ctx.cmd());
            p.op.pushConstants(ctx.cmd(), OpPush{kCount, mul, add, d.src.valid() ? 1u : 0u});
            ctx.dispatch(p.op, kCount / 64);
        });
    return data.dst;
}

// image = src + 1, word i at (i % kWidth, i / kWidth): a storage image
// written in GENERAL.
rg::Texture addToImage(rg::Graph& g, const Pipelines& p, rg::Buffer src) {
    struct ImageData {
        rg::Buffer src;
        rg::Texture image;
    };
    const ImageData& data = g.addPass<ImageData>(
        "to-image", rg::Queue::Graphics,
        [&](rg::Builder& b, ImageData& d) {
            d.src = b.read(src, rg::Access::StorageRead);
            d.image = b.write(b.createTexture("image", {kWidth, kCount / kWidth, 1, 1, 1, VK_FORMAT_R32_UINT}),
                              rg::Access::StorageWrite);
        },
        [&p](const ImageData& d, rg::PassContext& pc) {
            CHECK(pc.layout(d.image) == VK_IMAGE_LAYOUT_GENERAL);  // storage images live in GENERAL
            CHECK_THROWS_AS(pc.layout(rg::Texture{}), gpu::GpuError);
            gpu::PushDescriptors(p.imageWrite)
                .storageBuffer(0, pc.buffer(d.src))
                .storageImage(1, pc.view(d.image))
                .push(pc.gpu(), pc.cmd());
            p.imageWrite.pushConstants(pc.cmd(), OpPush{kCount, kWidth, 1, 0});
            pc.dispatch(p.imageWrite, kCount / 64);
        });
    return data.image;
}

// A new buffer "c" holding the image's words, read as a storage image.
rg::Buffer addFromImage(rg::Graph& g, const Pipelines& p, rg::Texture image) {
    struct ReadData {
        rg::Texture image;
        rg::Buffer dst;
    };
    const ReadData& data = g.addPass<ReadData>(
        "from-image", rg::Queue::Graphics,
        [&](rg::Builder& b, ReadData& d) {
            d.image = b.read(image, rg::Access::StorageRead);
            d.dst = b.write(b.createBuffer("c", {kCount * 4}), rg::Access::StorageWrite);
        },
        [&p](const ReadData& d, rg::PassContext& pc) {
            gpu::PushDescriptors(p.imageRead)
                .storageImage(0, pc.view(d.image))
                .storageBuffer(1, pc.buffer(d.dst))
                .push(pc.gpu(), pc.cmd());
            p.imageRead.pushConstants(pc.cmd(), OpPush{kCount, kWidth, 0, 0});
            pc.dispatch(p.imageRead, kCount / 64);
        });
    return data.dst;
}

constexpr rg::BoundaryState kHostRead =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

gpu::Buffer readbackTarget(gpu::Context& ctx, const char* name) {
    return gpu::Buffer(ctx, {kCount * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::Readback, name, true});
}

} // namespace

TEST_CASE("a multi-pass compute graph with aliased transients computes the right values, frame after frame") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const Pipelines pipelines(ctx);
    rg::Executor executor(ctx);
    // Host-serial timing submits every pass alone: the same plan, split
    // into more submissions, must give the same values and time each pass.
    // A timed span (three consecutive graphics passes) with per-pass times
    // off submits the span's passes together, split from the rest of the
    // frame on the host: the values must not change either.
    rg::PassTimer timer = rg::PassTimer::GpuTimestamps;
    bool span = false, perPass = true;
    SUBCASE("passes timed by GPU timestamps") {}
    SUBCASE("passes submitted alone and timed on the host") { timer = rg::PassTimer::HostSerial; }
    SUBCASE("GPU timestamps around the passes and a span") { span = true; }
    SUBCASE("GPU timestamps around a span alone") { span = true, perPass = false; }
    SUBCASE("a span alone timed on the host") {
        timer = rg::PassTimer::HostSerial;
        span = true, perPass = false;
    }
    executor.setPassTimer(timer);
    const std::set<std::string> members = {"double", "to-image", "from-image"};
    if (span) {
        executor.setTimedSpan(rg::TimedSpan{"middle", [&](std::string_view pass) {
                                                return members.count(std::string(pass)) != 0;
                                            }},
                              perPass);
    }
    gpu::Buffer results[2] = {readbackTarget(ctx, "results0"), readbackTarget(ctx, "results1")};

    // Frames 0-3 give each of the two frame slots its command buffers; the
    // later frames must reuse them (a pool reset does not free them).
    constexpr uint32_t kFrames = 8;
    uint32_t commandBuffersAfterWarmUp = 0;
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        if (frame == 4) commandBuffersAfterWarmUp = executor.stats().commandBuffers;
        rg::Graph g(executor.queueCaps());
        const rg::BufferDesc words{kCount * 4};
        rg::Buffer a = addOp(g, pipelines, "fill", rg::Queue::Graphics, {}, g.createBuffer("a", words), 1, 5 + frame);
        rg::Buffer b = addOp(g, pipelines, "double", rg::Queue::Graphics, a, g.createBuffer("b", words), 2, 0);
        const rg::Buffer c = addFromImage(g, pipelines, addToImage(g, pipelines, b));
        // Async compute where the device has it: crosses queues both ways.
        rg::Buffer d = addOp(g, pipelines, "async-add", rg::Queue::AsyncCompute, c, g.createBuffer("d", words), 1, 100);
        // The two result buffers alternate: each was last written by the
        // frame before the previous one (then read by the host).
        const rg::Buffer out = g.importBuffer("results", {words, rg::BoundaryState::of(rg::Access::StorageWrite), kHostRead});
        // Back on graphics: "e" can take the bytes of "a" or "b" (graphics-only
        // transients; memory is never shared across queues within a frame).
        rg::Buffer e = addOp(g, pipelines, "post", rg::Queue::Graphics, d, g.createBuffer("e", words), 1, 0);
        rg::Buffer written = addOp(g, pipelines, "copy-out", rg::Queue::Graphics, e, out, 1, 0);
        g.markOutput(written);

        const rg::Plan plan = g.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        // "a" is dead once "double" ran: later transients take its bytes.
        CHECK(plan.stats.aliasedTransientBytes < plan.stats.transientBytes);

        rg::FrameResources imports;
        gpu::Buffer& target = results[frame % 2];
        imports.bind(out, target);
        executor.run(plan, imports);
        executor.waitIdle();
        const auto words32 = target.mappedSpan<uint32_t>();
        for (uint32_t i = 0; i < kCount; ++i) {
            INFO("frame " << frame << " word " << i);
            REQUIRE(words32[i] == (i + 5 + frame) * 2 + 1 + 100);
        }
    }
    CHECK(executor.stats().transientRebuilds == 1);  // same layout every frame: memory kept
    CHECK(commandBuffersAfterWarmUp > 0);
    CHECK(executor.stats().commandBuffers == commandBuffersAfterWarmUp);

    const auto timings = executor.timings();
    REQUIRE(timings.size() == 7);
    std::set<std::string> names;
    const std::optional<double> spanMs = executor.spanTiming();
    CHECK(spanMs.has_value() == (span && (timer == rg::PassTimer::HostSerial || ctx.caps().timestamps)));
    if (spanMs) CHECK(*spanMs > 0.0);
    for (const auto& t : timings) {
        names.insert(t.name);
        if (!perPass) {
            CHECK_FALSE(t.milliseconds.has_value());
        } else if (timer == rg::PassTimer::HostSerial) {
            REQUIRE(t.milliseconds.has_value());
            REQUIRE(t.cpuMilliseconds.has_value());
            CHECK(*t.milliseconds > 0.0);
            CHECK(*t.cpuMilliseconds >= 0.0);
        } else if (ctx.caps().timestamps) {
            CHECK(t.milliseconds.has_value());
            CHECK_FALSE(t.cpuMilliseconds.has_value());
        }
    }
    CHECK(names == std::set<std::string>{"fill", "double", "to-image", "from-image", "async-add", "post", "copy-out"});
}

TEST_CASE("skipped passes record nothing, and the barriers they carry still order the frame") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const Pipelines pipelines(ctx);
    rg::Executor executor(ctx);
    rg::PassTimer timer = rg::PassTimer::GpuTimestamps;
    // A span (per-pass times off) starts at its first member that runs: a
    // skipped one records nothing; a span of skipped members is no span.
    std::set<std::string> spanMembers;
    SUBCASE("passes timed by GPU timestamps") {}
    SUBCASE("passes submitted alone and timed on the host") { timer = rg::PassTimer::HostSerial; }
    SUBCASE("a span from a member skipped on odd frames") { spanMembers = {"overwrite", "to-image"}; }
    SUBCASE("a span of a member skipped on odd frames") { spanMembers = {"probe"}; }
    SUBCASE("a span of a member skipped on odd frames, on the host") {
        timer = rg::PassTimer::HostSerial;
        spanMembers = {"probe"};
    }
    executor.setPassTimer(timer);
    if (!spanMembers.empty()) {
        executor.setTimedSpan(rg::TimedSpan{"skips", [&](std::string_view pass) {
                                                return spanMembers.count(std::string(pass)) != 0;
                                            }},
                              false);
    }
    const bool timed = timer == rg::PassTimer::HostSerial || ctx.caps().timestamps;
    gpu::Buffer results[2] = {readbackTarget(ctx, "skip.results0"), readbackTarget(ctx, "skip.results1")};

    // Odd frames skip "overwrite" (the buffer rewritten) and "probe"
    // (the image copied out as a transfer source: a layout of its own
    // between the storage write and the storage read around it).
    uint32_t probes = 0;
    constexpr uint32_t kFrames = 6;
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        const bool skip = frame % 2 == 1;
        rg::Graph g(executor.queueCaps());
        const rg::BufferDesc words{kCount * 4};
        rg::Buffer a = addOp(g, pipelines, "fill", rg::Queue::Graphics, {}, g.createBuffer("a", words), 1, 5 + frame);
        const rg::Buffer seed = addOp(g, pipelines, "seed", rg::Queue::Graphics, {}, g.createBuffer("seed", words), 0, 7);
        a = addOp(g, pipelines, "overwrite", rg::Queue::Graphics, seed, a, 1, 0, skip);
        const rg::Texture image = addToImage(g, pipelines, a);
        struct ProbeData {
            rg::Texture image;
            rg::Buffer copy;
        };
        g.addPass<ProbeData>(
            "probe", rg::Queue::Graphics,
            [&](rg::Builder& b, ProbeData& d) {
                d.image = b.read(image, rg::Access::TransferSrc);
                d.copy = b.write(b.createBuffer("probe.copy", words), rg::Access::TransferDst);
                b.markSideEffects();
                if (skip) b.skip();
            },
            [&probes](const ProbeData& d, rg::PassContext& pc) {
                ++probes;
                VkBufferImageCopy region{};
                region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                region.imageExtent = {kWidth, kCount / kWidth, 1};
                vkCmdCopyImageToBuffer(pc.cmd(), pc.image(d.image).handle(), pc.layout(d.image),
                                       pc.buffer(d.copy).handle(), 1, &region);
            });
        const rg::Buffer c = addFromImage(g, pipelines, image);
        const rg::Buffer out =
            g.importBuffer("results", {words, rg::BoundaryState::of(rg::Access::StorageWrite), kHostRead});
        g.markOutput(addOp(g, pipelines, "copy-out", rg::Queue::Graphics, c, out, 1, 0));

        const rg::Plan plan = g.compile(executor.compileOptions());
        REQUIRE(rg::verify(plan).ok());
        if (skip) {
            // The frame as the executor runs it; a carried barrier may
            // serve only the pass that skipped, so redundancy is not asked.
            rg::VerifyOptions options;
            options.checkRedundancy = false;
            const rg::Plan carried = rg::skipPasses(plan);
            const auto report = rg::verify(carried, options);
            REQUIRE_MESSAGE(report.ok(), report.text());
            CHECK(carried.findPass("probe")->skipped);
            CHECK(carried.findPass("probe")->barrierCount == 0);
        }
        rg::FrameResources imports;
        gpu::Buffer& target = results[frame % 2];
        imports.bind(out, target);
        executor.run(plan, imports);
        executor.waitIdle();
        const auto words32 = target.mappedSpan<uint32_t>();
        for (uint32_t i = 0; i < kCount; ++i) {
            INFO("frame " << frame << " word " << i);
            REQUIRE(words32[i] == (skip ? i + 5 + frame : 7u) + 1);
        }
        if (!spanMembers.empty() && timed) {
            INFO("frame " << frame);
            const bool onlySkipped = spanMembers.count("to-image") == 0 && skip;
            CHECK(executor.spanTiming().has_value() == !onlySkipped);
        }
    }
    CHECK(probes == kFrames / 2);
    CHECK(executor.stats().transientRebuilds == 1); // skipping keeps the plan's memory
    // The last frame skipped both: they took no time.
    if (spanMembers.empty()) {
        uint32_t skippedTimings = 0;
        for (const rg::PassTiming& t : executor.timings()) {
            INFO(t.name);
            const bool skippedPass = t.name == "overwrite" || t.name == "probe";
            CHECK(t.skipped == skippedPass);
            if (skippedPass) {
                ++skippedTimings;
                REQUIRE(t.milliseconds.has_value());
                CHECK(*t.milliseconds == 0.0);
            } else if (timed) {
                CHECK(t.milliseconds.has_value());
            }
        }
        CHECK(skippedTimings == 2);
    }
}

TEST_CASE("a history buffer carries last frame's value into this frame, with two frames in flight") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const Pipelines pipelines(ctx);
    rg::Executor executor(ctx, 2);
    constexpr uint32_t kFrames = 5;
    std::vector<gpu::Buffer> results;
    for (uint32_t i = 0; i < kFrames; ++i) {
        results.push_back(readbackTarget(ctx, "history.result"));
    }
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        rg::Graph g(executor.queueCaps());
        const rg::BufferDesc words{kCount * 4};
        const rg::HistoryBuffer counter = g.createHistoryBuffer("counter", words);
        // current = previous + 1 (previous starts cleared to zero)
        rg::Buffer current = addOp(g, pipelines, "count", rg::Queue::Graphics, counter.previous, counter.current, 1, 1);
        const rg::Buffer out = g.importBuffer("result", {words, rg::BoundaryState::of(rg::Access::None), kHostRead});
        g.markOutput(addOp(g, pipelines, "copy-out", rg::Queue::Graphics, current, out, 1, 0));
        const rg::Plan plan = g.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        rg::FrameResources imports;
        imports.bind(out, results[frame]);
        executor.run(plan, imports);
    }
    executor.waitIdle();
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        const auto words32 = results[frame].mappedSpan<uint32_t>();
        for (uint32_t i = 0; i < kCount; i += 97) {
            INFO("frame " << frame << " word " << i);
            REQUIRE(words32[i] == frame + 1);
        }
    }
}

TEST_CASE("a history texture survives plans that leave it in other layouts, and a resize starts it afresh") {
    // Frames alternate two plans: A writes `current` with a transfer clear
    // (it ends in TRANSFER_DST), B with a shader (GENERAL); both read
    // `previous` with a shader. Each plan expects the layouts its own cycle
    // leaves, so the executor must move the images when the plan changes.
    // Validation (layouts at submit, sync hazards) fails the test on any
    // message; the values prove the history itself carried over.
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const Pipelines pipelines(ctx);
    rg::Executor executor(ctx, 2);
    constexpr uint32_t kFrames = 6;
    std::vector<gpu::Buffer> results;
    for (uint32_t i = 0; i < kFrames; ++i) results.push_back(readbackTarget(ctx, "history.texture.result"));
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        // The last frame shrinks the image: a new pair, cleared.
        const uint32_t height = frame + 1 == kFrames ? kCount / kWidth / 2 : kCount / kWidth;
        const uint32_t words = kWidth * height;
        rg::Graph g(executor.queueCaps());
        const rg::HistoryTexture history = g.createHistoryTexture("history", {kWidth, height, 1, 1, 1, VK_FORMAT_R32_UINT});
        struct WriteData {
            rg::Buffer src;
            rg::Texture image;
        };
        const uint32_t value = frame + 1;
        rg::Texture written;
        if (frame % 2 == 0) {
            written = g.addPass<WriteData>(
                           "write-clear", rg::Queue::Graphics,
                           [&](rg::Builder& b, WriteData& d) { d.image = b.write(history.current, rg::Access::TransferDst); },
                           [value](const WriteData& d, rg::PassContext& pc) {
                               VkClearColorValue clear{};
                               clear.uint32[0] = value;
                               const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                               vkCmdClearColorImage(pc.cmd(), pc.image(d.image).handle(), pc.layout(d.image), &clear, 1,
                                                    &range);
                           })
                          .image;
        } else {
            const rg::Buffer filled = addOp(g, pipelines, "fill", rg::Queue::Graphics, {},
                                            g.createBuffer("fill", {kCount * 4}), 0, value);
            written = g.addPass<WriteData>(
                           "write-shader", rg::Queue::Graphics,
                           [&](rg::Builder& b, WriteData& d) {
                               d.src = b.read(filled, rg::Access::StorageRead);
                               d.image = b.write(history.current, rg::Access::StorageWrite);
                           },
                           [&pipelines, words](const WriteData& d, rg::PassContext& pc) {
                               gpu::PushDescriptors(pipelines.imageWrite)
                                   .storageBuffer(0, pc.buffer(d.src))
                                   .storageImage(1, pc.view(d.image))
                                   .push(pc.gpu(), pc.cmd());
                               pipelines.imageWrite.pushConstants(pc.cmd(), OpPush{words, kWidth, 0, 0});
                               pc.dispatch(pipelines.imageWrite, words / 64);
                           })
                          .image;
        }
        (void)written;
        struct ReadData {
            rg::Texture image;
            rg::Buffer dst;
        };
        const ReadData& read = g.addPass<ReadData>(
            "read-previous", rg::Queue::Graphics,
            [&](rg::Builder& b, ReadData& d) {
                d.image = b.read(history.previous, rg::Access::StorageRead);
                d.dst = b.write(g.createBuffer("previous-words", {kCount * 4}), rg::Access::StorageWrite);
            },
            [&pipelines, words](const ReadData& d, rg::PassContext& pc) {
                gpu::PushDescriptors(pipelines.imageRead)
                    .storageImage(0, pc.view(d.image))
                    .storageBuffer(1, pc.buffer(d.dst))
                    .push(pc.gpu(), pc.cmd());
                pipelines.imageRead.pushConstants(pc.cmd(), OpPush{words, kWidth, 0, 0});
                pc.dispatch(pipelines.imageRead, words / 64);
            });
        const rg::Buffer out = g.importBuffer("result", {{kCount * 4}, rg::BoundaryState::of(rg::Access::None), kHostRead});
        g.markOutput(addOp(g, pipelines, "copy-out", rg::Queue::Graphics, read.dst, out, 1, 0));
        const rg::Plan plan = g.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        rg::FrameResources imports;
        imports.bind(out, results[frame]);
        executor.run(plan, imports);
    }
    executor.waitIdle();
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        const auto got = results[frame].mappedSpan<uint32_t>();
        // `previous` holds last frame's value; frame 0 and the resized frame
        // start from a cleared pair.
        const uint32_t expected = frame == 0 || frame + 1 == kFrames ? 0u : frame;
        INFO("frame " << frame);
        CHECK(got[0] == expected);
        CHECK(got[kWidth * 3 + 5] == expected);
    }
}

TEST_CASE("running a plan whose import has nothing bound names the resource") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const Pipelines pipelines(ctx);
    rg::Executor executor(ctx);
    rg::Graph g(executor.queueCaps());
    const rg::Buffer out = g.importBuffer("unbound-results", {{kCount * 4}, rg::BoundaryState::of(rg::Access::None), kHostRead});
    g.markOutput(addOp(g, pipelines, "fill", rg::Queue::Graphics, {}, out, 1, 0));
    const rg::Plan plan = g.compile(executor.compileOptions());
    CHECK_THROWS_WITH_AS(executor.run(plan, {}), doctest::Contains("'unbound-results' has no resource bound"),
                         gpu::GpuError);
}

namespace {

gpu::Unique<VkSemaphore> binarySemaphore(gpu::Context& ctx, const std::string& name) {
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    gpu::check(vkCreateSemaphore(ctx.device(), &info, nullptr, &semaphore), "vkCreateSemaphore");
    ctx.setName(semaphore, VK_OBJECT_TYPE_SEMAPHORE, name);
    return gpu::Unique<VkSemaphore>(ctx.device(), semaphore, vkDestroySemaphore);
}

gpu::Unique<VkFence> fence(gpu::Context& ctx) {
    VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence f = VK_NULL_HANDLE;
    gpu::check(vkCreateFence(ctx.device(), &info, nullptr, &f), "vkCreateFence");
    return gpu::Unique<VkFence>(ctx.device(), f, vkDestroyFence);
}

// One submission outside the graph: optional command buffer, one binary
// semaphore waited and one signalled, an optional fence.
void submitOutside(gpu::Context& ctx, gpu::CommandPool& pool, VkSemaphore wait, VkPipelineStageFlags2 waitStages,
                   VkSemaphore signal, VkPipelineStageFlags2 signalStages, VkFence done,
                   const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    if (record) {
        VkCommandBuffer cmd = pool.allocate();
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        gpu::check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
        record(cmd);
        gpu::check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
        cmdInfo.commandBuffer = cmd;
    }
    VkSemaphoreSubmitInfo waitInfo{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    waitInfo.semaphore = wait;
    waitInfo.stageMask = waitStages;
    VkSemaphoreSubmitInfo signalInfo{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    signalInfo.semaphore = signal;
    signalInfo.stageMask = signalStages;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.waitSemaphoreInfoCount = wait ? 1 : 0;
    submit.pWaitSemaphoreInfos = &waitInfo;
    submit.commandBufferInfoCount = record ? 1 : 0;
    submit.pCommandBufferInfos = &cmdInfo;
    submit.signalSemaphoreInfoCount = signal ? 1 : 0;
    submit.pSignalSemaphoreInfos = &signalInfo;
    gpu::check(vkQueueSubmit2(ctx.graphicsQueue().queue, 1, &submit, done), "vkQueueSubmit2 (outside the graph)");
}

} // namespace

TEST_CASE("an external image is waited for on a binary semaphore, ends in PRESENT_SRC and signals another") {
    // The swapchain's part is played by the test: it owns the image, a
    // "producer" submission signals `ready` (as vkAcquireNextImageKHR
    // would), the graph draws into the image through a non-owning wrapper,
    // and a "consumer" submission waits on `finished` (as
    // vkQueuePresentKHR would) and reads the image back. Frame 0 imports
    // the producer's contents (it clears the image to 7 first); later frames
    // import it as acquired (contents undefined). The validation layer,
    // synchronisation validation on, judges the semaphore placement, the
    // stages and the PRESENT_SRC layout; the values prove the order.
    gpu::ContextOptions options;
    // VK_IMAGE_LAYOUT_PRESENT_SRC_KHR needs VK_KHR_swapchain (and it VK_KHR_surface); no surface is made.
    options.swapchain = true;
    options.instanceExtensions = {VK_KHR_SURFACE_EXTENSION_NAME};
    test::GpuTest gpu(options);
    auto& ctx = gpu.ctx();
    rg::Executor executor(ctx);
    constexpr uint32_t kFrames = 4;
    const gpu::ImageDesc desc{kWidth, kWidth, 1, 1, 1, VK_FORMAT_R32_UINT,
                              VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                  VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                              "external.owner"};
    const gpu::Image owner(ctx, desc);
    gpu::CommandPool pool(ctx, ctx.graphicsQueue().family, "external.pool");
    std::vector<gpu::Image> wrappers;  // kept until the GPU is done with their views
    // One of each, reused every frame: a binary semaphore signalled twice
    // without a wait between, or waited with no signal pending, is a
    // validation error, so a wait or signal the executor dropped fails.
    const gpu::Unique<VkSemaphore> ready = binarySemaphore(ctx, "external.ready");
    const gpu::Unique<VkSemaphore> finished = binarySemaphore(ctx, "external.finished");
    std::vector<gpu::Unique<VkFence>> consumed;
    std::vector<gpu::Buffer> readbacks;
    const gpu::Buffer seenByGraph(ctx, {kWidth * kWidth * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        gpu::MemoryUsage::Readback, "external.seen"});

    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        consumed.push_back(fence(ctx));
        readbacks.emplace_back(ctx, gpu::BufferDesc{kWidth * kWidth * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                    gpu::MemoryUsage::Readback, "external.readback"});
        const bool keepContents = frame == 0;

        // ---- producer: frame 0 clears to 7 (left in TRANSFER_DST); later
        // frames only signal, after everything earlier on the queue, as an
        // acquire does.
        submitOutside(ctx, pool, VK_NULL_HANDLE, 0, ready.get(),
                      keepContents ? VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_NULL_HANDLE, !keepContents ? std::function<void(VkCommandBuffer)>{} : [&](VkCommandBuffer cmd) {
                          gpu::imageBarrier(cmd, owner, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                            VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                                            VK_ACCESS_2_TRANSFER_WRITE_BIT);
                          VkClearColorValue seven{};
                          seven.uint32[0] = 7;
                          const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                          vkCmdClearColorImage(cmd, owner.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &seven, 1,
                                               &range);
                      });

        // ---- the graph
        rg::Graph g(executor.queueCaps());
        rg::FrameResources imports;
        const rg::BoundaryState initial =
            keepContents ? rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL)
                         : rg::BoundaryState::acquired(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
        rg::Texture image = g.importTexture(
            "external", {{kWidth, kWidth, 1, 1, 1, VK_FORMAT_R32_UINT}, initial, rg::BoundaryState::of(rg::Access::Present)});
        if (keepContents) {
            // Reads what the producer left (so the wait must come before its
            // first use, a transfer read), then overwrites it.
            struct SeenData {
                rg::Texture image;
                rg::Buffer seen;
            };
            const rg::Buffer seen =
                g.importBuffer("seen", {{kWidth * kWidth * 4}, rg::BoundaryState::of(rg::Access::None), kHostRead});
            const SeenData& read = g.addPass<SeenData>(
                "read-producer", rg::Queue::Graphics,
                [&](rg::Builder& b, SeenData& d) {
                    d.image = b.read(image, rg::Access::TransferSrc);
                    d.seen = b.write(seen, rg::Access::TransferDst);
                },
                [](const SeenData& d, rg::PassContext& pc) {
                    VkBufferImageCopy region{};
                    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                    region.imageExtent = {kWidth, kWidth, 1};
                    vkCmdCopyImageToBuffer(pc.cmd(), pc.image(d.image).handle(), pc.layout(d.image),
                                           pc.buffer(d.seen).handle(), 1, &region);
                });
            imports.bind(seen, seenByGraph);
            image = read.image;
        }
        {
            struct ClearData {
                rg::Texture image;
            };
            const uint32_t value = 100 + frame;
            g.addPass<ClearData>(
                "clear", rg::Queue::Graphics,
                [&](rg::Builder& b, ClearData& d) { d.image = b.write(image, rg::Access::TransferDst); },
                [value](const ClearData& d, rg::PassContext& pc) {
                    VkClearColorValue clear{};
                    clear.uint32[0] = value;
                    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                    vkCmdClearColorImage(pc.cmd(), pc.image(d.image).handle(), pc.layout(d.image), &clear, 1, &range);
                });
        }
        const rg::Plan plan = g.compile(executor.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        // The wait goes to the first use's batch, at its (transfer) stage.
        const uint32_t external = plan.findResource("external");
        CHECK(plan.firstUseOf(external).batch == 0);
        CHECK(plan.firstUseOf(external).stages == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
        CHECK(plan.batchEnding(external) == plan.batches.size() - 1);

        wrappers.push_back(gpu::Image::external(ctx, owner.handle(), desc));
        CHECK(wrappers.back().isExternal());
        CHECK(wrappers.back().view() != VK_NULL_HANDLE);  // its own view of the image it does not own
        imports.bind(image, wrappers.back());
        imports.waitSemaphore(image, ready.get());  // stages: the first use's (a transfer)
        imports.signalSemaphore(image, finished.get());
        const rg::SubmittedFrame submitted = executor.run(plan, imports);
        CHECK(submitted.frame == frame);

        // ---- consumer: waits on `finished`, finds PRESENT_SRC, reads back.
        const gpu::Buffer& readback = readbacks.back();
        submitOutside(ctx, pool, finished.get(), VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_NULL_HANDLE, 0,
                      consumed.back().get(), [&](VkCommandBuffer cmd) {
                          gpu::imageBarrier(cmd, owner, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                                            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                            0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
                          VkBufferImageCopy region{};
                          region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                          region.imageExtent = {kWidth, kWidth, 1};
                          vkCmdCopyImageToBuffer(cmd, owner.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                                 readback.handle(), 1, &region);
                          gpu::bufferBarrier(cmd, readback, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                             VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
                      });
        // The frame's own completion: its semaphores may be reused after it.
        executor.wait(submitted);
        CHECK(executor.finished(submitted));
        const VkFence done = consumed.back().get();
        gpu::check(vkWaitForFences(ctx.device(), 1, &done, VK_TRUE, 10'000'000'000ull), "vkWaitForFences");
        const auto words = readback.mappedSpan<uint32_t>();
        INFO("frame " << frame);
        if (keepContents) {
            // The graph's first pass saw the producer's clear.
            const auto seenWords = seenByGraph.mappedSpan<uint32_t>();
            CHECK(seenWords[0] == 7u);
            CHECK(seenWords[kWidth * kWidth - 1] == 7u);
        }
        CHECK(words[0] == 100u + frame);
        CHECK(words[kWidth * kWidth - 1] == 100u + frame);
    }
    executor.waitIdle();
}
