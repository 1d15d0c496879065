#pragma once
// The Vulkan context: instance (with the validation harness when asked),
// physical device selection, logical device, queues, extension entry points,
// and the memory allocator. Everything else in glint/gpu takes a Context&.

#include "glint/gpu/fault.h"
#include "glint/gpu/memory.h"
#include "glint/gpu/validation.h"

#include <vulkan/vulkan.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace glint::gpu {

struct ContextOptions {
    // Khronos validation layer + synchronization validation + a messenger
    // collecting every warning and error (see validation()). The environment
    // variable GLINT_VALIDATION=1 sets it too, for any program.
    bool validation = false;
    // Fail unless the device has acceleration structures and at least one
    // ray backend (ray query or ray tracing pipeline).
    bool requireRayTracing = true;
    // Treat the device as if it lacked VK_KHR_acceleration_structure, ray
    // query and ray tracing pipelines: none is enabled and Capabilities
    // reports none (with requireRayTracing, creation then fails). The
    // environment variable GLINT_NO_RAY_TRACING=1 sets it too, so any
    // program can be run as on a device without ray tracing.
    bool disableRayTracing = false;
    // Substring of the device name to pick; empty means: take it from the
    // GLINT_DEVICE environment variable, or choose (discrete GPU first, then
    // lavapipe, then anything else).
    std::string deviceFilter;
    // Extra instance extensions (a window system's, e.g. from GLFW) and
    // whether the device needs VK_KHR_swapchain.
    std::vector<std::string> instanceExtensions;
    bool swapchain = false;
    // Disables the ray query backend even where the device has it, so the
    // ray tracing pipeline path can be exercised on any device.
    bool disableRayQuery = false;
    // Log each pipeline's executable statistics as it is created (register
    // count, shared memory and the like, whatever the driver reports through
    // VK_KHR_pipeline_executable_properties; info level), to tell what
    // limits a shader's occupancy. Where the device lacks the extension, a
    // warning and nothing else. The environment variable
    // GLINT_PIPELINE_STATS=1 sets it too, for any program.
    bool pipelineStatistics = false;
    // Tests only: make the Nth allocation, submission or wait fail
    // (gpu/fault.h).
    std::optional<FaultInjection> fault;
};

// ContextOptions::disableRayTracing, or GLINT_NO_RAY_TRACING=1 in the
// environment.
bool rayTracingDisabled(const ContextOptions& options);
// ContextOptions::validation, or GLINT_VALIDATION=1 in the environment.
bool validationRequested(const ContextOptions& options);
// ContextOptions::pipelineStatistics, or GLINT_PIPELINE_STATS=1 in the environment.
bool pipelineStatisticsRequested(const ContextOptions& options);

struct QueueFamily {
    uint32_t index = 0;
    VkQueueFlags flags = 0;
    uint32_t queueCount = 0;
    uint32_t timestampValidBits = 0;
};

struct RayTracingProperties {
    uint32_t shaderGroupHandleSize = 0;
    uint32_t shaderGroupHandleAlignment = 0;
    uint32_t shaderGroupBaseAlignment = 0;
    uint32_t maxRayRecursionDepth = 0;
    uint32_t minScratchOffsetAlignment = 0;
};

// What the chosen device can do; the render graph and passes decide from this.
struct Capabilities {
    std::string deviceName;
    std::string driverName;
    std::string driverInfo;
    VkPhysicalDeviceType deviceType = VK_PHYSICAL_DEVICE_TYPE_OTHER;
    uint32_t vendorId = 0;
    uint32_t apiVersion = 0;
    uint32_t driverVersion = 0;

    bool accelerationStructure = false;
    bool rayQuery = false;
    bool rayTracingPipeline = false;
    RayTracingProperties rayTracing;

    bool memoryBudget = false;      // VK_EXT_memory_budget enabled (Context::deviceMemoryInUse)
    // VK_KHR_pipeline_executable_properties enabled: pipelines log their
    // statistics (ContextOptions::pipelineStatistics).
    bool pipelineStatistics = false;
    bool timestamps = false;        // graphics queue can write timestamps
    float timestampPeriodNs = 0.0f; // nanoseconds per tick
    uint64_t bufferImageGranularity = 1;
    uint32_t maxPushDescriptors = 0;
    uint32_t subgroupSize = 0;

    std::vector<QueueFamily> queueFamilies;
    uint32_t graphicsFamily = 0;            // graphics + compute
    std::optional<uint32_t> computeFamily;  // compute without graphics: real async compute

