#include "glint/gpu/shader_reflection.h"

#include "glint/gpu/error.h"

#include <spirv_cross_c.h>

#include <algorithm>
#include <memory>

namespace glint::gpu {

namespace {

struct ContextDeleter {
    void operator()(spvc_context context) const { spvc_context_destroy(context); }
};
using ContextPtr = std::unique_ptr<std::remove_pointer_t<spvc_context>, ContextDeleter>;

std::string typeName(VkDescriptorType type) {
    switch (type) {
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER: return "uniform buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER: return "storage buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE: return "storage image";
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER: return "sampled image";
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR: return "acceleration structure";
    default: return "descriptor type " + std::to_string(int(type));
    }
}

} // namespace

ShaderInterface reflectShader(std::span<const uint32_t> spirv, VkShaderStageFlags stage, const std::string& shader) {
    spvc_context raw = nullptr;
    if (spvc_context_create(&raw) != SPVC_SUCCESS) {
        throw GpuError("shader '" + shader + "': SPIRV-Cross failed to start");
    }
    const ContextPtr context(raw);
    const auto fail = [&](const std::string& what) {
        throw GpuError("shader '" + shader + "': " + what + ": " + spvc_context_get_last_error_string(raw));
    };
    spvc_parsed_ir ir = nullptr;
    if (spvc_context_parse_spirv(raw, spirv.data(), spirv.size(), &ir) != SPVC_SUCCESS) fail("cannot parse the SPIR-V");
    spvc_compiler compiler = nullptr;
    if (spvc_context_create_compiler(raw, SPVC_BACKEND_NONE, ir, SPVC_CAPTURE_MODE_TAKE_OWNERSHIP, &compiler) !=
        SPVC_SUCCESS) {
        fail("cannot reflect the SPIR-V");
    }
    spvc_resources resources = nullptr;
    if (spvc_compiler_create_shader_resources(compiler, &resources) != SPVC_SUCCESS) fail("cannot list its resources");

    ShaderInterface out;
    const auto list = [&](spvc_resource_type kind) {
        const spvc_reflected_resource* items = nullptr;
        size_t count = 0;
        if (spvc_resources_get_resource_list_for_type(resources, kind, &items, &count) != SPVC_SUCCESS) {
            fail("cannot list its resources");
        }
        return std::span<const spvc_reflected_resource>(items, count);
    };
    const struct {
        spvc_resource_type kind;
        VkDescriptorType type;
    } kinds[] = {
        {SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
        {SPVC_RESOURCE_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
        {SPVC_RESOURCE_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE},
        {SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
        {SPVC_RESOURCE_TYPE_ACCELERATION_STRUCTURE, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR},
    };
    for (const auto& [kind, type] : kinds) {
        for (const spvc_reflected_resource& r : list(kind)) {
            ReflectedBinding b;
            b.type = type;
            b.stages = stage;
            b.name = r.name != nullptr ? r.name : "";
            b.binding = spvc_compiler_get_decoration(compiler, r.id, SpvDecorationBinding);
            const uint32_t set = spvc_compiler_get_decoration(compiler, r.id, SpvDecorationDescriptorSet);
            if (set != 0) {
                throw GpuError("shader '" + shader + "': '" + b.name + "' is in descriptor set " + std::to_string(set) +
                               "; Glint pushes set 0 only");
            }
            const spvc_type t = spvc_compiler_get_type_handle(compiler, r.type_id);
            for (unsigned d = 0; d < spvc_type_get_num_array_dimensions(t); ++d) {
                // A runtime-sized array's dimension is 0.
                b.count *= spvc_type_array_dimension_is_literal(t, d) ? spvc_type_get_array_dimension(t, d) : 0;
            }
            out.bindings.push_back(std::move(b));
        }
    }
    for (const spvc_resource_type unsupported :
         {SPVC_RESOURCE_TYPE_SEPARATE_IMAGE, SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, SPVC_RESOURCE_TYPE_SUBPASS_INPUT,
          SPVC_RESOURCE_TYPE_ATOMIC_COUNTER}) {
        if (const auto items = list(unsupported); !items.empty()) {
            throw GpuError("shader '" + shader + "': '" + (items[0].name ? items[0].name : "") +
                           "' is a separate image, sampler, subpass input or atomic counter, which Glint does not "
                           "bind");
        }
    }
    for (const spvc_reflected_resource& r : list(SPVC_RESOURCE_TYPE_PUSH_CONSTANT)) {
        size_t size = 0;
        if (spvc_compiler_get_declared_struct_size(compiler, spvc_compiler_get_type_handle(compiler, r.base_type_id),
                                                   &size) != SPVC_SUCCESS) {
            fail("cannot size its push constants");
        }
        out.pushConstantBytes = std::max(out.pushConstantBytes, uint32_t(size));
    }
    std::sort(out.bindings.begin(), out.bindings.end(),
              [](const ReflectedBinding& a, const ReflectedBinding& b) { return a.binding < b.binding; });
    for (size_t i = 1; i < out.bindings.size(); ++i) {
        if (out.bindings[i].binding == out.bindings[i - 1].binding) {
            throw GpuError("shader '" + shader + "': binding " + std::to_string(out.bindings[i].binding) +
                           " is declared twice ('" + out.bindings[i - 1].name + "', '" + out.bindings[i].name + "')");
        }
    }
    return out;
}

ShaderInterface mergeInterfaces(std::span<const ShaderInterface> stages, const std::string& pipeline) {
    ShaderInterface out;
    for (const ShaderInterface& s : stages) {
        out.pushConstantBytes = std::max(out.pushConstantBytes, s.pushConstantBytes);
        for (const ReflectedBinding& b : s.bindings) {
            const auto it = std::find_if(out.bindings.begin(), out.bindings.end(),
                                         [&](const ReflectedBinding& o) { return o.binding == b.binding; });
            if (it == out.bindings.end()) {
                out.bindings.push_back(b);
                continue;
            }
            if (it->type != b.type || it->count != b.count) {
                throw GpuError("pipeline '" + pipeline + "': binding " + std::to_string(b.binding) + " is a " +
                               typeName(it->type) + " '" + it->name + "' in one stage and a " + typeName(b.type) +
                               " '" + b.name + "' in another (or of another array size)");
            }
            it->stages |= b.stages;
        }
    }
    std::sort(out.bindings.begin(), out.bindings.end(),
              [](const ReflectedBinding& a, const ReflectedBinding& b) { return a.binding < b.binding; });
    return out;
}

} // namespace glint::gpu
