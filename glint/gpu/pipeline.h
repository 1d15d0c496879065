#pragma once
// Shader modules loaded from the build's SPIR-V, and compute, graphics and
// ray tracing pipelines whose one descriptor set is a push-descriptor set
// (bindings are pushed at record time; no descriptor pools to manage).

#include "glint/gpu/handle.h"
#include "glint/gpu/resources.h"
#include "glint/gpu/shader_reflection.h"

#include <vulkan/vulkan.h>

#include <filesystem>
#include <string>
#include <vector>

namespace glint::gpu {

class Context;

// Where compiled shaders live: $GLINT_SHADER_DIR if set (the only place
// then), else the first that exists of: share/glint/shaders beside the
// installed library (<prefix>/lib/.. ; with static libraries, beside the
// executable's folder), a "shaders" folder next to the executable or one
// level up (build/bin -> build/shaders), the install prefix configured at
// build time, the build tree this library was compiled in.
std::filesystem::path shaderDirectory();
// Reads "<shaderDirectory()>/<name>.spv", e.g. name = "smoke/trace_query.comp";
// an absolute path (an engine's own SPIR-V, "/.../blur.comp.spv") as it is.
// Throws GpuError naming the file and the folders searched.
std::vector<uint32_t> loadSpirv(const std::string& name);

// One stage's SPIR-V, loaded and reflected (gpu/shader_reflection.h).
class ShaderModule {
public:
    ShaderModule(Context& ctx, const std::string& name, VkShaderStageFlags stage);
    VkShaderModule handle() const { return module_.get(); }
    const std::string& name() const { return name_; }
    const ShaderInterface& interface() const { return interface_; }

private:
    std::string name_;
    ShaderInterface interface_;
    Unique<VkShaderModule> module_;
};

// A descriptor binding of a pipeline layout. Pipelines take their bindings
// from the shaders' SPIR-V; a pipeline description lists only what SPIR-V
// cannot say (the count of a runtime-sized array) or what it wants checked.
struct Binding {
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    VkShaderStageFlags stages = VK_SHADER_STAGE_ALL;
    uint32_t count = 1;
    std::string name;  // the GLSL name (reflected)
};

// A push-descriptor set layout plus push-constant range.
class PipelineLayout {
public:
    PipelineLayout() = default;
    PipelineLayout(Context& ctx, std::vector<Binding> bindings, uint32_t pushConstantBytes, std::string_view name);
    VkPipelineLayout handle() const { return layout_.get(); }
    const std::vector<Binding>& bindings() const { return bindings_; }
    // The binding whose GLSL name is `name`; throws GpuError naming the
    // pipeline layout's bindings otherwise.
    const Binding& binding(std::string_view name) const;
    uint32_t pushConstantBytes() const { return pushConstantBytes_; }

private:
    std::string name_;
    std::vector<Binding> bindings_;
    uint32_t pushConstantBytes_ = 0;
    Unique<VkDescriptorSetLayout> setLayout_;
    Unique<VkPipelineLayout> layout_;
};

// In every pipeline description: `bindings` and `pushConstantBytes` may
// stay empty and 0, and the layout is the shaders' (reflected from SPIR-V).
// A binding listed that a shader has must have its type there (the listed
// count sizes a runtime-sized array); one no shader has is added as listed
// (for pipelines sharing one layout). A push-constant size given must
// cover the shaders' block (a C++ struct may carry trailing padding).
struct ComputePipelineDesc {
    std::string shader;  // e.g. "smoke/trace_query.comp"
    std::vector<Binding> bindings;
    uint32_t pushConstantBytes = 0;
    std::string name;
};

struct GraphicsPipelineDesc {
    std::string vertexShader;
    std::string fragmentShader;
    std::vector<Binding> bindings;
    uint32_t pushConstantBytes = 0;
    std::vector<VkVertexInputBindingDescription> vertexBindings;
    std::vector<VkVertexInputAttributeDescription> vertexAttributes;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkCullModeFlags cullMode = VK_CULL_MODE_BACK_BIT;
    VkFrontFace frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    // Cull mode and front face set per draw (vkCmdSetCullMode,
    // vkCmdSetFrontFace; Vulkan 1.3) instead of the two fields above.
    bool dynamicCulling = false;
    std::vector<VkFormat> colorFormats;
    VkFormat depthFormat = VK_FORMAT_UNDEFINED;
    bool depthTest = true;
    bool depthWrite = true;
    // Reversed Z is Glint's convention (near = 1, far = 0).
    VkCompareOp depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    // One per colour attachment (blending, write mask); empty: no blending,
    // every channel written.
    std::vector<VkPipelineColorBlendAttachmentState> colorBlends;
    std::string name;
};

struct HitGroup {
    std::string closestHit;  // empty: none
    std::string anyHit;      // empty: none
};

struct RayTracingPipelineDesc {
    std::string raygen;
    std::vector<std::string> misses;
    std::vector<HitGroup> hitGroups;
    std::vector<Binding> bindings;
    uint32_t pushConstantBytes = 0;
    uint32_t maxRecursionDepth = 1;
    std::string name;
};

class Pipeline {
public:
    Pipeline() = default;
    Pipeline(Pipeline&&) noexcept = default;
    Pipeline& operator=(Pipeline&&) noexcept = default;

    VkPipeline handle() const { return pipeline_.get(); }
    VkPipelineBindPoint bindPoint() const { return bindPoint_; }
    const PipelineLayout& layout() const { return layout_; }
    const std::string& name() const { return name_; }
    uint32_t groupCount() const { return groupCount_; }

    void bind(VkCommandBuffer cmd) const { vkCmdBindPipeline(cmd, bindPoint_, pipeline_.get()); }
    void pushConstants(VkCommandBuffer cmd, const void* data, uint32_t size) const;
    template <typename T> void pushConstants(VkCommandBuffer cmd, const T& value) const {
        pushConstants(cmd, &value, sizeof(T));
    }

private:
    friend Pipeline createComputePipeline(Context&, const ComputePipelineDesc&);
    friend Pipeline createGraphicsPipeline(Context&, const GraphicsPipelineDesc&);
    friend Pipeline createRayTracingPipeline(Context&, const RayTracingPipelineDesc&);
    std::string name_;
    VkPipelineBindPoint bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
    PipelineLayout layout_;
    Unique<VkPipeline> pipeline_;
    uint32_t groupCount_ = 0;
};

Pipeline createComputePipeline(Context& ctx, const ComputePipelineDesc& desc);
Pipeline createGraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& desc);
// Group order: raygen, then misses, then hit groups.
Pipeline createRayTracingPipeline(Context& ctx, const RayTracingPipelineDesc& desc);

// The shader binding table of a ray tracing pipeline: one raygen record,
// the miss records, the hit-group records, each region aligned as the
// device asks.
class ShaderBindingTable {
public:
    ShaderBindingTable() = default;
    ShaderBindingTable(Context& ctx, const Pipeline& pipeline, uint32_t missCount, uint32_t hitGroupCount);

    const VkStridedDeviceAddressRegionKHR& raygen() const { return raygen_; }
    const VkStridedDeviceAddressRegionKHR& miss() const { return miss_; }
    const VkStridedDeviceAddressRegionKHR& hit() const { return hit_; }
    const VkStridedDeviceAddressRegionKHR& callable() const { return callable_; }

    void traceRays(const Context& ctx, VkCommandBuffer cmd, uint32_t width, uint32_t height, uint32_t depth = 1) const;

private:
    Buffer buffer_;
    VkStridedDeviceAddressRegionKHR raygen_{}, miss_{}, hit_{}, callable_{};
};

} // namespace glint::gpu
