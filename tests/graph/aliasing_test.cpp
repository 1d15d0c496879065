// Transient memory: placement, aliasing, and the barriers aliasing needs.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

bool bytesOverlap(const PlannedResource& a, const PlannedResource& b) {
    return a.heap == b.heap && a.offset < b.offset + b.size && b.offset < a.offset + a.size;
}

// a -> b -> c -> d, each a full-screen texture read only by the next pass.
Graph chain(const QueueCaps& caps) {
    Graph g(caps);
    Texture t[4];
    const char* names[] = {"a", "b", "c", "d"};
    for (int i = 0; i < 4; ++i) t[i] = g.createTexture(names[i], tex(256));
    g.addPass(
        "make_a", Queue::Graphics, [&](Builder& b) { t[0] = b.write(t[0], Access::StorageWrite); }, noop);
    for (int i = 1; i < 4; ++i)
        g.addPass(
            std::string("make_") + names[i], Queue::Graphics,
            [&](Builder& b) {
                b.read(t[i - 1], Access::SampledRead);
                t[i] = b.write(t[i], Access::StorageWrite);
            },
            noop);
    g.markOutput(t[3]);
    return g;
}

} // namespace

TEST_CASE("transients with disjoint lifetimes share bytes") {
    Graph g = chain(oneQueue());
    Plan plan = compileChecked(g);
    const PlannedResource& a = plan.resources[resourceNamed(plan, "a")];
    const PlannedResource& c = plan.resources[resourceNamed(plan, "c")];
    CHECK(bytesOverlap(a, c)); // a dies before c is born
    CHECK(plan.stats.aliasedTransientBytes < plan.stats.transientBytes);
}

TEST_CASE("transients with overlapping lifetimes do not share bytes") {
    Graph g = chain(oneQueue());
    Plan plan = compileChecked(g);
    for (const auto& [x, y] : {std::pair{"a", "b"}, std::pair{"b", "c"}, std::pair{"c", "d"}}) {
        INFO(x << " and " << y);
        CHECK_FALSE(bytesOverlap(plan.resources[resourceNamed(plan, x)], plan.resources[resourceNamed(plan, y)]));
    }
}