    bool hasAsyncCompute() const { return computeFamily.has_value(); }
    // Acceleration structures and at least one ray backend.
    bool canTraceRays() const { return rayQuery || rayTracingPipeline; }
};

struct Queue {
    VkQueue queue = VK_NULL_HANDLE;
    uint32_t family = 0;
};

// Device-level entry points of extensions (the loader exports only core ones).
struct DeviceFunctions {
    PFN_vkCreateAccelerationStructureKHR createAccelerationStructure = nullptr;
    PFN_vkDestroyAccelerationStructureKHR destroyAccelerationStructure = nullptr;
    PFN_vkGetAccelerationStructureBuildSizesKHR getAccelerationStructureBuildSizes = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR getAccelerationStructureDeviceAddress = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR cmdBuildAccelerationStructures = nullptr;
    PFN_vkCreateRayTracingPipelinesKHR createRayTracingPipelines = nullptr;
    PFN_vkGetRayTracingShaderGroupHandlesKHR getRayTracingShaderGroupHandles = nullptr;
    PFN_vkCmdTraceRaysKHR cmdTraceRays = nullptr;
    PFN_vkCmdTraceRaysIndirectKHR cmdTraceRaysIndirect = nullptr;
    PFN_vkCmdPushDescriptorSetKHR cmdPushDescriptorSet = nullptr;
    PFN_vkSetDebugUtilsObjectNameEXT setDebugUtilsObjectName = nullptr;
    PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginDebugUtilsLabel = nullptr;
    PFN_vkCmdEndDebugUtilsLabelEXT cmdEndDebugUtilsLabel = nullptr;
    PFN_vkGetPipelineExecutablePropertiesKHR getPipelineExecutableProperties = nullptr;
    PFN_vkGetPipelineExecutableStatisticsKHR getPipelineExecutableStatistics = nullptr;
};

class Context {
public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
    VkDevice device() const { return device_; }
    const Capabilities& caps() const { return caps_; }
    const DeviceFunctions& fn() const { return fn_; }
    MemoryAllocator& memory() { return *memory_; }
    // Asked before every device memory allocation and queue submission and
    // after every host wait (gpu/fault.h); reports nothing unless
    // ContextOptions::fault.
    FaultInjector& faults() const { return *faults_; }
    // Bytes of device memory this process uses, summed over the heaps, as
    // the driver reports it (VK_EXT_memory_budget); none without the
    // extension. Counts what the driver holds beyond our allocator's blocks.
    std::optional<uint64_t> deviceMemoryInUse() const;

    const Queue& graphicsQueue() const { return graphics_; }
    // The async compute queue, or the graphics queue where the device has no
    // separate compute family (work then runs in order on one queue).
    const Queue& computeQueue() const { return compute_ ? *compute_ : graphics_; }

    bool validationEnabled() const { return validation_; }
    // Submissions the host waited for on the spot (gpu::submitAndWait:
    // uploads, readbacks, one-off work): per-frame code should make none.
    uint64_t blockingSubmits() const { return blockingSubmits_; }
    void countBlockingSubmit() { ++blockingSubmits_; }
    ValidationLog& validation() { return *log_; }
    // Shared so the log can be read after the Context (and its device) is gone.
    std::shared_ptr<ValidationLog> validationLog() const { return log_; }

    // Debug-utils object name (no-op without the extension).
    void setName(VkObjectType type, uint64_t handle, std::string_view name) const;
    template <typename T> void setName(T handle, VkObjectType type, std::string_view name) const {
        setName(type, reinterpret_cast<uint64_t>(handle), name);
    }

    // vkDeviceWaitIdle; throws GpuError on failure (a lost device).
    void waitIdle() const;
    // For destructors: waits like waitIdle, but a failure is logged, not
    // thrown (a lost device must not end the program while it tears down).
    void waitIdleForTeardown(std::string_view who) const noexcept;

private:
    void createInstance(const ContextOptions& options);
    void selectPhysicalDevice(const ContextOptions& options);
    void createDevice(const ContextOptions& options);
    void release() noexcept;

    bool validation_ = false;
    bool debugUtils_ = false;
    uint64_t blockingSubmits_ = 0;
    std::shared_ptr<ValidationLog> log_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    Capabilities caps_;
    DeviceFunctions fn_;
    Queue graphics_;
    std::optional<Queue> compute_;
    std::unique_ptr<FaultInjector> faults_;
    std::unique_ptr<MemoryAllocator> memory_;
};

// "1.3.280"
std::string versionString(uint32_t apiVersion);
const char* deviceTypeName(VkPhysicalDeviceType type);
std::string queueFlagsString(VkQueueFlags flags);

} // namespace glint::gpu
