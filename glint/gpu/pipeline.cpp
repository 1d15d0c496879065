#include "glint/gpu/pipeline.h"

#include "glint/gpu/context.h"
#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <dlfcn.h>
#include <fstream>
#include <unistd.h>

#ifndef GLINT_BUILD_SHADER_DIR
#define GLINT_BUILD_SHADER_DIR ""
#endif
#ifndef GLINT_INSTALL_SHADER_SUBDIR
#define GLINT_INSTALL_SHADER_SUBDIR "share/glint/shaders"
#endif
#ifndef GLINT_INSTALL_PREFIX
#define GLINT_INSTALL_PREFIX ""
#endif

namespace glint::gpu {

namespace {

// The flag that has the driver keep a pipeline's statistics, where the
// context enabled them (ContextOptions::pipelineStatistics).
VkPipelineCreateFlags statisticsFlags(const Context& ctx) {
    return ctx.caps().pipelineStatistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0;
}

// One info line per executable (a shader stage, or what the driver made of
// it) with every statistic the driver reports for it: on NVIDIA the
// register count among them, which bounds how many warps an SM holds.
void logStatistics(const Context& ctx, VkPipeline pipeline, const std::string& name) {
    if (!ctx.caps().pipelineStatistics) return;
    const DeviceFunctions& fn = ctx.fn();
    VkPipelineInfoKHR info{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
    info.pipeline = pipeline;
    uint32_t count = 0;
    if (fn.getPipelineExecutableProperties(ctx.device(), &info, &count, nullptr) != VK_SUCCESS) return;
    std::vector<VkPipelineExecutablePropertiesKHR> executables(
        count, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR});
    if (fn.getPipelineExecutableProperties(ctx.device(), &info, &count, executables.data()) != VK_SUCCESS) return;
    for (uint32_t e = 0; e < count; ++e) {
        VkPipelineExecutableInfoKHR which{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
        which.pipeline = pipeline;
        which.executableIndex = e;
        uint32_t statCount = 0;
        if (fn.getPipelineExecutableStatistics(ctx.device(), &which, &statCount, nullptr) != VK_SUCCESS) continue;
        std::vector<VkPipelineExecutableStatisticKHR> stats(statCount,
                                                            {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
        if (fn.getPipelineExecutableStatistics(ctx.device(), &which, &statCount, stats.data()) != VK_SUCCESS) continue;
        std::string text;
        for (const VkPipelineExecutableStatisticKHR& s : stats) {
            text += text.empty() ? "" : ", ";
            text += s.name;
            text += " ";
            switch (s.format) {
                case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
                    text += s.value.b32 ? "yes" : "no";
                    break;
                case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
                    text += std::to_string(s.value.i64);
                    break;
                case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
                    text += std::to_string(s.value.u64);
                    break;
                case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR:
                    text += std::to_string(s.value.f64);
                    break;
                default:
                    text += "?";
            }
        }
        spdlog::info("pipeline '{}' {} (subgroup {}): {}", name, executables[e].name, executables[e].subgroupSize,
                     text);
    }
}

std::vector<std::filesystem::path> shaderSearchPath() {
    std::vector<std::filesystem::path> dirs;
    if (const char* env = std::getenv("GLINT_SHADER_DIR"); env && *env) {
        dirs.emplace_back(env);
        return dirs;  // an explicit choice is the only place looked at
    }
    // The installed layout, <prefix>/lib/libglint_gpu.so beside
    // <prefix>/share/glint/shaders: found from the file this code was loaded
    // from (the shared library, or the executable it is linked into).
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&shaderSearchPath), &info) != 0 && info.dli_fname != nullptr) {
        std::error_code ec;
        const auto module = std::filesystem::weakly_canonical(info.dli_fname, ec);
        if (!ec) {
            dirs.push_back(module.parent_path().parent_path() / GLINT_INSTALL_SHADER_SUBDIR);
        }
    }
    // A build tree: build/bin/<executable> beside build/shaders.
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        dirs.push_back(exe.parent_path() / "shaders");
        dirs.push_back(exe.parent_path().parent_path() / "shaders");
        dirs.push_back(exe.parent_path().parent_path() / GLINT_INSTALL_SHADER_SUBDIR);
    }
    // The prefix this library was configured to install into, then the
    // build tree it was built in.
    if (*GLINT_INSTALL_PREFIX) {
        dirs.push_back(std::filesystem::path(GLINT_INSTALL_PREFIX) / GLINT_INSTALL_SHADER_SUBDIR);
    }
    if (*GLINT_BUILD_SHADER_DIR) {
        dirs.emplace_back(GLINT_BUILD_SHADER_DIR);
    }
    return dirs;
}

uint32_t alignUp(uint32_t v, uint32_t a) { return (v + a - 1) / a * a; }

std::string bindingText(const Binding& b) {
    return "binding " + std::to_string(b.binding) + (b.name.empty() ? "" : " '" + b.name + "'");
}

// The layout of a pipeline of `modules`: their reflected bindings, checked
// against and completed by the description's (see ComputePipelineDesc).
PipelineLayout layoutFor(Context& ctx, const std::vector<Binding>& declared, uint32_t pushConstantBytes,
                         const std::vector<const ShaderModule*>& modules, const std::string& pipeline) {
    std::vector<ShaderInterface> stages;
    for (const ShaderModule* m : modules) stages.push_back(m->interface());
    const ShaderInterface merged = mergeInterfaces(stages, pipeline);
    std::vector<Binding> out;
    for (const ReflectedBinding& r : merged.bindings) {
        Binding b{r.binding, r.type, r.stages, r.count, r.name};
        const auto d = std::find_if(declared.begin(), declared.end(),
                                    [&](const Binding& x) { return x.binding == r.binding; });
        if (d != declared.end()) {
            if (d->type != r.type) {
                throw GpuError("pipeline '" + pipeline + "': " + bindingText(b) + " is descriptor type " +
                               std::to_string(int(r.type)) + " in the shader, declared as type " +
                               std::to_string(int(d->type)));
            }
            if (r.count != 0 && d->count != r.count) {
                throw GpuError("pipeline '" + pipeline + "': " + bindingText(b) + " has " + std::to_string(r.count) +
                               " elements in the shader, declared with " + std::to_string(d->count));
            }
            b.count = d->count;
        }
        if (b.count == 0) {
            throw GpuError("pipeline '" + pipeline + "': " + bindingText(b) +
                           " is a runtime-sized array: state its count in the pipeline description");
        }
        out.push_back(std::move(b));
    }
    // A binding listed that no stage has stays in the layout as listed:
    // pipelines that share one layout and one push code (the G-buffer's
    // sky and surface pipelines) push it whether or not they read it.
    for (const Binding& d : declared) {
        if (std::none_of(out.begin(), out.end(), [&](const Binding& b) { return b.binding == d.binding; })) {
            out.push_back(d);
        }
    }
    std::sort(out.begin(), out.end(), [](const Binding& a, const Binding& b) { return a.binding < b.binding; });
    if (pushConstantBytes == 0) {
        pushConstantBytes = alignUp(merged.pushConstantBytes, 4);
    } else if (pushConstantBytes < merged.pushConstantBytes) {
        throw GpuError("pipeline '" + pipeline + "': " + std::to_string(pushConstantBytes) +
                       " bytes of push constants declared, the shaders' block has " +
                       std::to_string(merged.pushConstantBytes));
    }
    return PipelineLayout(ctx, std::move(out), pushConstantBytes, pipeline);
}

} // namespace

