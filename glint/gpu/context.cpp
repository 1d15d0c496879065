#include "glint/gpu/context.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string_view>

namespace glint::gpu {

namespace {

constexpr uint32_t kRequiredApi = VK_API_VERSION_1_3;

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
    return out;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* log = static_cast<ValidationLog*>(user);
    const char* id = data->pMessageIdName ? data->pMessageIdName : "";
    const char* text = data->pMessage ? data->pMessage : "";
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        const size_t before = log->count();
        log->add({severity, id, text});
        if (log->count() > before) {
            spdlog::error("validation: [{}] {}", id, text);
        } else {
            spdlog::debug("validation (set aside: layer 1.3.239 cannot see timeline waits): [{}] {}", id, text);
        }
    } else {
        spdlog::trace("validation: [{}] {}", id, text);
    }
    return VK_FALSE;  // never abort the call: the test decides
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(ValidationLog* log) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_VERBOSE_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = onValidationMessage;
    info.pUserData = log;
    return info;
}

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice device) {
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
    return extensions;
}

bool hasExtension(const std::vector<VkExtensionProperties>& list, const char* name) {
    return std::any_of(list.begin(), list.end(), [&](const auto& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// Lower is worse: a discrete GPU first, then lavapipe (the tests' device).
int typeScore(VkPhysicalDeviceType type) {
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 1;
    default: return 0;
    }
}

// Why a device cannot serve Glint, or empty when it can.
std::string unsuitableReason(VkPhysicalDevice device, const ContextOptions& options) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(device, &props);
    if (props.apiVersion < kRequiredApi) {
        return "Vulkan " + versionString(props.apiVersion) + " < 1.3 required";
    }
    const auto extensions = deviceExtensions(device);
    std::vector<std::string> missing;
    auto need = [&](const char* name) {
        if (!hasExtension(extensions, name)) {
            missing.emplace_back(name);
        }
    };
    need(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    if (options.swapchain) {
        need(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    if (options.requireRayTracing) {
        need(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
        need(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
        if (!hasExtension(extensions, VK_KHR_RAY_QUERY_EXTENSION_NAME) &&
            !hasExtension(extensions, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME)) {
            missing.emplace_back(VK_KHR_RAY_QUERY_EXTENSION_NAME " or " VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
        }
    }
    std::string reason;
    for (const auto& m : missing) {
        reason += (reason.empty() ? "missing " : ", ") + m;
    }
    return reason;
}

// An option, or its environment variable set to 1.
bool optionOrEnvironment(bool option, const char* variable) {
    if (option) return true;
    const char* env = std::getenv(variable);
    return env != nullptr && std::string_view(env) == "1";
}

} // namespace

bool rayTracingDisabled(const ContextOptions& options) {
    return optionOrEnvironment(options.disableRayTracing, "GLINT_NO_RAY_TRACING");
}

bool validationRequested(const ContextOptions& options) {
    return optionOrEnvironment(options.validation, "GLINT_VALIDATION");
}

bool pipelineStatisticsRequested(const ContextOptions& options) {
    return optionOrEnvironment(options.pipelineStatistics, "GLINT_PIPELINE_STATS");
}

std::string versionString(uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

const char* deviceTypeName(VkPhysicalDeviceType type) {
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
    }
}

std::string queueFlagsString(VkQueueFlags flags) {
    std::string s;
    auto add = [&](VkQueueFlags bit, const char* name) {
        if (flags & bit) {
            s += s.empty() ? name : std::string("+") + name;
        }
    };
    add(VK_QUEUE_GRAPHICS_BIT, "graphics");
    add(VK_QUEUE_COMPUTE_BIT, "compute");
    add(VK_QUEUE_TRANSFER_BIT, "transfer");
    add(VK_QUEUE_SPARSE_BINDING_BIT, "sparse");
    add(VK_QUEUE_VIDEO_DECODE_BIT_KHR, "video-decode");
    add(VK_QUEUE_OPTICAL_FLOW_BIT_NV, "optical-flow");
    return s.empty() ? "none" : s;
}

Context::Context(const ContextOptions& options) : log_(std::make_shared<ValidationLog>()) {
    // If construction throws half-way the destructor does not run, so the
    // handles made so far are released here.
    try {
        createInstance(options);
        selectPhysicalDevice(options);
        createDevice(options);
        faults_ = std::make_unique<FaultInjector>(options.fault);
        memory_ = std::make_unique<MemoryAllocator>(physicalDevice_, device_, faults_.get());
    } catch (...) {
        release();
        throw;
    }
}

Context::~Context() { release(); }

void Context::release() noexcept {
    memory_.reset();
    if (device_ != VK_NULL_HANDLE) {
        vkDeviceWaitIdle(device_);
        vkDestroyDevice(device_, nullptr);
        device_ = VK_NULL_HANDLE;
    }
    if (messenger_ != VK_NULL_HANDLE) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        destroy(instance_, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance_ != VK_NULL_HANDLE) {
        vkDestroyInstance(instance_, nullptr);
        instance_ = VK_NULL_HANDLE;
    }
}

void Context::createInstance(const ContextOptions& options) {
    uint32_t loaderVersion = 0;
    if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS || loaderVersion < kRequiredApi) {
        throw GpuError("the Vulkan loader supports " + versionString(loaderVersion) +
                       "; Glint needs 1.3 (install libvulkan1 >= 1.3)");
    }

    uint32_t count = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> available(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, available.data());

    std::vector<const char*> extensions;
    for (const auto& e : options.instanceExtensions) {
        extensions.push_back(e.c_str());
    }
    debugUtils_ = hasExtension(available, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (debugUtils_) {
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }

    std::vector<const char*> layers;
    validation_ = validationRequested(options);
    VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    VkDebugUtilsMessengerCreateInfoEXT messenger = messengerInfo(log_.get());
    const void* next = nullptr;
    if (validation_) {
        vkEnumerateInstanceLayerProperties(&count, nullptr);
        std::vector<VkLayerProperties> layerProps(count);
        vkEnumerateInstanceLayerProperties(&count, layerProps.data());
        const bool found = std::any_of(layerProps.begin(), layerProps.end(), [](const auto& l) {
            return std::strcmp(l.layerName, kValidationLayerName) == 0;
        });
        if (!found) {
            throw GpuError(std::string("validation requested but the layer ") + kValidationLayerName +
                           " is not installed: run scripts/setup (package vulkan-validationlayers) or point "
                           "VK_LAYER_PATH at a folder holding VkLayer_khronos_validation.json");
        }
        if (!debugUtils_) {
            throw GpuError("validation requested but VK_EXT_debug_utils is missing, so messages cannot be collected");
        }
        layers.push_back(kValidationLayerName);
        extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        // Submit-time synchronization validation (hazards between command
        // buffers and queues) has no VkValidationFeatureEnableEXT value in
        // the 1.3.239 layer; it is switched on through the layer's own
        // setting (a ':'-separated list on Linux). A user's explicit
        // VK_LAYER_ENABLES wins.
        setenv("VK_LAYER_ENABLES",
               "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT:"
               "VALIDATION_CHECK_ENABLE_SYNCHRONIZATION_VALIDATION_QUEUE_SUBMIT",
               /*overwrite=*/0);
        features.enabledValidationFeatureCount = 1;
        features.pEnabledValidationFeatures = enables;
        features.pNext = &messenger;  // also catches messages from vkCreate/DestroyInstance
        next = &features;
    }

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "Glint";
    app.pEngineName = "Glint";
    app.apiVersion = kRequiredApi;
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pNext = next;
    info.pApplicationInfo = &app;
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    const VkResult created = vkCreateInstance(&info, nullptr, &instance_);
    if (created == VK_ERROR_INCOMPATIBLE_DRIVER) {
        throw GpuError("no Vulkan driver could be loaded (VK_ERROR_INCOMPATIBLE_DRIVER): install a GPU driver or "
                       "lavapipe (scripts/setup), or point VK_DRIVER_FILES at a driver's ICD manifest");
    }
    check(created, "vkCreateInstance");

    if (validation_) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
        check(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
        spdlog::info("validation: Khronos layer on, synchronization validation on");
    }
}

void Context::selectPhysicalDevice(const ContextOptions& options) {
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    if (count == 0) {
        throw GpuError("no Vulkan device found: install a GPU driver, or lavapipe with scripts/setup "
                       "(mesa-vulkan-drivers >= 25 from bookworm-backports)");
    }
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());

    std::string filter = options.deviceFilter;
    if (filter.empty()) {
        if (const char* env = std::getenv("GLINT_DEVICE")) {
            filter = env;
        }
    }

    std::string names;
    std::string rejections;
    VkPhysicalDevice best = VK_NULL_HANDLE;
    int bestScore = -1;
    bool anyMatch = false;
    for (VkPhysicalDevice d : devices) {
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(d, &props);
        names += (names.empty() ? "'" : ", '") + std::string(props.deviceName) + "'";
        if (!filter.empty() && lower(props.deviceName).find(lower(filter)) == std::string::npos) {
            continue;
        }
        anyMatch = true;
        const std::string reason = unsuitableReason(d, options);
        if (!reason.empty()) {
            rejections += "\n  '" + std::string(props.deviceName) + "': " + reason;
            continue;
        }
        if (typeScore(props.deviceType) > bestScore) {
            bestScore = typeScore(props.deviceType);
            best = d;
        }
    }
    if (!anyMatch) {
        throw GpuError("GLINT_DEVICE='" + filter + "' matches no Vulkan device; devices: " + names +
                       " (unset GLINT_DEVICE or give a substring of one of these)");
    }
    if (best == VK_NULL_HANDLE) {
        throw GpuError("no Vulkan device can run Glint:" + rejections +
                       "\n  lavapipe needs Mesa >= 25 (scripts/setup installs it from bookworm-backports)");
    }
    physicalDevice_ = best;
}

void Context::createDevice(const ContextOptions& options) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physicalDevice_, &props);
    const auto extensions = deviceExtensions(physicalDevice_);

    // ---- capabilities
    caps_.deviceName = props.deviceName;
    caps_.deviceType = props.deviceType;
    caps_.vendorId = props.vendorID;
    caps_.apiVersion = props.apiVersion;
    caps_.driverVersion = props.driverVersion;
    caps_.timestampPeriodNs = props.limits.timestampPeriod;
    caps_.bufferImageGranularity = props.limits.bufferImageGranularity;

    VkPhysicalDeviceAccelerationStructureFeaturesKHR asFeatures{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtFeatures{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
    VkPhysicalDeviceRayQueryFeaturesKHR rqFeatures{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR statsFeatures{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};

    const bool hasAs = !rayTracingDisabled(options) &&
                       hasExtension(extensions, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) &&
                       hasExtension(extensions, VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
    const bool hasRq = hasAs && hasExtension(extensions, VK_KHR_RAY_QUERY_EXTENSION_NAME) && !options.disableRayQuery;
    const bool hasRt = hasAs && hasExtension(extensions, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
    const bool statsRequested = pipelineStatisticsRequested(options);
    const bool hasStats =
        statsRequested && hasExtension(extensions, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);

    // Build the query chain with only the structures this device knows.
    void* chain = nullptr;
    auto link = [&](auto& s) {
        s.pNext = chain;
        chain = &s;
    };
    if (hasAs) link(asFeatures);
    if (hasRt) link(rtFeatures);
    if (hasRq) link(rqFeatures);
    if (hasStats) link(statsFeatures);
    link(f13);
    link(f12);
    link(f11);
    features.pNext = chain;
    vkGetPhysicalDeviceFeatures2(physicalDevice_, &features);

    auto require = [&](VkBool32 value, const char* name) {
        if (!value) {
            throw GpuError("device '" + caps_.deviceName + "' lacks the feature " + name);
        }
    };
    require(f12.bufferDeviceAddress, "bufferDeviceAddress");
    require(f12.timelineSemaphore, "timelineSemaphore");
    require(f12.scalarBlockLayout, "scalarBlockLayout");
    require(f12.hostQueryReset, "hostQueryReset");
    require(f13.synchronization2, "synchronization2");
    require(f13.dynamicRendering, "dynamicRendering");
    // The G-buffer draws runs of instances with multi-draws whose count the
    // occlusion cull writes, the instance in each command's firstInstance
    // (passes/gbuffer.cpp).
    require(features.features.multiDrawIndirect, "multiDrawIndirect");
    require(features.features.drawIndirectFirstInstance, "drawIndirectFirstInstance");
    require(f12.drawIndirectCount, "drawIndirectCount");

    caps_.accelerationStructure = hasAs && asFeatures.accelerationStructure;
    caps_.rayQuery = hasRq && rqFeatures.rayQuery && caps_.accelerationStructure;
    caps_.rayTracingPipeline = hasRt && rtFeatures.rayTracingPipeline && caps_.accelerationStructure;
    caps_.memoryBudget = hasExtension(extensions, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    caps_.pipelineStatistics = hasStats && statsFeatures.pipelineExecutableInfo;
    if (statsRequested && !caps_.pipelineStatistics) {
        spdlog::warn("pipeline statistics requested, but device '{}' has no VK_KHR_pipeline_executable_properties",
                     caps_.deviceName);
    }
    if (options.requireRayTracing && !(caps_.rayQuery || caps_.rayTracingPipeline)) {
        throw GpuError("device '" + caps_.deviceName + "' has no usable ray backend (needs accelerationStructure plus "
                       "rayQuery or rayTracingPipeline)" +
                       (rayTracingDisabled(options) ? " (ray tracing disabled by option or GLINT_NO_RAY_TRACING)" : ""));
    }

    // Enable exactly what we use: the queried structs double as the enable
    // chain once the features we do not want are cleared.
    VkPhysicalDeviceFeatures2 enable{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    enable.features.shaderInt64 = features.features.shaderInt64;
    enable.features.shaderInt16 = features.features.shaderInt16;
    enable.features.samplerAnisotropy = features.features.samplerAnisotropy;
    enable.features.fragmentStoresAndAtomics = features.features.fragmentStoresAndAtomics;
    enable.features.shaderStorageImageWriteWithoutFormat = features.features.shaderStorageImageWriteWithoutFormat;
    enable.features.shaderStorageImageReadWithoutFormat = features.features.shaderStorageImageReadWithoutFormat;
    enable.features.multiDrawIndirect = VK_TRUE;
    enable.features.drawIndirectFirstInstance = VK_TRUE;
    enable.features.depthClamp = features.features.depthClamp;
    enable.features.fillModeNonSolid = features.features.fillModeNonSolid;

    VkPhysicalDeviceVulkan11Features e11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    e11.shaderDrawParameters = f11.shaderDrawParameters;
    e11.storageBuffer16BitAccess = f11.storageBuffer16BitAccess;
    VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    e12.bufferDeviceAddress = VK_TRUE;
    e12.timelineSemaphore = VK_TRUE;
    e12.drawIndirectCount = VK_TRUE;
    e12.scalarBlockLayout = VK_TRUE;
    e12.hostQueryReset = VK_TRUE;
    e12.descriptorIndexing = f12.descriptorIndexing;
    e12.runtimeDescriptorArray = f12.runtimeDescriptorArray;
    e12.descriptorBindingPartiallyBound = f12.descriptorBindingPartiallyBound;
    e12.descriptorBindingVariableDescriptorCount = f12.descriptorBindingVariableDescriptorCount;
    e12.shaderSampledImageArrayNonUniformIndexing = f12.shaderSampledImageArrayNonUniformIndexing;
    e12.shaderStorageBufferArrayNonUniformIndexing = f12.shaderStorageBufferArrayNonUniformIndexing;
    e12.storageBuffer8BitAccess = f12.storageBuffer8BitAccess;
    e12.uniformAndStorageBuffer8BitAccess = f12.uniformAndStorageBuffer8BitAccess;
    e12.shaderInt8 = f12.shaderInt8;
    e12.shaderFloat16 = f12.shaderFloat16;
    e12.samplerFilterMinmax = f12.samplerFilterMinmax;
    VkPhysicalDeviceVulkan13Features e13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    e13.synchronization2 = VK_TRUE;
    e13.dynamicRendering = VK_TRUE;
    e13.maintenance4 = f13.maintenance4;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR eAs{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    eAs.accelerationStructure = VK_TRUE;
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR eRt{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
    eRt.rayTracingPipeline = VK_TRUE;
    eRt.rayTraversalPrimitiveCulling = rtFeatures.rayTraversalPrimitiveCulling;
    eRt.rayTracingPipelineTraceRaysIndirect = rtFeatures.rayTracingPipelineTraceRaysIndirect;
    VkPhysicalDeviceRayQueryFeaturesKHR eRq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    eRq.rayQuery = VK_TRUE;
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR eStats{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
    eStats.pipelineExecutableInfo = VK_TRUE;

    std::vector<const char*> enabledExtensions = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
    chain = nullptr;
    if (caps_.accelerationStructure) {
        enabledExtensions.push_back(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
        enabledExtensions.push_back(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
        link(eAs);
    }
    if (caps_.rayTracingPipeline) {
        enabledExtensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
        link(eRt);
    }
    if (caps_.rayQuery) {
        enabledExtensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
        link(eRq);
    }
    if (options.swapchain) {
        enabledExtensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    if (caps_.memoryBudget) {
        enabledExtensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    }
    if (caps_.pipelineStatistics) {
        enabledExtensions.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
        link(eStats);
    }
    link(e13);
    link(e12);
    link(e11);
    enable.pNext = chain;

    // ---- properties that depend on extensions
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDevicePushDescriptorPropertiesKHR push{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
    VkPhysicalDeviceRayTracingPipelinePropertiesKHR rtProps{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
    VkPhysicalDeviceAccelerationStructurePropertiesKHR asProps{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
    VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    driver.pNext = &push;
    push.pNext = &subgroup;
    void** tail = &subgroup.pNext;
    if (caps_.rayTracingPipeline) {
        *tail = &rtProps;
        tail = &rtProps.pNext;
    }
    if (caps_.accelerationStructure) {
        *tail = &asProps;
    }
    props2.pNext = &driver;
    vkGetPhysicalDeviceProperties2(physicalDevice_, &props2);
    caps_.driverName = driver.driverName;
    caps_.driverInfo = driver.driverInfo;
    caps_.maxPushDescriptors = push.maxPushDescriptors;
    caps_.subgroupSize = subgroup.subgroupSize;
    caps_.rayTracing.shaderGroupHandleSize = rtProps.shaderGroupHandleSize;
    caps_.rayTracing.shaderGroupHandleAlignment = rtProps.shaderGroupHandleAlignment;
    caps_.rayTracing.shaderGroupBaseAlignment = rtProps.shaderGroupBaseAlignment;
    caps_.rayTracing.maxRayRecursionDepth = rtProps.maxRayRecursionDepth;
    caps_.rayTracing.minScratchOffsetAlignment = asProps.minAccelerationStructureScratchOffsetAlignment;

    // ---- queue families
    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, families.data());
    std::optional<uint32_t> graphics;
    for (uint32_t i = 0; i < familyCount; ++i) {
        const VkQueueFlags f = families[i].queueFlags;
        caps_.queueFamilies.push_back({i, f, families[i].queueCount, families[i].timestampValidBits});
        const bool gc = (f & VK_QUEUE_GRAPHICS_BIT) && (f & VK_QUEUE_COMPUTE_BIT);
        if (gc && !graphics) {
            graphics = i;
        }
        if ((f & VK_QUEUE_COMPUTE_BIT) && !(f & VK_QUEUE_GRAPHICS_BIT) && !caps_.computeFamily) {
            caps_.computeFamily = i;
        }
    }
    if (!graphics) {
        throw GpuError("device '" + caps_.deviceName + "' has no queue family with graphics and compute");
    }
    caps_.graphicsFamily = *graphics;
    caps_.timestamps = props.limits.timestampComputeAndGraphics && families[*graphics].timestampValidBits > 0;

    const float priority = 1.0f;
    std::vector<VkDeviceQueueCreateInfo> queues;
    for (std::optional<uint32_t> family : {std::optional<uint32_t>(caps_.graphicsFamily), caps_.computeFamily}) {
        if (family) {
            VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
            q.queueFamilyIndex = *family;
            q.queueCount = 1;
            q.pQueuePriorities = &priority;
            queues.push_back(q);
        }
    }

    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.pNext = &enable;
    info.queueCreateInfoCount = static_cast<uint32_t>(queues.size());
    info.pQueueCreateInfos = queues.data();
    info.enabledExtensionCount = static_cast<uint32_t>(enabledExtensions.size());
    info.ppEnabledExtensionNames = enabledExtensions.data();
    check(vkCreateDevice(physicalDevice_, &info, nullptr, &device_), "vkCreateDevice");

    graphics_ = {VK_NULL_HANDLE, caps_.graphicsFamily};
    vkGetDeviceQueue(device_, caps_.graphicsFamily, 0, &graphics_.queue);
    if (caps_.computeFamily) {
        compute_ = Queue{VK_NULL_HANDLE, *caps_.computeFamily};
        vkGetDeviceQueue(device_, *caps_.computeFamily, 0, &compute_->queue);
    }

    // ---- extension entry points
    auto load = [&](auto& fn, const char* name) {
        fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(vkGetDeviceProcAddr(device_, name));
        if (!fn) {
            throw GpuError(std::string("device '") + caps_.deviceName + "' does not provide " + name);
        }
    };
    load(fn_.cmdPushDescriptorSet, "vkCmdPushDescriptorSetKHR");
    if (caps_.accelerationStructure) {
        load(fn_.createAccelerationStructure, "vkCreateAccelerationStructureKHR");
        load(fn_.destroyAccelerationStructure, "vkDestroyAccelerationStructureKHR");
        load(fn_.getAccelerationStructureBuildSizes, "vkGetAccelerationStructureBuildSizesKHR");
        load(fn_.getAccelerationStructureDeviceAddress, "vkGetAccelerationStructureDeviceAddressKHR");
        load(fn_.cmdBuildAccelerationStructures, "vkCmdBuildAccelerationStructuresKHR");
    }
    if (caps_.rayTracingPipeline) {
        load(fn_.createRayTracingPipelines, "vkCreateRayTracingPipelinesKHR");
        load(fn_.getRayTracingShaderGroupHandles, "vkGetRayTracingShaderGroupHandlesKHR");
        load(fn_.cmdTraceRays, "vkCmdTraceRaysKHR");
        load(fn_.cmdTraceRaysIndirect, "vkCmdTraceRaysIndirectKHR");
    }
    if (caps_.pipelineStatistics) {
        load(fn_.getPipelineExecutableProperties, "vkGetPipelineExecutablePropertiesKHR");
        load(fn_.getPipelineExecutableStatistics, "vkGetPipelineExecutableStatisticsKHR");
    }
    if (debugUtils_) {
        fn_.setDebugUtilsObjectName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
            vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
        fn_.cmdBeginDebugUtilsLabel = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
            vkGetInstanceProcAddr(instance_, "vkCmdBeginDebugUtilsLabelEXT"));
        fn_.cmdEndDebugUtilsLabel = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
            vkGetInstanceProcAddr(instance_, "vkCmdEndDebugUtilsLabelEXT"));
    }

    spdlog::info("device: {} ({}, {} {}), ray query {}, ray tracing pipeline {}, async compute {}", caps_.deviceName,
                 deviceTypeName(caps_.deviceType), caps_.driverName, caps_.driverInfo, caps_.rayQuery ? "yes" : "no",
                 caps_.rayTracingPipeline ? "yes" : "no",
                 caps_.computeFamily ? "family " + std::to_string(*caps_.computeFamily) : std::string("no"));
}

std::optional<uint64_t> Context::deviceMemoryInUse() const {
    if (!caps_.memoryBudget) return std::nullopt;
    VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
    VkPhysicalDeviceMemoryProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2};
    properties.pNext = &budget;
    vkGetPhysicalDeviceMemoryProperties2(physicalDevice_, &properties);
    uint64_t used = 0;
    for (uint32_t heap = 0; heap < properties.memoryProperties.memoryHeapCount; ++heap) used += budget.heapUsage[heap];
    return used;
}

void Context::setName(VkObjectType type, uint64_t handle, std::string_view name) const {
    if (fn_.setDebugUtilsObjectName && handle != 0) {
        const std::string n(name);
        VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
        info.objectType = type;
        info.objectHandle = handle;
        info.pObjectName = n.c_str();
        fn_.setDebugUtilsObjectName(device_, &info);
    }
}

void Context::waitIdle() const {
    VkResult result = vkDeviceWaitIdle(device_);
    if (result == VK_SUCCESS) result = faults_->next(FaultSite::Wait);
    check(result, "vkDeviceWaitIdle");
}

void Context::waitIdleForTeardown(std::string_view who) const noexcept {
    try {
        waitIdle();
    } catch (const std::exception& e) {
        // The error that ended the work was reported where it happened.
        spdlog::warn("{}: releasing its objects without the GPU idle: {}", who, e.what());
    }
}

} // namespace glint::gpu
