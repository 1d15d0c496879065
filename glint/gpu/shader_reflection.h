#pragma once
// What a shader declares, read from its SPIR-V (SPIRV-Cross's C API), so a
// pass states its bindings once, in GLSL: pipelines take their descriptor
// set layout and push-constant size from here, and PushDescriptors binds by
// the GLSL name.
//
// Names: a buffer block by its block name ("Rays" in
// `buffer Rays { PackedRay rays[]; };`), anything else by its variable name
// ("depthTexture").

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace glint::gpu {

struct ReflectedBinding {
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    // Array elements; 0 for a runtime-sized array (the pipeline description
    // must state its count).
    uint32_t count = 1;
    VkShaderStageFlags stages = 0;
    std::string name;
};

struct ShaderInterface {
    std::vector<ReflectedBinding> bindings;  // sorted by binding
    uint32_t pushConstantBytes = 0;
};

// The descriptor bindings (set 0 only; another set is an error) and the
// push-constant block size of one stage. Throws GpuError naming `shader`
// on SPIR-V it cannot read or a resource kind Glint does not bind.
ShaderInterface reflectShader(std::span<const uint32_t> spirv, VkShaderStageFlags stage, const std::string& shader);

// The interface of several stages of one pipeline: bindings merged by
// number (stage flags OR-ed), each the same kind and count in every stage
// that declares it; the largest push-constant block. Throws GpuError naming
// the pipeline and the binding otherwise.
ShaderInterface mergeInterfaces(std::span<const ShaderInterface> stages, const std::string& pipeline);

} // namespace glint::gpu
