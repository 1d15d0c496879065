// Misuse: every error names the pass and the resource, where it happens.

#include <doctest/doctest.h>

#include <string>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

// Runs `declare`, expecting a GraphError of `kind` naming `pass` and
// `resource` (in its fields and its message).
template <class F>
void expectError(F&& declare, ErrorKind kind, const std::string& pass, const std::string& resource) {
    try {
        declare();
        FAIL("no GraphError was thrown");
    } catch (const GraphError& e) {
        INFO(e.what());
        CHECK((e.kind() == kind));
        CHECK(e.pass() == pass);
        CHECK(e.resource() == resource);
        CHECK(contains(e.what(), "'" + pass + "'"));
        CHECK(contains(e.what(), "'" + resource + "'"));
    }
}

} // namespace

TEST_CASE("reading a resource nobody wrote names the pass and the resource") {
    Graph g(twoQueues());
    Texture t = g.createTexture("gbuffer.normal", tex());
    expectError(
        [&] {
            g.addPass(
                "sslr", Queue::Graphics, [&](Builder& b) { b.read(t, Access::SampledRead); }, noop);
        },
        ErrorKind::ReadBeforeWrite, "sslr", "gbuffer.normal");
}

TEST_CASE("reading a mip nobody wrote is an error even when another mip was written") {
    Graph g(twoQueues());
    Texture t = g.createTexture("hiz", tex(64, VK_FORMAT_R32_SFLOAT, 3));
    g.addPass(
        "mip0", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite, Subresource::mip(0)); }, noop);
    expectError(
        [&] {
            g.addPass(
                "reader", Queue::Graphics, [&](Builder& b) { b.read(t, Access::SampledRead); }, noop);
        },
        ErrorKind::ReadBeforeWrite, "reader", "hiz");
}

TEST_CASE("reading a stale handle version is an error") {
    Graph g(twoQueues());
    Texture v0 = g.createTexture("lit", tex());
    Texture v1, v2;
    g.addPass(
        "gbuffer", Queue::Graphics, [&](Builder& b) { v1 = b.write(v0, Access::StorageWrite); }, noop);
    g.addPass(
        "decals", Queue::Graphics, [&](Builder& b) { v2 = b.write(v1, Access::StorageReadWrite); }, noop);
    expectError(
        [&] {
            g.addPass(
                "sslr", Queue::Graphics, [&](Builder& b) { b.read(v1, Access::SampledRead); }, noop);
        },
        ErrorKind::StaleHandle, "sslr", "lit");
}

TEST_CASE("two writers of one version are unordered") {
    Graph g(twoQueues());
    Texture v0 = g.createTexture("radiance", tex());
    Texture v1;
    g.addPass(
        "first", Queue::Graphics, [&](Builder& b) { v1 = b.write(v0, Access::StorageWrite); }, noop);
    g.addPass(
        "reader", Queue::Graphics, [&](Builder& b) { b.read(v1, Access::SampledRead); }, noop);
    Texture v1b;
    expectError(
        [&] {
            g.addPass(
                "second", Queue::AsyncCompute, [&](Builder& b) { v1b = b.write(v0, Access::StorageWrite); }, noop);
        },
        ErrorKind::UnorderedWriters, "second", "radiance");
}

TEST_CASE("a cycle through explicit orderings is reported with a resource on it") {
    Graph g(twoQueues());
    Buffer buf = g.createBuffer("counters", {256});
    PassId producer = g.addPass(
        "producer", Queue::Graphics, [&](Builder& b) { buf = b.write(buf, Access::StorageWrite); }, noop);
    PassId consumer = g.addPass(
        "consumer", Queue::Graphics,
        [&](Builder& b) {
            b.read(buf, Access::StorageRead);
            b.markSideEffects();
        },
        noop);
    g.order(consumer, producer); // contradicts the data flow
    expectError([&] { (void)g.compile(); }, ErrorKind::Cycle, "producer", "counters");
    try {
        (void)g.compile();
    } catch (const GraphError& e) {
        CHECK(contains(e.what(), "'consumer'"));
        CHECK(contains(e.what(), "(order)"));
    }
}

TEST_CASE("a colour attachment on the async compute queue is refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("hud", tex());
    expectError(
        [&] {
            g.addPass(
                "overlay", Queue::AsyncCompute, [&](Builder& b) { t = b.write(t, Access::ColorAttachment); }, noop);
        },
        ErrorKind::QueueCannotAccess, "overlay", "hud");
}