std::filesystem::path shaderDirectory() {
    for (const auto& dir : shaderSearchPath()) {
        if (std::filesystem::is_directory(dir)) {
            return dir;
        }
    }
    return {};
}

std::vector<uint32_t> loadSpirv(const std::string& name) {
    std::string searched;
    // An absolute path: an engine's own shader, read as it is.
    const bool absolute = std::filesystem::path(name).is_absolute();
    const std::vector<std::filesystem::path> dirs =
        absolute ? std::vector<std::filesystem::path>{std::filesystem::path(name).parent_path()} : shaderSearchPath();
    for (const auto& dir : dirs) {
        const auto path = absolute ? std::filesystem::path(name) : dir / (name + ".spv");
        std::ifstream file(path, std::ios::binary | std::ios::ate);
        if (!file) {
            searched += (searched.empty() ? "" : ", ") + dir.string();
            continue;
        }
        const auto bytes = static_cast<size_t>(file.tellg());
        if (bytes == 0 || bytes % 4 != 0) {
            throw GpuError("shader '" + path.string() + "' is not SPIR-V (" + std::to_string(bytes) +
                           " bytes); rebuild it (ninja -C build glint_shaders)");
        }
        std::vector<uint32_t> code(bytes / 4);
        file.seekg(0);
        file.read(reinterpret_cast<char*>(code.data()), static_cast<std::streamsize>(bytes));
        if (!file || code[0] != 0x07230203u) {
            throw GpuError("shader '" + path.string() + "' is not SPIR-V (bad magic); rebuild it");
        }
        return code;
    }
    if (absolute) throw GpuError("shader '" + name + "' not found");
    throw GpuError("shader '" + name + ".spv' not found in [" + searched +
                   "]: build the project (scripts/demo or ninja -C build) or set GLINT_SHADER_DIR to build/shaders");
}

