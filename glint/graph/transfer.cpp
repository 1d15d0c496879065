#include "glint/graph/transfer.h"

#include "glint/graph/error.h"
#include "glint/graph/ir.h"

#include <algorithm>
#include <memory>
#include <vector>

namespace glint::rg {

namespace {

constexpr BoundaryState kHostRead =
    BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

// The declared resource a handle names, or a GraphError naming the readback.
template <class H>
const ir::Resource& declared(const Graph& graph, H handle, const std::string& readback) {
    if (!handle.valid() || handle.graph != graph.id() || handle.index >= graph.declaration().resources.size()) {
        throw GraphError(ErrorKind::ForeignHandle, readback, "",
                         "the readback's source is not a resource of this graph");
    }
    return graph.declaration().resources[handle.index];
}

} // namespace

Buffer addUpload(Graph& graph, std::string_view name, std::span<const std::byte> bytes) {
    return graph.uploadBuffer(name, bytes);
}

HostReadback::HostReadback(gpu::Context& ctx, VkDeviceSize bytes, std::string name)
    : buffer_(ctx, {bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUsage::Readback, name}),
      name_(std::move(name)) {}

Buffer HostReadback::importTarget(Graph& graph, FrameResources& resources) const {
    // Left by the last frame's copy, read by the host after this one's.
    const Buffer target =
        graph.importBuffer(name_, {{buffer_.size()}, BoundaryState::of(Access::TransferDst), kHostRead});
    resources.bind(target, buffer_);
    return target;
}

void HostReadback::copy(Graph& graph, FrameResources& resources, Texture texture) const {
    // Copied: declaring the import below may move the declaration's
    // resources.
    const ir::Resource& source = declared(graph, texture, name_);
    const TextureDesc desc = source.texture;
    const std::string sourceName(source.name);
    const VkDeviceSize needed = VkDeviceSize(desc.width) * desc.height * desc.depth * gpu::bytesPerTexel(desc.format);
    if (needed > buffer_.size()) {
        throw GraphError(ErrorKind::InvalidDescription, name_, sourceName,
                         "the readback holds " + std::to_string(buffer_.size()) + " bytes, the texture's mip 0 " +
                             std::to_string(needed));
    }
    const Buffer target = importTarget(graph, resources);
    struct Data {
        Texture source;
        Buffer target;
    };
    const Data& data = graph.addPass<Data>(
        name_, Queue::Graphics,
        [&](Builder& b, Data& d) {
            d.source = b.read(texture, Access::TransferSrc);
            d.target = b.write(target, Access::TransferDst);
        },
        [extent = VkExtent3D{desc.width, desc.height, desc.depth}](const Data& d, PassContext& pc) {
            const gpu::Image& image = pc.image(d.source);
            VkBufferImageCopy region{};
            region.imageSubresource = {image.aspect(), 0, 0, 1};
            region.imageExtent = extent;
            vkCmdCopyImageToBuffer(pc.cmd(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.buffer(d.target).handle(), 1, &region);
        });
    graph.markOutput(data.target);
}

void HostReadback::copy(Graph& graph, FrameResources& resources, Buffer buffer) const {
    const VkDeviceSize size = std::min<VkDeviceSize>(declared(graph, buffer, name_).buffer.size, buffer_.size());
    const Buffer target = importTarget(graph, resources);
    struct Data {
        Buffer source;
        Buffer target;
    };
    const Data& data = graph.addPass<Data>(
        name_, Queue::Graphics,
        [&](Builder& b, Data& d) {
            d.source = b.read(buffer, Access::TransferSrc);
            d.target = b.write(target, Access::TransferDst);
        },
        [size](const Data& d, PassContext& pc) {
            const VkBufferCopy region{0, 0, size};
            vkCmdCopyBuffer(pc.cmd(), pc.buffer(d.source).handle(), pc.buffer(d.target).handle(), 1, &region);
        });
    graph.markOutput(data.target);
}

std::span<const std::byte> HostReadback::bytes() const {
    return {buffer_.mapped(), static_cast<size_t>(buffer_.size())};
}

FrameReadback::FrameReadback(gpu::Context& ctx, VkDeviceSize bytes, std::string name, uint32_t depth)
    : done_(ctx, name + ".done"), name_(std::move(name)) {
    if (depth < 2 || bytes == 0) {
        throw GraphError(ErrorKind::InvalidDescription, name_, "",
                         "a frame readback needs at least 2 buffers of at least one byte (got " +
                             std::to_string(depth) + " of " + std::to_string(bytes) + ")");
    }
    buffers_.reserve(depth);
    for (uint32_t i = 0; i < depth; ++i) {
        buffers_.emplace_back(ctx, gpu::BufferDesc{bytes,
                                                   VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                                   gpu::MemoryUsage::Readback, name_ + "." + std::to_string(i)});
    }
}

std::optional<FrameReadback::Target> FrameReadback::declare(Graph& graph) {
    const uint64_t sequence = declared_ + 1;
    // The buffer's last frame (depth sequences ago) must have finished: the
    // host read it, and a new frame may write it.
    if (sequence > depth() && !done_.reached(sequence - depth())) {
        return std::nullopt;
    }
    declared_ = sequence;
    // Left, by its last frame, as this frame leaves it: to the host's read
    // (the barrier from there orders this frame's write after that frame's).
    const Buffer buffer = graph.importBuffer(name_, {{buffers_.front().size()}, kHostRead, kHostRead});
    return Target{buffer, sequence};
}

void FrameReadback::bind(FrameResources& resources, const Target& target) const {
    resources.bind(target.buffer, buffers_[target.sequence % depth()]);
    resources.signalSemaphore(target.buffer, done_.handle(), target.sequence);
}

std::optional<std::span<const std::byte>> FrameReadback::read(uint64_t sequence) const {
    if (sequence == 0 || sequence > declared_ || overwritten(sequence) || !done_.reached(sequence)) {
        return std::nullopt;
    }
    const gpu::Buffer& buffer = buffers_[sequence % depth()];
    return std::span<const std::byte>(buffer.mapped(), static_cast<size_t>(buffer.size()));
}

} // namespace glint::rg
