// Mips and array layers are synchronised separately.

#include <doctest/doctest.h>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

TEST_CASE("a mip chain step reads one mip and writes the next, each with its own barrier") {
    Graph g(oneQueue());
    Texture hiz = g.createTexture("hiz", tex(64, VK_FORMAT_R32_SFLOAT, 4));
    g.addPass(
        "mip0", Queue::Graphics, [&](Builder& b) { hiz = b.write(hiz, Access::StorageWrite, Subresource::mip(0)); },
        noop);
    for (uint32_t m = 1; m < 4; ++m) {
        g.addPass(
            "mip" + std::to_string(m), Queue::Graphics,
            [&](Builder& b) {
                b.read(hiz, Access::SampledRead, Subresource::mip(m - 1));
                hiz = b.write(hiz, Access::StorageWrite, Subresource::mip(m));
            },
            noop);
    }
    g.markOutput(hiz);
    Plan plan = compileChecked(g);
    const auto step = barriersOn(plan, "mip2", "hiz");
    REQUIRE(step.size() == 2);
    // mip 1: written by mip1, now sampled.
    const Barrier& read = step[0].range.baseMip == 1 ? step[0] : step[1];
    const Barrier& write = step[0].range.baseMip == 2 ? step[0] : step[1];
    CHECK(read.range == Subresource{1, 1, 0, 1});
    CHECK(read.oldLayout == VK_IMAGE_LAYOUT_GENERAL);
    CHECK(read.newLayout == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL);
    CHECK(read.srcAccess == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    // mip 2: first use this frame.
    CHECK(write.range == Subresource{2, 1, 0, 1});
    CHECK(write.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED);
    CHECK(write.newLayout == VK_IMAGE_LAYOUT_GENERAL);
}

TEST_CASE("barriers cover only the subresources a pass uses") {
    Graph g(oneQueue());
    Texture cube = g.createTexture("cube", tex(32, VK_FORMAT_R16G16B16A16_SFLOAT, 1, 6));
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "render_faces", Queue::Graphics, [&](Builder& b) { cube = b.write(cube, Access::StorageWrite); }, noop);
    g.addPass(
        "face2", Queue::Graphics,
        [&](Builder& b) {
            b.read(cube, Access::SampledRead, Subresource::layer(2));
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "face2", "cube");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].range == Subresource{0, 1, 2, 1});
}

TEST_CASE("adjacent subresources with the same needs merge into one barrier") {
    Graph g(oneQueue());
    Texture t = g.createTexture("atlas", tex(64, VK_FORMAT_R8G8B8A8_UNORM, 3, 4));
    Buffer out = g.createBuffer("out", {256});
    g.addPass(
        "fill", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::TransferDst); }, noop);
    g.addPass(
        "sample", Queue::Graphics,
        [&](Builder& b) {
            b.read(t, Access::SampledRead);
            out = b.write(out, Access::StorageWrite);
        },
        noop);
    g.markOutput(out);
    Plan plan = compileChecked(g);
    const auto fill = barriersOn(plan, "fill", "atlas");
    REQUIRE(fill.size() == 1);
    CHECK(fill[0].range == Subresource{0, 3, 0, 4});
    const auto sample = barriersOn(plan, "sample", "atlas");
    REQUIRE(sample.size() == 1);
    CHECK(sample[0].range == Subresource{0, 3, 0, 4});
}

TEST_CASE("array layers in different states get separate barriers") {
    Graph g(oneQueue());
    Texture shadows = g.createTexture("cascades", tex(64, VK_FORMAT_D32_SFLOAT, 1, 4));
    Texture lit = g.createTexture("lit", tex());
    for (uint32_t c = 0; c < 4; ++c)
        g.addPass(
            "cascade" + std::to_string(c), Queue::Graphics,
            [&](Builder& b) {
                b.setPipeline(Pipeline::Raster);
                shadows = b.write(shadows, Access::DepthWrite, Subresource::layer(c));
            },
            noop);
    g.addPass(
        "light", Queue::Graphics,
        [&](Builder& b) {
            b.read(shadows, Access::SampledRead, {0, 1, 0, 2}); // near cascades
            lit = b.write(lit, Access::StorageWrite);
        },
        noop);
    g.markOutput(lit);
    Plan plan = compileChecked(g);
    const auto bs = barriersOn(plan, "light", "cascades");
    REQUIRE(bs.size() == 1);
    CHECK(bs[0].range == Subresource{0, 1, 0, 2});
    CHECK(bs[0].aspect == VK_IMAGE_ASPECT_DEPTH_BIT);
    CHECK(bs[0].srcStages ==
          (VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT));
}
