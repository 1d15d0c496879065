#pragma once
// Pushes a pipeline's bindings at record time (VK_KHR_push_descriptor).
// Every binding the pipeline declares must be written before push(); a
// missing or mistyped one is an error naming the pipeline and the binding,
// not undefined behaviour on the GPU.

#include "glint/gpu/pipeline.h"

#include <deque>
#include <string_view>
#include <vector>

namespace glint::gpu {

class Context;

class PushDescriptors {
public:
    explicit PushDescriptors(const Pipeline& pipeline) : pipeline_(pipeline) {}

    PushDescriptors& storageBuffer(uint32_t binding, const Buffer& buffer, VkDeviceSize offset = 0,
                                   VkDeviceSize range = VK_WHOLE_SIZE);
    PushDescriptors& uniformBuffer(uint32_t binding, const Buffer& buffer, VkDeviceSize offset = 0,
                                   VkDeviceSize range = VK_WHOLE_SIZE);
    PushDescriptors& storageImage(uint32_t binding, VkImageView view);
    PushDescriptors& sampledImage(uint32_t binding, VkImageView view, VkSampler sampler,
                                  VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    PushDescriptors& accelerationStructure(uint32_t binding, VkAccelerationStructureKHR as);

    // The same by the binding's GLSL name (a buffer block's block name, any
    // other resource's variable name): the shader states the number once.
    PushDescriptors& storageBuffer(std::string_view name, const Buffer& buffer, VkDeviceSize offset = 0,
                                   VkDeviceSize range = VK_WHOLE_SIZE) {
        return storageBuffer(number(name), buffer, offset, range);
    }
    PushDescriptors& uniformBuffer(std::string_view name, const Buffer& buffer, VkDeviceSize offset = 0,
                                   VkDeviceSize range = VK_WHOLE_SIZE) {
        return uniformBuffer(number(name), buffer, offset, range);
    }
    PushDescriptors& storageImage(std::string_view name, VkImageView view) { return storageImage(number(name), view); }
    PushDescriptors& sampledImage(std::string_view name, VkImageView view, VkSampler sampler,
                                  VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL) {
        return sampledImage(number(name), view, sampler, layout);
    }
    PushDescriptors& accelerationStructure(std::string_view name, VkAccelerationStructureKHR as) {
        return accelerationStructure(number(name), as);
    }

    void push(const Context& ctx, VkCommandBuffer cmd) const;

private:
    uint32_t number(std::string_view name) const { return pipeline_.layout().binding(name).binding; }
    VkWriteDescriptorSet& add(uint32_t binding, VkDescriptorType type);

    const Pipeline& pipeline_;
    std::vector<VkWriteDescriptorSet> writes_;
    // Deques: stable addresses for the pointers inside writes_.
    std::deque<VkDescriptorBufferInfo> buffers_;
    std::deque<VkDescriptorImageInfo> images_;
    std::deque<VkAccelerationStructureKHR> accels_;
    std::deque<VkWriteDescriptorSetAccelerationStructureKHR> accelWrites_;
};

} // namespace glint::gpu