TEST_CASE("a raster pipeline on the async compute queue is refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("target", tex());
    expectError(
        [&] {
            g.addPass(
                "draw", Queue::AsyncCompute,
                [&](Builder& b) {
                    b.setPipeline(Pipeline::Raster);
                    t = b.write(t, Access::StorageWrite);
                },
                noop);
        },
        ErrorKind::QueueCannotAccess, "draw", "target");
}

TEST_CASE("a handle from another graph is refused") {
    Graph lastFrame(twoQueues());
    Texture stale = lastFrame.createTexture("reflections", tex());
    lastFrame.addPass(
        "temporal", Queue::Graphics, [&](Builder& b) { stale = b.write(stale, Access::StorageWrite); }, noop);
    Graph g(twoQueues());
    g.createTexture("reflections", tex());
    try {
        g.addPass(
            "composite", Queue::Graphics, [&](Builder& b) { b.read(stale, Access::SampledRead); }, noop);
        FAIL("no GraphError was thrown");
    } catch (const GraphError& e) {
        CHECK((e.kind() == ErrorKind::ForeignHandle));
        CHECK(e.pass() == "composite");
        CHECK(contains(e.what(), "another graph"));
    }
    // A default handle belongs to no graph.
    try {
        g.addPass(
            "composite2", Queue::Graphics, [&](Builder& b) { b.read(Texture{}, Access::SampledRead); }, noop);
        FAIL("no GraphError was thrown");
    } catch (const GraphError& e) {
        CHECK((e.kind() == ErrorKind::ForeignHandle));
    }
}

TEST_CASE("an imported resource without an initial or final state is refused where it is used") {
    Graph g(twoQueues());
    Texture swapchain = g.importTexture("swapchain", {tex(), std::nullopt, BoundaryState::of(Access::Present)});
    AccelStruct tlas = g.importAccelStruct("tlas", {BoundaryState::of(Access::AccelRead), std::nullopt});
    expectError(
        [&] {
            g.addPass(
                "tonemap", Queue::Graphics,
                [&](Builder& b) {
                    b.setPipeline(Pipeline::Raster);
                    swapchain = b.write(swapchain, Access::ColorAttachment);
                },
                noop);
        },
        ErrorKind::ImportWithoutState, "tonemap", "swapchain");
    expectError(
        [&] {
            g.addPass(
                "trace", Queue::Graphics, [&](Builder& b) { b.read(tlas, Access::AccelRead); }, noop);
        },
        ErrorKind::ImportWithoutState, "trace", "tlas");
}

TEST_CASE("an access the resource kind cannot take is refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("image", tex());
    expectError(
        [&] {
            g.addPass(
                "dispatch", Queue::Graphics, [&](Builder& b) { b.read(t, Access::IndirectArgs); }, noop);
        },
        ErrorKind::InvalidAccess, "dispatch", "image");
    Buffer buffer = g.createBuffer("args", {64});
    expectError(
        [&] {
            g.addPass(
                "clear", Queue::Graphics, [&](Builder& b) { (void)b.write(buffer, Access::ColorAttachment); }, noop);
        },
        ErrorKind::InvalidAccess, "clear", "args");
}

TEST_CASE("read() with a writing kind and write() with a reading kind are refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("image", tex());
    expectError(
        [&] {
            g.addPass(
                "p", Queue::Graphics, [&](Builder& b) { b.read(t, Access::StorageWrite); }, noop);
        },
        ErrorKind::InvalidAccess, "p", "image");
    expectError(
        [&] {
            g.addPass(
                "q", Queue::Graphics, [&](Builder& b) { (void)b.write(t, Access::SampledRead); }, noop);
        },
        ErrorKind::InvalidAccess, "q", "image");
}

TEST_CASE("attachments need a raster pipeline") {
    Graph g(twoQueues());
    Texture t = g.createTexture("target", tex());
    expectError(
        [&] {
            g.addPass(
                "draw", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::ColorAttachment); }, noop);
        },
        ErrorKind::InvalidAccess, "draw", "target");
}

