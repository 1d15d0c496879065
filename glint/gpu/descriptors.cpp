#include "glint/gpu/descriptors.h"

#include "glint/gpu/context.h"
#include "glint/gpu/error.h"

#include <algorithm>

namespace glint::gpu {

VkWriteDescriptorSet& PushDescriptors::add(uint32_t binding, VkDescriptorType type) {
    const auto& bindings = pipeline_.layout().bindings();
    const auto it = std::find_if(bindings.begin(), bindings.end(), [&](const Binding& b) { return b.binding == binding; });
    if (it == bindings.end()) {
        throw GpuError("pipeline '" + pipeline_.name() + "' has no binding " + std::to_string(binding));
    }
    if (it->type != type) {
        throw GpuError("pipeline '" + pipeline_.name() + "': binding " + std::to_string(binding) +
                       " written with descriptor type " + std::to_string(type) + ", declared " +
                       std::to_string(it->type));
    }
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = type;
    writes_.push_back(w);
    return writes_.back();
}

PushDescriptors& PushDescriptors::storageBuffer(uint32_t binding, const Buffer& buffer, VkDeviceSize offset,
                                                VkDeviceSize range) {
    buffers_.push_back({buffer.handle(), offset, range});
    add(binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER).pBufferInfo = &buffers_.back();
    return *this;
}

PushDescriptors& PushDescriptors::uniformBuffer(uint32_t binding, const Buffer& buffer, VkDeviceSize offset,
                                                VkDeviceSize range) {
    buffers_.push_back({buffer.handle(), offset, range});
    add(binding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER).pBufferInfo = &buffers_.back();
    return *this;
}

PushDescriptors& PushDescriptors::storageImage(uint32_t binding, VkImageView view) {
    images_.push_back({VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL});
    add(binding, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE).pImageInfo = &images_.back();
    return *this;
}

PushDescriptors& PushDescriptors::sampledImage(uint32_t binding, VkImageView view, VkSampler sampler,
                                               VkImageLayout layout) {
    images_.push_back({sampler, view, layout});
    add(binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER).pImageInfo = &images_.back();
    return *this;
}

PushDescriptors& PushDescriptors::accelerationStructure(uint32_t binding, VkAccelerationStructureKHR as) {
    accels_.push_back(as);
    VkWriteDescriptorSetAccelerationStructureKHR a{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    a.accelerationStructureCount = 1;
    a.pAccelerationStructures = &accels_.back();
    accelWrites_.push_back(a);
    add(binding, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR).pNext = &accelWrites_.back();
    return *this;
}

void PushDescriptors::push(const Context& ctx, VkCommandBuffer cmd) const {
    for (const auto& b : pipeline_.layout().bindings()) {
        const bool written = std::any_of(writes_.begin(), writes_.end(),
                                         [&](const VkWriteDescriptorSet& w) { return w.dstBinding == b.binding; });
        if (!written) {
            throw GpuError("pipeline '" + pipeline_.name() + "': binding " + std::to_string(b.binding) +
                           " was not written before push");
        }
    }
    ctx.fn().cmdPushDescriptorSet(cmd, pipeline_.bindPoint(), pipeline_.layout().handle(), 0,
                                  static_cast<uint32_t>(writes_.size()), writes_.data());
}

} // namespace glint::gpu