TEST_CASE("an alias's first use discards contents and waits for the previous owner's last use") {
    Graph g = chain(oneQueue());
    Plan plan = compileChecked(g);
    const auto first = barriersOn(plan, "make_c", "c");
    REQUIRE(first.size() == 1);
    CHECK(first[0].aliasing);
    CHECK(first[0].oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
    // a's last use (sampled by make_b) must be done before c's bytes are written.
    CHECK((first[0].srcStages & VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT) != 0);
}

TEST_CASE("transient bytes are reported with and without aliasing") {
    Graph g = chain(oneQueue());
    Plan aliased = compileChecked(g);
    CompileOptions off;
    off.aliasing = false;
    Plan separate = compileChecked(g, oneQueue(), off);
    const uint64_t one = estimateMemoryRequirements({"", ResourceKind::Texture, tex(256), {}, 0, 0}).size;
    CHECK(aliased.stats.transientBytes == 4 * one);
    CHECK(separate.stats.transientBytes == 4 * one);
    CHECK(separate.stats.aliasedTransientBytes == 4 * one);
    CHECK(aliased.stats.aliasedTransientBytes == 2 * one); // two live at a time
    for (const char* x : {"a", "b", "c", "d"})
        for (const char* y : {"a", "b", "c", "d"})
            if (std::string(x) != y)
                CHECK_FALSE(bytesOverlap(separate.resources[resourceNamed(separate, x)],
                                         separate.resources[resourceNamed(separate, y)]));
}

TEST_CASE("aliasing never crosses queues, and resources on both queues get bytes of their own") {
    Graph g(twoQueues());
    Texture gfx = g.createTexture("graphics_only", tex(256));
    Texture async = g.createTexture("async_only", tex(256));
    Texture shared = g.createTexture("shared", tex(256));
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "g1", Queue::Graphics, [&](Builder& b) { gfx = b.write(gfx, Access::StorageWrite); }, noop);
    g.addPass(
        "g2", Queue::Graphics,
        [&](Builder& b) {
            b.read(gfx, Access::SampledRead);
            shared = b.write(shared, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "c1", Queue::AsyncCompute,
        [&](Builder& b) {
            b.read(shared, Access::SampledRead);
            async = b.write(async, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "c2", Queue::AsyncCompute,
        [&](Builder& b) {
            b.read(async, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const PlannedResource& gr = plan.resources[resourceNamed(plan, "graphics_only")];
    const PlannedResource& ar = plan.resources[resourceNamed(plan, "async_only")];
    const PlannedResource& sr = plan.resources[resourceNamed(plan, "shared")];
    CHECK(gr.heap != ar.heap);
    CHECK((plan.heaps[gr.heap].queue == Queue::Graphics));
    CHECK((plan.heaps[ar.heap].queue == Queue::AsyncCompute));
    CHECK(sr.crossQueue);
    CHECK(plan.heaps[sr.heap].crossQueue);
    CHECK_FALSE(gr.crossQueue);
}

TEST_CASE("a memory requirements callback sizes transients and keeps memory types apart") {
    Graph g = chain(oneQueue());
    CompileOptions options;
    options.memoryRequirements = [](const TransientDescription& d) {
        // Pretend "a" and "c" need a different memory type.
        const bool special = d.name == "a" || d.name == "c";
        return MemoryRequirements{1u << 20, 4096, special ? 0x2u : 0x1u};
    };
    Plan plan = compileChecked(g, oneQueue(), options);
    CHECK(plan.heaps.size() == 2);
    const PlannedResource& a = plan.resources[resourceNamed(plan, "a")];
    const PlannedResource& b = plan.resources[resourceNamed(plan, "b")];
    CHECK(a.size == (1u << 20));
    CHECK(a.heap != b.heap);
    CHECK(plan.heaps[a.heap].memoryTypeBits == 0x2u);
    CHECK(bytesOverlap(a, plan.resources[resourceNamed(plan, "c")]));
}

TEST_CASE("buffers and images share a heap, placed on bufferImageGranularity boundaries") {
    Graph g(oneQueue());
    Texture image = g.createTexture("image", tex(64));
    Buffer small = g.createBuffer("small", {100});
    Buffer out = g.createBuffer("out", {100});
    g.addPass(
        "a", Queue::Graphics, [&](Builder& b) { image = b.write(image, Access::StorageWrite); }, noop);
    g.addPass(
        "b", Queue::Graphics,
        [&](Builder& b) {
            b.read(image, Access::SampledRead);
            small = b.write(small, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "c", Queue::Graphics,
        [&](Builder& b) {
            b.read(small, Access::StorageRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    QueueCaps caps = oneQueue();
    caps.bufferImageGranularity = 1024;
    Plan plan = compileChecked(g, caps);
    const PlannedResource& s = plan.resources[resourceNamed(plan, "small")];
    const PlannedResource& o = plan.resources[resourceNamed(plan, "out")];
    CHECK(plan.resources[resourceNamed(plan, "image")].heap == s.heap);
    CHECK(plan.heaps[s.heap].images);
    CHECK(plan.heaps[s.heap].buffers);
    CHECK(s.offset % 1024 == 0);
    CHECK(o.offset % 1024 == 0);
    CHECK_FALSE(bytesOverlap(s, o)); // both live in pass c
}

TEST_CASE("a buffer that takes over an image's memory waits for the image's last use") {
    Graph g(oneQueue());
    Texture image = g.createTexture("image", tex(64));
    Buffer first = g.createBuffer("first", {256});
    Buffer later = g.createBuffer("later", {64 * 1024});
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "render", Queue::Graphics, [&](Builder& b) { image = b.write(image, Access::StorageWrite); }, noop);
    g.addPass(
        "reduce", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(image, Access::SampledRead);
            first = b.write(first, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "scatter", Queue::Graphics,
        [&](Builder& b) {
            b.read(first, Access::StorageRead);
            later = b.write(later, Access::StorageWrite);
        },
        noop);
    g.addPass(
        "gather", Queue::Graphics,
        [&](Builder& b) {
            b.read(later, Access::StorageRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const PlannedResource& img = plan.resources[resourceNamed(plan, "image")];
    const PlannedResource& buf = plan.resources[resourceNamed(plan, "later")];
    REQUIRE(bytesOverlap(img, buf));
    const auto bs = barriersOn(plan, "scatter", "later");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].aliasing);
    CHECK((bs[0].srcStages & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT) != 0); // the image's sampling is done
}