ShaderModule::ShaderModule(Context& ctx, const std::string& name, VkShaderStageFlags stage) : name_(name) {
    const auto code = loadSpirv(name);
    interface_ = reflectShader(code, stage, name);
    VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = code.size() * sizeof(uint32_t);
    info.pCode = code.data();
    VkShaderModule module = VK_NULL_HANDLE;
    check(vkCreateShaderModule(ctx.device(), &info, nullptr, &module), "vkCreateShaderModule '" + name + "'");
    module_ = Unique<VkShaderModule>(ctx.device(), module, vkDestroyShaderModule);
    ctx.setName(module, VK_OBJECT_TYPE_SHADER_MODULE, name);
}

// ---------------------------------------------------------------- PipelineLayout

PipelineLayout::PipelineLayout(Context& ctx, std::vector<Binding> bindings, uint32_t pushConstantBytes,
                               std::string_view name)
    : name_(name), bindings_(std::move(bindings)), pushConstantBytes_(pushConstantBytes) {
    uint32_t descriptorCount = 0;
    std::vector<VkDescriptorSetLayoutBinding> vkBindings;
    for (const auto& b : bindings_) {
        vkBindings.push_back({b.binding, b.type, b.count, b.stages, nullptr});
        descriptorCount += b.count;
    }
    if (descriptorCount > ctx.caps().maxPushDescriptors) {
        throw GpuError("pipeline '" + std::string(name) + "': " + std::to_string(descriptorCount) +
                       " descriptors exceed the device's push-descriptor limit of " +
                       std::to_string(ctx.caps().maxPushDescriptors));
    }
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    setInfo.bindingCount = static_cast<uint32_t>(vkBindings.size());
    setInfo.pBindings = vkBindings.data();
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    check(vkCreateDescriptorSetLayout(ctx.device(), &setInfo, nullptr, &setLayout),
          "vkCreateDescriptorSetLayout '" + std::string(name) + "'");
    setLayout_ = Unique<VkDescriptorSetLayout>(ctx.device(), setLayout, vkDestroyDescriptorSetLayout);

    VkPushConstantRange range{VK_SHADER_STAGE_ALL, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    info.setLayoutCount = 1;
    info.pSetLayouts = &setLayout;
    info.pushConstantRangeCount = pushConstantBytes > 0 ? 1 : 0;
    info.pPushConstantRanges = &range;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    check(vkCreatePipelineLayout(ctx.device(), &info, nullptr, &layout), "vkCreatePipelineLayout '" + std::string(name) + "'");
    layout_ = Unique<VkPipelineLayout>(ctx.device(), layout, vkDestroyPipelineLayout);
    ctx.setName(layout, VK_OBJECT_TYPE_PIPELINE_LAYOUT, name);
}

const Binding& PipelineLayout::binding(std::string_view name) const {
    for (const Binding& b : bindings_) {
        if (b.name == name) return b;
    }
    std::string names;
    for (const Binding& b : bindings_) names += (names.empty() ? "" : ", ") + b.name;
    throw GpuError("pipeline '" + name_ + "' has no binding named '" + std::string(name) + "' (it has: " + names + ")");
}

// ---------------------------------------------------------------- Pipeline

void Pipeline::pushConstants(VkCommandBuffer cmd, const void* data, uint32_t size) const {
    // At least the layout's range; bytes beyond it are a C++ struct's
    // trailing padding, which the shaders' block does not have.
    if (size < layout_.pushConstantBytes() || layout_.pushConstantBytes() == 0) {
        throw GpuError("pipeline '" + name_ + "': " + std::to_string(size) + " bytes of push constants, layout has " +
                       std::to_string(layout_.pushConstantBytes()));
    }
    vkCmdPushConstants(cmd, layout_.handle(), VK_SHADER_STAGE_ALL, 0, layout_.pushConstantBytes(), data);
}

Pipeline createComputePipeline(Context& ctx, const ComputePipelineDesc& desc) {
    Pipeline p;
    p.name_ = desc.name.empty() ? desc.shader : desc.name;
    p.bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
    ShaderModule module(ctx, desc.shader, VK_SHADER_STAGE_COMPUTE_BIT);
    p.layout_ = layoutFor(ctx, desc.bindings, desc.pushConstantBytes, {&module}, p.name_);
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module.handle();
    info.stage.pName = "main";
    info.layout = p.layout_.handle();
    info.flags = statisticsFlags(ctx);
    VkPipeline pipeline = VK_NULL_HANDLE;
    check(vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline),
          "vkCreateComputePipelines '" + p.name_ + "'");
    p.pipeline_ = Unique<VkPipeline>(ctx.device(), pipeline, vkDestroyPipeline);
    logStatistics(ctx, pipeline, p.name_);
    ctx.setName(pipeline, VK_OBJECT_TYPE_PIPELINE, p.name_);
    return p;
}

