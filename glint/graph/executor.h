#pragma once

// Executing Plans on Vulkan: the half of the render graph that makes calls.
//
//   rg::Executor executor(gpu);                     // once
//   each frame:
//     rg::Graph graph(executor.queueCaps());
//     ... addPass(...) ...
//     rg::Plan plan = graph.compile(executor.compileOptions());
//     rg::FrameResources imports;                 // this frame's imports
//     imports.bind(sceneHandle, sceneBuffer);
//     rg::SubmittedFrame done = executor.run(plan, imports);
//   executor.waitIdle(); executor.timings();       // per-pass GPU times
//
// A swapchain image (any image the graph does not own, waited for and
// handed on through binary semaphores):
//   const VkImage vk = swapchainImages[index];     // after vkAcquireNextImageKHR(acquired)
//   gpu::Image image = gpu::Image::external(gpu, vk, desc);  // non-owning; keep one per swapchain image
//   rg::Texture target = graph.importTexture("swapchain", {size,
//       rg::BoundaryState::acquired(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT),
//       rg::BoundaryState::of(rg::Access::Present)});
//   ... passes write `target` ...
//   imports.bind(target, image);
//   imports.waitSemaphore(target, acquired);       // by the batch of its first use
//   imports.signalSemaphore(target, renderFinished);  // by the batch that ends it in PRESENT_SRC
//   rg::SubmittedFrame frame = executor.run(plan, imports);
//   vkQueuePresentKHR(... waits renderFinished ...);
//   later: executor.wait(frame) before reusing what belonged to that frame
//   (its acquire semaphore, a readback buffer).
// The batch holding the image's first use waits on the semaphore at the
// stages of that use and of the initial state (where its first barrier
// starts, so the layout transition follows the wait). The batch that
// records the image's final barrier (PRESENT_SRC, destination stages
// kSemaphoreSignalStages) signals at kSemaphoreSignalStages, so the
// transition is inside the signal's scope; the verifier checks that order.
//
// What it keeps across frames:
// - transient memory: one allocation per plan heap, with the transients
//   placed (aliased) as the plan says. Kept while the transient layout
//   (descriptions, usage, placement) stays the same; rebuilt, after the GPU
//   is idle, when it changes.
// - history pairs, by name: two images (or buffers) that swap roles every
//   frame.
// - per frame in flight: command pools, timestamp queries; one timeline
//   semaphore per queue.
// Frames in flight: run() blocks only until the frame that last used the
// same slot (framesInFlight frames ago) has finished on the GPU. Resources
// the caller binds are its own to keep alive until the SubmittedFrame that
// used them has finished (wait(), finished()).

#include "glint/graph/compile.h"
#include "glint/graph/plan.h"
#include "glint/graph/types.h"

