#pragma once
// Moving small data in and out of a frame through the graph, so that a
// pass, a sample or a test does not write its own copy pass:
//
//   // constants that outgrow push constants, written by the host for the frame:
//   const rg::Buffer constants = rg::addUpload(graph, "integrate.constants", values);
//   ... b.read(constants, rg::Access::StorageRead) ...
//
//   // a frame's image read back on the host:
//   rg::HostReadback readback(ctx, width * height * 4, "output");
//   readback.copy(graph, resources, frame.output.color);
//   executor.run(graph.compile(...), resources);
//   executor.waitIdle();
//   std::span<const uint8_t> rgba = readback.bytes();
//
//   // a few bytes of each frame, read some frames later without a wait:
//   rg::FrameReadback (below)

#include "glint/gpu/commands.h"
#include "glint/gpu/resources.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace glint::rg {

// A buffer of bytes.size() bytes that holds `bytes` (copied now) when the
// frame starts (Graph::uploadBuffer): the executor writes them into
// host-visible memory of its own before it submits the frame, so no
// transfer pass runs and no barrier waits for one between the passes
// around the reader. Readers then declare their own access to the returned
// handle, on either queue.
Buffer addUpload(Graph& graph, std::string_view name, std::span<const std::byte> bytes);

// One value's bytes (a constants struct).
template <class T>
    requires(!std::is_convertible_v<const T&, std::span<const std::byte>>)
Buffer addUpload(Graph& graph, std::string_view name, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "addUpload copies the value's bytes");
    return addUpload(graph, name, std::span<const std::byte>(reinterpret_cast<const std::byte*>(&value), sizeof(T)));
}

// A host-visible buffer that a frame fills at its end: copy() declares a
// graph import of it and a transfer pass on the graphics queue copying a
// texture (mip 0, layer 0, tightly packed) or a buffer into it, marked as
// an output so it is never culled. Read bytes() once the frame's work has
// finished (Executor::waitIdle, or a later frame's slot wait). One copy per
// frame per HostReadback.
class HostReadback {
public:
    HostReadback(gpu::Context& ctx, VkDeviceSize bytes, std::string name);

    // The texture's mip 0 must fit (width x height x bytesPerTexel); checked
    // when the copy runs, against the image the plan bound.
    void copy(Graph& graph, FrameResources& resources, Texture texture) const;
    // Copies min(buffer size, this size) bytes from the start.
    void copy(Graph& graph, FrameResources& resources, Buffer buffer) const;

    std::span<const std::byte> bytes() const;
    template <class T>
    std::span<const T> as() const {
        static_assert(std::is_trivially_copyable_v<T>);
        const std::span<const std::byte> b = bytes();
        return {reinterpret_cast<const T*>(b.data()), b.size() / sizeof(T)};
    }
    const gpu::Buffer& buffer() const { return buffer_; }
    const std::string& name() const { return name_; }

private:
    // This buffer as the frame's import, bound in `resources`.
    Buffer importTarget(Graph& graph, FrameResources& resources) const;

    gpu::Buffer buffer_;
    std::string name_;
};

// A few bytes out of each frame that asks, read by the host some frames
// later without waiting for the GPU: a frame's own statistics steering the
// frames after it (passes::ReflectionRenderer's SSLR gate).
//
//   rg::FrameReadback readback(ctx, 4, "gate");
//   each frame:
//     if (const auto target = readback.declare(graph))   // an import
//         ... a pass writes target->buffer (TransferDst or a storage write) ...
//     ... then, with the frame's resources: readback.bind(resources, *target);
//   a later frame, with a sequence an earlier declare() returned:
//     if (const auto bytes = readback.read(sequence)) use(*bytes);
//
// `depth` host-visible buffers take turns; a timeline semaphore, signalled
// by the batch that leaves the frame's buffer in its final state (a host
// read), says which frames have finished. Run every frame that declares a
// target: one that is not leaves its sequence to read the bytes an older
// frame left in that buffer once a later frame has finished.
class FrameReadback {
public:
    // `depth` must exceed the frames in flight, or declare() finds every
    // buffer still in use and declares nothing.
    FrameReadback(gpu::Context& ctx, VkDeviceSize bytes, std::string name, uint32_t depth = 4);

    struct Target {
        Buffer buffer;          // the import a pass of this frame writes
        uint64_t sequence = 0;  // 1, 2, ...: what read() takes
    };
    // This frame's target; nullopt while every buffer awaits a frame still
    // on the GPU (no host wait).
    std::optional<Target> declare(Graph& graph);
    // Binds the target's buffer and the semaphore its frame signals.
    void bind(FrameResources& resources, const Target& target) const;

    // What the frame of `sequence` wrote, once it has finished (no wait):
    // nullopt before, and once its buffer has been declared again. Valid
    // until the next declare().
    std::optional<std::span<const std::byte>> read(uint64_t sequence) const;
    // Whether read(sequence) can no longer answer: declared again since.
    bool overwritten(uint64_t sequence) const { return declared_ >= sequence + depth(); }

    uint32_t depth() const { return uint32_t(buffers_.size()); }
    const std::string& name() const { return name_; }

private:
    std::vector<gpu::Buffer> buffers_;
    gpu::TimelineSemaphore done_;
    std::string name_;
    uint64_t declared_ = 0;  // the last sequence declared
};

} // namespace glint::rg