Pipeline createGraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& desc) {
    Pipeline p;
    p.name_ = desc.name.empty() ? desc.vertexShader : desc.name;
    p.bindPoint_ = VK_PIPELINE_BIND_POINT_GRAPHICS;
    ShaderModule vs(ctx, desc.vertexShader, VK_SHADER_STAGE_VERTEX_BIT);
    ShaderModule fs(ctx, desc.fragmentShader, VK_SHADER_STAGE_FRAGMENT_BIT);
    p.layout_ = layoutFor(ctx, desc.bindings, desc.pushConstantBytes, {&vs, &fs}, p.name_);
    VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                                 {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vs.handle();
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fs.handle();
    stages[1].pName = "main";

    VkPipelineVertexInputStateCreateInfo vertexInput{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vertexInput.vertexBindingDescriptionCount = static_cast<uint32_t>(desc.vertexBindings.size());
    vertexInput.pVertexBindingDescriptions = desc.vertexBindings.data();
    vertexInput.vertexAttributeDescriptionCount = static_cast<uint32_t>(desc.vertexAttributes.size());
    vertexInput.pVertexAttributeDescriptions = desc.vertexAttributes.data();
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = desc.topology;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = desc.cullMode;
    raster.frontFace = desc.frontFace;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = desc.depthFormat != VK_FORMAT_UNDEFINED && desc.depthTest;
    depth.depthWriteEnable = desc.depthFormat != VK_FORMAT_UNDEFINED && desc.depthWrite;
    depth.depthCompareOp = desc.depthCompare;
    std::vector<VkPipelineColorBlendAttachmentState> blends(desc.colorFormats.size());
    for (auto& b : blends) {
        b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                           VK_COLOR_COMPONENT_A_BIT;
    }
    if (!desc.colorBlends.empty()) {
        if (desc.colorBlends.size() != desc.colorFormats.size()) {
            throw GpuError("graphics pipeline '" + p.name_ + "': colorBlends must have one entry per colour attachment");
        }
        blends = desc.colorBlends;
    }
    VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = static_cast<uint32_t>(blends.size());
    blend.pAttachments = blends.data();
    const VkDynamicState dynamics[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR, VK_DYNAMIC_STATE_CULL_MODE,
                                       VK_DYNAMIC_STATE_FRONT_FACE};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = desc.dynamicCulling ? 4 : 2;
    dynamic.pDynamicStates = dynamics;
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = static_cast<uint32_t>(desc.colorFormats.size());
    rendering.pColorAttachmentFormats = desc.colorFormats.data();
    rendering.depthAttachmentFormat = desc.depthFormat;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertexInput;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = p.layout_.handle();
    info.flags = statisticsFlags(ctx);
    VkPipeline pipeline = VK_NULL_HANDLE;
    check(vkCreateGraphicsPipelines(ctx.device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline),
          "vkCreateGraphicsPipelines '" + p.name_ + "'");
    p.pipeline_ = Unique<VkPipeline>(ctx.device(), pipeline, vkDestroyPipeline);
    logStatistics(ctx, pipeline, p.name_);
    ctx.setName(pipeline, VK_OBJECT_TYPE_PIPELINE, p.name_);
    return p;
}

Pipeline createRayTracingPipeline(Context& ctx, const RayTracingPipelineDesc& desc) {
    Pipeline p;
    p.name_ = desc.name.empty() ? desc.raygen : desc.name;
    if (!ctx.caps().rayTracingPipeline) {
        throw GpuError("pipeline '" + p.name_ + "': device '" + ctx.caps().deviceName +
                       "' has no VK_KHR_ray_tracing_pipeline");
    }
    if (desc.maxRecursionDepth > ctx.caps().rayTracing.maxRayRecursionDepth) {
        throw GpuError("pipeline '" + p.name_ + "': recursion depth " + std::to_string(desc.maxRecursionDepth) +
                       " exceeds the device's " + std::to_string(ctx.caps().rayTracing.maxRayRecursionDepth));
    }
    p.bindPoint_ = VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR;

    std::vector<ShaderModule> modules;
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
    modules.reserve(1 + desc.misses.size() + 2 * desc.hitGroups.size());
    auto addStage = [&](const std::string& name, VkShaderStageFlagBits stage) -> uint32_t {
        modules.emplace_back(ctx, name, stage);
        VkPipelineShaderStageCreateInfo s{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        s.stage = stage;
        s.module = modules.back().handle();
        s.pName = "main";
        stages.push_back(s);
        return static_cast<uint32_t>(stages.size() - 1);
    };
    auto group = [](VkRayTracingShaderGroupTypeKHR type) {
        VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
        g.type = type;
        g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
        return g;
    };
    auto raygen = group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR);
    raygen.generalShader = addStage(desc.raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    groups.push_back(raygen);
    for (const auto& m : desc.misses) {
        auto g = group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR);
        g.generalShader = addStage(m, VK_SHADER_STAGE_MISS_BIT_KHR);
        groups.push_back(g);
    }
    for (const auto& h : desc.hitGroups) {
        auto g = group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR);
        if (!h.closestHit.empty()) g.closestHitShader = addStage(h.closestHit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
        if (!h.anyHit.empty()) g.anyHitShader = addStage(h.anyHit, VK_SHADER_STAGE_ANY_HIT_BIT_KHR);
        groups.push_back(g);
    }

    std::vector<const ShaderModule*> reflected;
    for (const ShaderModule& m : modules) reflected.push_back(&m);
    p.layout_ = layoutFor(ctx, desc.bindings, desc.pushConstantBytes, reflected, p.name_);

    VkRayTracingPipelineCreateInfoKHR info{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
    info.stageCount = static_cast<uint32_t>(stages.size());
    info.pStages = stages.data();
    info.groupCount = static_cast<uint32_t>(groups.size());
    info.pGroups = groups.data();
    info.maxPipelineRayRecursionDepth = desc.maxRecursionDepth;
    info.layout = p.layout_.handle();
    info.flags = statisticsFlags(ctx);
    VkPipeline pipeline = VK_NULL_HANDLE;
    check(ctx.fn().createRayTracingPipelines(ctx.device(), VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline),
          "vkCreateRayTracingPipelinesKHR '" + p.name_ + "'");
    p.pipeline_ = Unique<VkPipeline>(ctx.device(), pipeline, vkDestroyPipeline);
    logStatistics(ctx, pipeline, p.name_);
    p.groupCount_ = info.groupCount;
    ctx.setName(pipeline, VK_OBJECT_TYPE_PIPELINE, p.name_);
    return p;
}

// ---------------------------------------------------------------- ShaderBindingTable

ShaderBindingTable::ShaderBindingTable(Context& ctx, const Pipeline& pipeline, uint32_t missCount,
                                       uint32_t hitGroupCount) {
    const auto& rt = ctx.caps().rayTracing;
    const uint32_t groupCount = 1 + missCount + hitGroupCount;
    if (groupCount != pipeline.groupCount()) {
        throw GpuError("shader binding table for '" + pipeline.name() + "': " + std::to_string(groupCount) +
                       " groups asked, the pipeline has " + std::to_string(pipeline.groupCount()));
    }
    const uint32_t handleSize = rt.shaderGroupHandleSize;
    const uint32_t stride = alignUp(handleSize, rt.shaderGroupHandleAlignment);
    const uint32_t base = rt.shaderGroupBaseAlignment;
    const uint32_t raygenSize = alignUp(stride, base);  // raygen: size must equal stride
    const uint32_t missSize = alignUp(missCount * stride, base);
    const uint32_t hitSize = alignUp(hitGroupCount * stride, base);

    std::vector<std::byte> handles(size_t(groupCount) * handleSize);
    check(ctx.fn().getRayTracingShaderGroupHandles(ctx.device(), pipeline.handle(), 0, groupCount, handles.size(),
                                                   handles.data()),
          "vkGetRayTracingShaderGroupHandlesKHR '" + pipeline.name() + "'");

    // Over-allocate by one base alignment: the buffer's address is only
    // guaranteed to meet the buffer's own alignment.
    const VkDeviceSize total = raygenSize + missSize + hitSize + base;
    buffer_ = Buffer(ctx, {total, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR, MemoryUsage::Upload,
                           pipeline.name() + ".sbt"});
    const VkDeviceAddress start = (buffer_.address() + base - 1) / base * base;
    std::byte* mapped = buffer_.mapped() + (start - buffer_.address());
    auto copyGroup = [&](uint32_t group, std::byte* dst) {
        std::memcpy(dst, handles.data() + size_t(group) * handleSize, handleSize);
    };
    copyGroup(0, mapped);
    for (uint32_t i = 0; i < missCount; ++i) copyGroup(1 + i, mapped + raygenSize + i * stride);
    for (uint32_t i = 0; i < hitGroupCount; ++i) copyGroup(1 + missCount + i, mapped + raygenSize + missSize + i * stride);

    raygen_ = {start, raygenSize, raygenSize};
    miss_ = {missCount ? start + raygenSize : 0, stride, missCount ? missSize : 0};
    hit_ = {hitGroupCount ? start + raygenSize + missSize : 0, stride, hitGroupCount ? hitSize : 0};
    callable_ = {0, 0, 0};
}

void ShaderBindingTable::traceRays(const Context& ctx, VkCommandBuffer cmd, uint32_t width, uint32_t height,
                                   uint32_t depth) const {
    ctx.fn().cmdTraceRays(cmd, &raygen_, &miss_, &hit_, &callable_, width, height, depth);
}

} // namespace glint::gpu
