// Bindings stated once, in GLSL: pipeline layouts and push-constant sizes
// read from the SPIR-V, bindings pushed by their GLSL names, and a binding
// table that disagrees with the shader refused with the pipeline and the
// binding named.
#include "support/gpu_test.h"

#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/shader_reflection.h"

#include <algorithm>
#include <string>

using namespace glint;

namespace {

const gpu::ReflectedBinding& find(const gpu::ShaderInterface& s, uint32_t binding) {
    const auto it = std::find_if(s.bindings.begin(), s.bindings.end(),
                                 [&](const gpu::ReflectedBinding& b) { return b.binding == binding; });
    REQUIRE(it != s.bindings.end());
    return *it;
}

} // namespace

TEST_CASE("a shader's bindings, names and push-constant size come from its SPIR-V") {
    const gpu::ShaderInterface spatial =
        gpu::reflectShader(gpu::loadSpirv("temporal/spatial.comp"), VK_SHADER_STAGE_COMPUTE_BIT, "spatial");
    REQUIRE(spatial.bindings.size() == 6);
    CHECK(find(spatial, 0).type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER);
    CHECK(find(spatial, 0).name == "Frame");  // a block: its block name
    CHECK(find(spatial, 1).type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
    CHECK(find(spatial, 1).name == "depthTexture");
    CHECK(find(spatial, 4).type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
    CHECK(find(spatial, 4).name == "resolvedImage");
    CHECK(find(spatial, 4).stages == VK_SHADER_STAGE_COMPUTE_BIT);
    CHECK(spatial.pushConstantBytes == 0);

    const gpu::ShaderInterface clear =
        gpu::reflectShader(gpu::loadSpirv("common/clear_image.comp"), VK_SHADER_STAGE_COMPUTE_BIT, "clear");
    REQUIRE(clear.bindings.size() == 1);
    CHECK(clear.bindings[0].name == "target");
    CHECK(clear.pushConstantBytes == 24);  // vec4 value, uvec2 size

    CHECK_THROWS_WITH_AS(gpu::reflectShader(std::vector<uint32_t>{1, 2, 3}, VK_SHADER_STAGE_COMPUTE_BIT, "junk"),
                         doctest::Contains("shader 'junk'"), gpu::GpuError);
}

TEST_CASE("stages of one pipeline must agree on a binding's kind") {
    gpu::ShaderInterface a, b;
    a.bindings.push_back({0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, "Particles"});
    b.bindings.push_back({0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, "Particles"});
    const gpu::ShaderInterface both[] = {a, b};
    const gpu::ShaderInterface merged = gpu::mergeInterfaces(both, "p");
    REQUIRE(merged.bindings.size() == 1);
    CHECK(merged.bindings[0].stages == (VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT));
    b.bindings[0].type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    const gpu::ShaderInterface clash[] = {a, b};
    CHECK_THROWS_WITH_AS(gpu::mergeInterfaces(clash, "p"), doctest::Contains("binding 0"), gpu::GpuError);
}

TEST_CASE("a pipeline takes its layout from the shader, checks a stated table, and pushes by name") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const gpu::Pipeline reflected = gpu::createComputePipeline(ctx, {"temporal/spatial.comp", {}, 0, "spatial"});
    REQUIRE(reflected.layout().bindings().size() == 6);
    CHECK(reflected.layout().binding("accumulatedTexture").binding == 3);
    CHECK_THROWS_WITH_AS(reflected.layout().binding("noSuchTexture"),
                         doctest::Contains("pipeline 'spatial' has no binding named 'noSuchTexture'"), gpu::GpuError);
    gpu::PushDescriptors push(reflected);
    CHECK_THROWS_WITH_AS(push.storageImage("depthTexture", VK_NULL_HANDLE), doctest::Contains("binding 1"),
                         gpu::GpuError);

    // A stated binding of the wrong kind names the pipeline and the binding.
    CHECK_THROWS_WITH_AS(
        gpu::createComputePipeline(
            ctx, {"temporal/spatial.comp", {{1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_SHADER_STAGE_COMPUTE_BIT}}, 0,
                  "spatial"}),
        doctest::Contains("pipeline 'spatial': binding 1 'depthTexture'"), gpu::GpuError);
    // Push constants smaller than the shader's block are refused.
    CHECK_THROWS_WITH_AS(gpu::createComputePipeline(ctx, {"common/clear_image.comp", {}, 8, "clear"}),
                         doctest::Contains("24"), gpu::GpuError);
}