TEST_CASE("a subresource outside the texture is refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("cube", tex(64, VK_FORMAT_R16G16B16A16_SFLOAT, 2, 6));
    expectError(
        [&] {
            g.addPass(
                "face", Queue::Graphics,
                [&](Builder& b) {
                    t = b.write(t, Access::StorageWrite, {0, 1, 6, 1});
                },
                noop);
        },
        ErrorKind::InvalidSubresource, "face", "cube");
    expectError(
        [&] {
            g.addPass(
                "mip", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite, Subresource::mip(2)); },
                noop);
        },
        ErrorKind::InvalidSubresource, "mip", "cube");
}

TEST_CASE("one subresource used twice in one pass in different ways is refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("image", tex());
    g.addPass(
        "init", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    expectError(
        [&] {
            g.addPass(
                "both", Queue::Graphics,
                [&](Builder& b) {
                    b.read(t, Access::SampledRead);
                    b.read(t, Access::StorageRead); // another layout
                },
                noop);
        },
        ErrorKind::ConflictingAccess, "both", "image");
    expectError(
        [&] {
            g.addPass(
                "rw", Queue::Graphics,
                [&](Builder& b) {
                    b.read(t, Access::StorageRead);
                    t = b.write(t, Access::StorageWrite);
                },
                noop);
        },
        ErrorKind::ConflictingAccess, "rw", "image");
}

TEST_CASE("ray queries and ray tracing pipelines need the device feature") {
    QueueCaps caps = twoQueues();
    caps.rayQuery = false;
    caps.rayTracingPipeline = false;
    Graph g(caps);
    AccelStruct tlas =
        g.importAccelStruct("tlas", {BoundaryState::of(Access::AccelRead), BoundaryState::of(Access::AccelRead)});
    Texture out = g.createTexture("hits", tex());
    g.addPass(
        "trace", Queue::Graphics,
        [&](Builder& b) {
            b.read(tlas, Access::AccelRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    expectError([&] { (void)g.compile(); }, ErrorKind::UnsupportedFeature, "trace", "tlas");
    caps.rayQuery = true;
    CHECK_NOTHROW((void)compile(g, caps));
}

TEST_CASE("an output nobody wrote, and a stale output, are refused") {
    Graph g(twoQueues());
    Texture t = g.createTexture("image", tex());
    expectError([&] { g.markOutput(t); }, ErrorKind::ReadBeforeWrite, "(output)", "image");
    Texture v1;
    g.addPass(
        "a", Queue::Graphics, [&](Builder& b) { v1 = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "b", Queue::Graphics, [&](Builder& b) { (void)b.write(v1, Access::StorageReadWrite); }, noop);
    expectError([&] { g.markOutput(v1); }, ErrorKind::StaleHandle, "(output)", "image");
}

TEST_CASE("descriptions that cannot be created are refused") {
    Graph g(twoQueues());
    CHECK_THROWS_AS(g.createTexture("empty", TextureDesc{0, 64, 1, 1, 1, VK_FORMAT_R8_UNORM}), GraphError);
    CHECK_THROWS_AS(g.createTexture("noformat", TextureDesc{64, 64, 1, 1, 1, VK_FORMAT_UNDEFINED}), GraphError);
    CHECK_THROWS_AS(g.createTexture("mips", TextureDesc{4, 4, 1, 1, 4, VK_FORMAT_R8_UNORM}), GraphError);
    CHECK_THROWS_AS(g.createBuffer("zero", {0}), GraphError);
}

TEST_CASE("an import with a final state but no initial state is refused at compile, used or not") {
    // Found by the graph fuzzer: unused, it was moved to its final state
    // from an unknown one every frame, racing the previous frame's move.
    Graph g(twoQueues());
    g.importTexture("orphan", {tex(64, VK_FORMAT_R8G8B8A8_UNORM, 4), std::nullopt,
                               BoundaryState::of(Access::StorageWrite)});
    try {
        compile(g, g.caps());
        FAIL("no GraphError was thrown");
    } catch (const GraphError& e) {
        CHECK((e.kind() == ErrorKind::ImportWithoutState));
        CHECK(std::string(e.what()).find("orphan") != std::string::npos);
    }
    // A final state of None asks for nothing: compiles.
    Graph quiet(twoQueues());
    quiet.importTexture("orphan", {tex(), std::nullopt, BoundaryState::of(Access::None)});
    CHECK(compile(quiet, quiet.caps()).passes.empty());
}