#include "glint/gpu/accel.h"
#include "glint/gpu/commands.h"
#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/gpu/timestamps.h"

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace glint::rg {

// The queue description compile() needs, from the device's capabilities.
QueueCaps queueCapsOf(const gpu::Capabilities& caps);

// The caller's resources for one frame, bound to the handles that imported
// them, and the semaphores (binary or timeline) that tie the frame to work
// outside the graph: a swapchain image's acquire and present.
class FrameResources {
public:
    void bind(Texture handle, const gpu::Image& image);
    void bind(Buffer handle, const gpu::Buffer& buffer);
    void bind(AccelStruct handle, const gpu::AccelerationStructure& accel);

    // The batch holding the first use of `image` waits on `semaphore` at
    // `stages`; 0 takes the stages of that use and of the import's initial
    // state, which must name a stage (BoundaryState::acquired): the first
    // barrier starts there, so its layout transition follows the wait. An
    // import no pass uses waits in the frame's first batch.
    void waitSemaphore(Texture image, VkSemaphore semaphore, VkPipelineStageFlags2 stages = 0, uint64_t value = 0);
    // The frame's first batch (submission order) waits on `semaphore` at `stages`.
    void waitSemaphore(VkSemaphore semaphore, VkPipelineStageFlags2 stages, uint64_t value = 0);
    // The batch that leaves `image` in its final state (records its final
    // barrier, or else holds its last use) signals `semaphore` at
    // kSemaphoreSignalStages. An import no pass uses: the frame's last batch.
    void signalSemaphore(Texture image, VkSemaphore semaphore, uint64_t value = 0);
    // The same for an imported buffer: the batch that leaves it in its final
    // state (a host read: the host may read it once the semaphore is
    // signalled, rg::FrameReadback) signals `semaphore`.
    void signalSemaphore(Buffer buffer, VkSemaphore semaphore, uint64_t value = 0);
    // The frame's last batch (submission order) signals `semaphore`. With
    // two queues the other queue may still be working: wait for a
    // SubmittedFrame to know the whole frame is done.
    void signalSemaphore(VkSemaphore semaphore, uint64_t value = 0);

private:
    friend class Executor;
    struct SemaphoreUse {
        uint32_t resource = kNoIndex;  // an imported texture or buffer; kNoIndex: the frame's first / last batch
        ResourceKind kind = ResourceKind::Texture;
        VkSemaphore semaphore = VK_NULL_HANDLE;
        VkPipelineStageFlags2 stages = 0;
        uint64_t value = 0;  // timeline semaphores only
    };
    std::map<uint32_t, const gpu::Image*> images_;
    std::map<uint32_t, const gpu::Buffer*> buffers_;
    std::map<uint32_t, const gpu::AccelerationStructure*> accels_;
    std::vector<SemaphoreUse> waits_;
    std::vector<SemaphoreUse> signals_;
    uint32_t graph_ = 0;
};

// What run() submitted: the timeline value each queue reaches when the
// frame's work on it is done (0: the frame put nothing there).
struct SubmittedFrame {
    uint64_t frame = 0;
    uint64_t timelineValue[kQueueCount] = {0, 0};
};

// What a pass's execute callback records with.
class PassContext {
public:
    VkCommandBuffer cmd() const { return cmd_; }
    gpu::Context& gpu() const { return gpu_; }
    const std::string& passName() const { return name_; }
    uint64_t frame() const { return frame_; }
    Queue queue() const { return queue_; }

    // The Vulkan objects behind this frame's handles (history handles give
    // this frame's image of the pair). Errors name the pass and resource.
    const gpu::Image& image(Texture handle) const;
    VkImageView view(Texture handle) const { return image(handle).view(); }
    // The layout this pass's use of `handle` has (what a descriptor for it
    // must say): e.g. DEPTH_READ_ONLY_OPTIMAL for a sampled depth buffer.
    VkImageLayout layout(Texture handle) const;
    const gpu::Buffer& buffer(Buffer handle) const;
    const gpu::AccelerationStructure& accel(AccelStruct handle) const;

    // Binds `pipeline` and dispatches; the bindings must have been pushed.
    void dispatch(const gpu::Pipeline& pipeline, uint32_t x, uint32_t y = 1, uint32_t z = 1) const;
    void dispatchIndirect(const gpu::Pipeline& pipeline, Buffer args, VkDeviceSize offset = 0) const;

private:
    friend class Executor;
    PassContext(class Executor& executor, gpu::Context& gpu) : executor_(executor), gpu_(gpu) {}
    class Executor& executor_;
    gpu::Context& gpu_;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    std::string name_;
    uint64_t frame_ = 0;
    Queue queue_ = Queue::Graphics;
    const Plan* plan_ = nullptr;
    const PlannedPass* pass_ = nullptr;
};

struct PassTiming {
    std::string name;
    Queue queue = Queue::Graphics;
    std::optional<double> milliseconds;  // none where the queue has no timestamps (see PassTimer)
    uint64_t frame = 0;                  // the run() it belongs to, counted from 0
    // PassTimer::HostSerial only: the process's CPU time over the pass (all
    // threads, the CPU implementation's included): what the pass costs on a
    // CPU device even when other processes share the cores.
    std::optional<double> cpuMilliseconds;
    // Builder::skip(): the pass recorded nothing this frame; its times are
    // 0 wherever passes were timed.
    bool skipped = false;
};

// How per-pass times are taken.
// - GpuTimestamps: a timestamp pair around each pass; the frame runs as the
//   plan batches it. What a GPU is measured with.
// - HostSerial: each pass is submitted alone and waited for; its time is the
//   host's wall time from submission to idle. For CPU implementations
//   (lavapipe), whose timestamps do not cover compute dispatches; it
//   serialises the queues (no async overlap) and adds one submission's
//   overhead (tens of microseconds) to every pass.
enum class PassTimer : uint8_t { GpuTimestamps, HostSerial };

// A chain of passes timed as one: from the start of the first pass (in
// submission order) whose name `member` accepts to the end of the last one,
// everything between included (barriers, idle gaps, passes that are not
// members). Members skipped this frame (Builder::skip) do not count: the
// span runs from the first member that is recorded to the last; none, no
// span. All members must run on one queue. With GPU timestamps it is
// one timestamp pair; host-serial, the host's wall time from the first
// submission of the span's commands to the queue's idle after its last
// (the span's passes are then submitted together, per batch, not alone).
struct TimedSpan {
    std::string name;
    std::function<bool(std::string_view pass)> member;
};

struct ExecutorStats {
    uint64_t frames = 0;
    uint32_t transientRebuilds = 0;  // times the transient memory was (re)created
    uint64_t transientBytes = 0;     // bytes of the current transient heaps
    // Command buffers held by the frames' pools: as many as the busiest
    // frame of each slot needed, flat over a steady frame loop.
    uint32_t commandBuffers = 0;
};

class Executor {
public:
    explicit Executor(gpu::Context& gpu, uint32_t framesInFlight = 2);
    ~Executor();
    Executor(const Executor&) = delete;
    Executor& operator=(const Executor&) = delete;

    QueueCaps queueCaps() const { return queueCapsOf(gpu_.caps()); }
    // Compile options whose memory sizes are the driver's. Each distinct
    // transient description is asked about once and the answer kept (a frame
    // loop compiles the same descriptions every frame); the options must not
    // outlive the executor.
    CompileOptions compileOptions(bool aliasing = true) const;

    // Records and submits one frame of `plan`. Passes the declaration
    // skips (Builder::skip) run no execute callback; their barriers are
    // carried on to the next pass that runs (rg::skipPasses).
    SubmittedFrame run(const Plan& plan, const FrameResources& imports = {});
    // Off: a skipped pass's barriers stay where the plan put them, each its
    // own call (the executor still records no execute callback for it):
    // what carrying them saves, measured (default on).
    void setCarrySkippedBarriers(bool carry) { carrySkippedBarriers_ = carry; }
    // Waits for every submitted frame.
    void waitIdle();
    // Waits until `frame`'s work is done on every queue (its semaphore
    // waits included, so a binary semaphore it waited on may be reused).
    void wait(const SubmittedFrame& frame) const;
    bool finished(const SubmittedFrame& frame) const;
    // Per-pass GPU times of the most recent frame that has completed, in
    // submission order (after waitIdle(): the last frame run).
    std::vector<PassTiming> timings() const;
    const ExecutorStats& stats() const { return stats_; }
    void setPassTimer(PassTimer timer) { passTimer_ = timer; }
    PassTimer passTimer() const { return passTimer_; }
    // Times `span` in every frame run from now on (none: no span). With
    // `perPass` false the passes themselves are not timed (timings() then
    // gives no milliseconds): per-pass timestamps add a drain of the queue
    // at every pass boundary, which the span should not pay.
    void setTimedSpan(std::optional<TimedSpan> span, bool perPass = true);
    // The span's time in the frame timings() reads (none: no span, no
    // member pass in that frame, or no timestamps on the queue).
    std::optional<double> spanTiming() const;

private:
    friend class PassContext;
    struct Physical {
        const gpu::Image* image = nullptr;
        const gpu::Buffer* buffer = nullptr;
        const gpu::AccelerationStructure* accel = nullptr;
    };
    struct Transients;
    struct History;
    struct FrameSlot;
    struct RequirementsCache;

    void prepareTransients(const Plan& plan);
    void prepareHistory(const Plan& plan);
    void bindResources(const Plan& plan, const FrameResources& imports);
    void bindUploads(const Plan& plan, FrameSlot& slot);
    void recordBarriers(VkCommandBuffer cmd, const Plan& plan, std::span<const Barrier> barriers) const;
    struct ExternalSync;
    ExternalSync placeSemaphores(const Plan& plan, const FrameResources& imports) const;
    const gpu::Queue& queueOf(Queue q) const;
    const Physical& physical(uint32_t resource, std::string_view pass) const;

    gpu::Context& gpu_;
    uint32_t framesInFlight_;
    uint64_t frame_ = 0;
    gpu::TimelineSemaphore timelines_[kQueueCount];
    uint64_t lastSignal_[kQueueCount] = {0, 0};
    uint64_t previousBase_[kQueueCount] = {0, 0};  // timeline value before the previous frame's batches
    std::vector<std::unique_ptr<FrameSlot>> slots_;
    std::unique_ptr<Transients> transients_;
    std::unique_ptr<RequirementsCache> requirements_; // compileOptions()' answers by description
    std::map<std::string, std::unique_ptr<History>> history_;
    // Per declaration resource of the plan being run.
    std::vector<Physical> physical_;
    std::vector<std::string> resourceNames_;
    const FrameSlot* lastCompletedSlot() const;

    ExecutorStats stats_;
    PassTimer passTimer_ = PassTimer::GpuTimestamps;
    std::optional<TimedSpan> span_;
    bool perPassTiming_ = true;
    bool carrySkippedBarriers_ = true;
};

}  // namespace glint::rg
