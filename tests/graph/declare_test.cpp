// Declaring a frame: versions, setup, rollback, plans sharing declarations.

#include <doctest/doctest.h>

#include <stdexcept>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

TEST_CASE("a write returns the next version of the handle") {
    Graph g(twoQueues());
    Texture t = g.createTexture("t", tex());
    CHECK(t.version == 0);
    Texture v1, v2;
    g.addPass(
        "a", Queue::Graphics, [&](Builder& b) { v1 = b.write(t, Access::StorageWrite); }, noop);
    g.addPass(
        "b", Queue::Graphics, [&](Builder& b) { v2 = b.write(v1, Access::StorageReadWrite); }, noop);
    CHECK(v1.version == 1);
    CHECK(v2.version == 2);
    CHECK(v2.index == t.index);
    CHECK(v2.graph == g.id());
}

TEST_CASE("setup runs inside addPass, before it returns") {
    Graph g(twoQueues());
    bool ran = false;
    const PassId id = g.addPass(
        "p", Queue::Graphics, [&](Builder&) { ran = true; }, noop);
    CHECK(ran);
    CHECK(id.valid());
    CHECK(id.graph == g.id());
}

TEST_CASE("a failed setup leaves the graph as it was") {
    Graph g(twoQueues());
    Texture t = g.createTexture("t", tex());
    Texture written;
    g.addPass(
        "writer", Queue::Graphics, [&](Builder& b) { written = b.write(t, Access::StorageWrite); }, noop);
    const size_t resources = g.declaration().resources.size();
    const size_t uses = g.declaration().uses.size();
    CHECK_THROWS_AS(g.addPass(
                        "broken", Queue::Graphics,
                        [&](Builder& b) {
                            b.createTexture("scratch", tex());
                            b.read(written, Access::SampledRead);
                            throw std::runtime_error("setup failed");
                        },
                        noop),
                    std::runtime_error);
    CHECK(g.declaration().passes.size() == 1);
    CHECK(g.declaration().resources.size() == resources);
    CHECK(g.declaration().uses.size() == uses);
    // The graph goes on: the handle is still current.
    Texture out;
    g.addPass(
        "next", Queue::Graphics, [&](Builder& b) { out = b.write(written, Access::StorageReadWrite); }, noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    CHECK(plan.passes.size() == 2);
}

TEST_CASE("two read kinds of one subresource that share a layout merge into one use") {
    Graph g(twoQueues());
    Texture depth = g.createTexture("depth", tex(64, VK_FORMAT_D32_SFLOAT));
    Texture color = g.createTexture("color", tex());
    g.addPass(
        "prepass", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            depth = b.write(depth, Access::DepthWrite);
        },
        noop);
    g.addPass(
        "particles", Queue::Graphics,
        [&](Builder& b) {
            b.setPipeline(Pipeline::Raster);
            b.read(depth, Access::DepthRead);   // depth test
            b.read(depth, Access::SampledRead); // soft particles sample it too
            color = b.write(color, Access::ColorAttachment);
        },
        noop);
    g.markOutput(color);
    Plan plan = compileChecked(g);
    const auto uses = plan.uses(passNamed(plan, "particles"));
    REQUIRE(uses.size() == 2);
    CHECK((uses[0].kinds == (accessBit(Access::DepthRead) | accessBit(Access::SampledRead))));
    const auto barriers = barriersOn(plan, "particles", "depth");
    REQUIRE(barriers.size() == 1);
    CHECK(barriers[0].newLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK((barriers[0].dstStages & VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT) != 0);
    CHECK((barriers[0].dstStages & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT) != 0);
    CHECK(barriers[0].aspect == VK_IMAGE_ASPECT_DEPTH_BIT);
}

TEST_CASE("a plan keeps the declaration it was compiled from when the graph changes") {
    Graph g(twoQueues());
    Texture t = g.createTexture("t", tex());
    g.addPass(
        "a", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, noop);
    g.markOutput(t);
    Plan plan = compileChecked(g);
    g.addPass(
        "b", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageReadWrite); }, noop);
    CHECK(plan.declaration->passes.size() == 1);
    CHECK(g.declaration().passes.size() == 2);
    CHECK(plan.passName(plan.passes[0]) == "a");
}

namespace {
void recordA(PassContext&) {}
void recordB(PassContext&) {}
} // namespace

TEST_CASE("a plan hands the executor each pass's callback, barriers and timestamps") {
    Graph g(twoQueues());
    Texture t = g.createTexture("t", tex());
    g.addPass(
        "a", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); }, recordA);
    g.addPass(
        "b", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageReadWrite); }, recordB);
    g.markOutput(t);
    Plan plan = compileChecked(g);
    REQUIRE(plan.passes.size() == 2);
    using Fn = void (*)(PassContext&);
    REQUIRE(plan.execute(passNamed(plan, "a")).target<Fn>() != nullptr);
    CHECK((*plan.execute(passNamed(plan, "a")).target<Fn>() == &recordA));
    CHECK((*plan.execute(passNamed(plan, "b")).target<Fn>() == &recordB));
    CHECK(plan.passes[0].timestampQuery == 0);
    CHECK(plan.passes[1].timestampQuery == 2);
    CHECK(plan.timestampQueryCount() == 4);
    CHECK(plan.barriersBefore(plan.passes[0]).size() == 1); // last frame's write of the same memory
    CHECK(plan.barriersBefore(plan.passes[1]).size() == 1);
}

TEST_CASE("recompiling into last frame's plan gives the same plan") {
    Graph g(twoQueues());
    synthetic::declare(g, synthetic::reflectionFrame({}));
    Plan fresh = g.compile();
    Plan recycled = g.compile({}, std::move(fresh));
    Plan again = g.compile();
    CHECK(recycled.toJson() == again.toJson());
}
