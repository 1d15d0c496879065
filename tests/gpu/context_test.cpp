// Device selection, capabilities and the errors a user meets first.
#include "support/gpu_test.h"

#include "glint/gpu/commands.h"
#include "glint/gpu/descriptors.h"
#include "glint/gpu/error.h"
#include "glint/gpu/pipeline.h"

#include <cstdlib>
#include <string>

using namespace glint;

TEST_CASE("an unknown device name is an error that lists the devices there are") {
    gpu::ContextOptions o;
    o.deviceFilter = "no-such-gpu-anywhere";
    try {
        gpu::Context ctx(o);
        FAIL("expected an error");
    } catch (const gpu::GpuError& e) {
        const std::string what = e.what();
        CHECK(what.find("no-such-gpu-anywhere") != std::string::npos);
        CHECK(what.find("matches no Vulkan device") != std::string::npos);
        CHECK(what.find("devices:") != std::string::npos);
    }
}

TEST_CASE("capabilities describe a graphics queue and at least one ray backend") {
    test::GpuTest gpu;
    const auto& caps = gpu.ctx().caps();
    CHECK_FALSE(caps.deviceName.empty());
    REQUIRE(caps.graphicsFamily < caps.queueFamilies.size());
    const auto& family = caps.queueFamilies[caps.graphicsFamily];
    CHECK((family.flags & VK_QUEUE_GRAPHICS_BIT) != 0);
    CHECK((family.flags & VK_QUEUE_COMPUTE_BIT) != 0);
    if (caps.computeFamily) {
        CHECK(*caps.computeFamily != caps.graphicsFamily);
        CHECK((caps.queueFamilies[*caps.computeFamily].flags & VK_QUEUE_GRAPHICS_BIT) == 0);
        CHECK(gpu.ctx().computeQueue().family == *caps.computeFamily);
    } else {
        CHECK(gpu.ctx().computeQueue().queue == gpu.ctx().graphicsQueue().queue);
    }
    CHECK(caps.accelerationStructure);
    CHECK((caps.rayQuery || caps.rayTracingPipeline));
    CHECK(caps.maxPushDescriptors >= 8);
}

TEST_CASE("GLINT_DEVICE picks the device when no filter is given") {
    std::string name;
    {
        gpu::Context probe(gpu::ContextOptions{});
        name = probe.caps().deviceName;
    }
    setenv("GLINT_DEVICE", name.substr(0, 4).c_str(), 1);
    gpu::Context ctx(gpu::ContextOptions{});
    CHECK(ctx.caps().deviceName == name);
    setenv("GLINT_DEVICE", "definitely-not-a-device", 1);
    CHECK_THROWS_WITH_AS(gpu::Context(gpu::ContextOptions{}), doctest::Contains("GLINT_DEVICE"), gpu::GpuError);
    unsetenv("GLINT_DEVICE");
}

TEST_CASE("disabling ray query leaves the ray tracing pipeline as the only backend") {
    gpu::ContextOptions o;
    o.disableRayQuery = true;
    test::GpuTest gpu(o);
    CHECK_FALSE(gpu.ctx().caps().rayQuery);
}

TEST_CASE("a missing SPIR-V file is an error naming the file and where it was looked for") {
    test::GpuTest gpu;
    try {
        gpu::createComputePipeline(gpu.ctx(), {"no/such_shader.comp", {}, 0, "missing"});
        FAIL("expected an error");
    } catch (const gpu::GpuError& e) {
        const std::string what = e.what();
        CHECK(what.find("no/such_shader.comp.spv") != std::string::npos);
        CHECK(what.find("not found") != std::string::npos);
    }
}

TEST_CASE("pushing descriptors with a binding left out names the pipeline and the binding") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto pipeline = gpu::createComputePipeline(
        ctx, {"test/fill_buffer.comp", {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_SHADER_STAGE_COMPUTE_BIT}}, 8,
              "test.fill"});
    gpu::Buffer buffer(ctx, {64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUsage::DeviceLocal, "b"});
    gpu::CommandPool pool(ctx, ctx.graphicsQueue().family, "t");
    VkCommandBuffer cmd = pool.allocate();
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cmd, &begin);
    CHECK_THROWS_WITH_AS(gpu::PushDescriptors(pipeline).push(ctx, cmd),
                         doctest::Contains("'test.fill': binding 0 was not written"), gpu::GpuError);
    CHECK_THROWS_WITH_AS(gpu::PushDescriptors(pipeline).storageBuffer(3, buffer),
                         doctest::Contains("has no binding 3"), gpu::GpuError);
    CHECK_THROWS_WITH_AS(gpu::PushDescriptors(pipeline).storageImage(0, VK_NULL_HANDLE),
                         doctest::Contains("binding 0 written with descriptor type"), gpu::GpuError);
    CHECK_THROWS_WITH_AS(pipeline.pushConstants(cmd, uint32_t(1)), doctest::Contains("4 bytes of push constants"),
                         gpu::GpuError);
    vkEndCommandBuffer(cmd);
}
