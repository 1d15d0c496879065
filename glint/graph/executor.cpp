// The render graph's executor: one frame of a Plan recorded and submitted
// (its barriers, the timeline waits between queues, the caller's
// semaphores), per-pass and span timing, and what a pass's execute sees
// (PassContext). The resources a frame runs on are made ready in
// executor_resources.cpp.

#include "glint/graph/executor.h"
#include "glint/graph/executor_internal.h"
#include "glint/graph/skip.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <ctime>

namespace glint::rg {

namespace {

double processCpuMilliseconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

} // namespace

QueueCaps queueCapsOf(const gpu::Capabilities& caps) {
    QueueCaps q;
    q.separateComputeFamily = caps.computeFamily.has_value();
    q.graphicsFamily = caps.graphicsFamily;
    q.computeFamily = caps.computeFamily.value_or(caps.graphicsFamily);
    q.rayQuery = caps.rayQuery;
    q.rayTracingPipeline = caps.rayTracingPipeline;
    q.bufferImageGranularity = caps.bufferImageGranularity;
    return q;
}

// ---------------------------------------------------------------- FrameResources

void FrameResources::bind(Texture handle, const gpu::Image& image) { images_[handle.index] = &image; }
void FrameResources::bind(Buffer handle, const gpu::Buffer& buffer) { buffers_[handle.index] = &buffer; }
void FrameResources::bind(AccelStruct handle, const gpu::AccelerationStructure& accel) {
    accels_[handle.index] = &accel;
}

void FrameResources::waitSemaphore(Texture image, VkSemaphore semaphore, VkPipelineStageFlags2 stages,
                                   uint64_t value) {
    waits_.push_back({image.index, ResourceKind::Texture, semaphore, stages, value});
}
void FrameResources::waitSemaphore(VkSemaphore semaphore, VkPipelineStageFlags2 stages, uint64_t value) {
    waits_.push_back({kNoIndex, ResourceKind::Texture, semaphore, stages, value});
}
void FrameResources::signalSemaphore(Texture image, VkSemaphore semaphore, uint64_t value) {
    signals_.push_back({image.index, ResourceKind::Texture, semaphore, kSemaphoreSignalStages, value});
}
void FrameResources::signalSemaphore(Buffer buffer, VkSemaphore semaphore, uint64_t value) {
    signals_.push_back({buffer.index, ResourceKind::Buffer, semaphore, kSemaphoreSignalStages, value});
}
void FrameResources::signalSemaphore(VkSemaphore semaphore, uint64_t value) {
    signals_.push_back({kNoIndex, ResourceKind::Texture, semaphore, kSemaphoreSignalStages, value});
}

// ---------------------------------------------------------------- internal state

struct Executor::FrameSlot {
    gpu::CommandPool pools[kQueueCount];
    gpu::TimestampQueries timer;
    uint64_t frame = 0;
    bool used = false;
    uint64_t endValue[kQueueCount] = {0, 0};  // timeline values that mark this frame done
    std::vector<PassTiming> passes;            // names and queues, in query-pair order
    bool hostTimed = false;                    // passes[].milliseconds are host times already
    // The TimedSpan: its query pair (after the passes'), whether this frame
    // had a member, and (host-serial) its time.
    uint32_t spanPair = 0;
    bool spanRecorded = false;
    std::optional<double> spanMilliseconds;
    // The buffers of the frames' uploads (Graph::uploadBuffer), host-visible
    // and rewritten whenever the slot is reused: by the upload's name (and
    // its count among this frame's uploads of that name), each of a power
    // of two of at least 256 bytes that only grows. So a frame of another
    // mode or with a few more particles reuses them, and the memory they
    // hold stops growing once every frame's kinds have run. A name no frame
    // of the last kUploadKeepFrames used is let go.
    struct Uploads {
        std::vector<std::unique_ptr<gpu::Buffer>> buffers;
        uint64_t lastFrame = 0;
        uint32_t usedInLastFrame = 0;  // buffers taken by lastFrame's uploads of the name
    };
    std::map<std::string, Uploads, std::less<>> uploads;
};

namespace {

constexpr uint64_t kUploadKeepFrames = 64;

} // namespace

// ---------------------------------------------------------------- Executor

void Executor::bindUploads(const Plan& plan, FrameSlot& slot) {
    const ir::Declaration& decl = *plan.declaration;
    for (const ir::Declaration::Upload& u : decl.uploads) {
        const PlannedResource& r = plan.resources[u.resource];
        if (!r.used) continue;
        const std::string_view name = decl.resources[u.resource].name;
        auto list = slot.uploads.find(name);
        if (list == slot.uploads.end()) list = slot.uploads.emplace(std::string(name), FrameSlot::Uploads{}).first;
        FrameSlot::Uploads& kept = list->second;
        if (kept.lastFrame != frame_) {
            kept.lastFrame = frame_;
            kept.usedInLastFrame = 0;
        }
        const uint32_t k = kept.usedInLastFrame++;
        if (kept.buffers.size() <= k) kept.buffers.resize(k + 1);
        std::unique_ptr<gpu::Buffer>& buffer = kept.buffers[k];
        // Any usage a reader may need; the readers take only the bytes
        // they declared (a constants block, a readback of the declared size).
        const VkBufferUsageFlags usage = r.bufferUsage | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                         VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
        if (!buffer || buffer->size() < u.size || (buffer->desc().usage & usage) != usage) {
            // run() waited for the frame that used this slot last.
            const VkDeviceSize capacity = std::bit_ceil(std::max<VkDeviceSize>(u.size, 256));
            buffer = std::make_unique<gpu::Buffer>(
                gpu_, gpu::BufferDesc{capacity, usage, gpu::MemoryUsage::Upload, "rg.upload." + std::string(name), true});
        }
        std::memcpy(buffer->mapped(), decl.uploadBytes.data() + u.offset, u.size);
        physical_[u.resource].buffer = buffer.get();
    }
    // Every frame that used this slot before has finished (run() waited).
    std::erase_if(slot.uploads, [&](const auto& entry) { return frame_ - entry.second.lastFrame > kUploadKeepFrames; });
}

Executor::Executor(gpu::Context& gpu, uint32_t framesInFlight)
    : gpu_(gpu), framesInFlight_(std::max(framesInFlight, 1u)), requirements_(std::make_unique<RequirementsCache>()) {
    timelines_[0] = gpu::TimelineSemaphore(gpu_, "rg.timeline.graphics");
    timelines_[1] = gpu::TimelineSemaphore(gpu_, "rg.timeline.compute");
    for (uint32_t i = 0; i < framesInFlight_; ++i) {
        auto slot = std::make_unique<FrameSlot>();
        slot->pools[0] = gpu::CommandPool(gpu_, gpu_.graphicsQueue().family, "rg.frame" + std::to_string(i) + ".graphics");
        slot->pools[1] = gpu::CommandPool(gpu_, gpu_.computeQueue().family, "rg.frame" + std::to_string(i) + ".compute");
        slots_.push_back(std::move(slot));
    }
}

Executor::~Executor() {
    try {
        waitIdle();
    } catch (const std::exception& e) {
        spdlog::warn("render graph: releasing its objects without the GPU idle: {}", e.what());
    }
}

const gpu::Queue& Executor::queueOf(Queue q) const {
    return q == Queue::AsyncCompute ? gpu_.computeQueue() : gpu_.graphicsQueue();
}

void Executor::waitIdle() {
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        timelines_[q].wait(lastSignal_[q]);
    }
}

void Executor::recordBarriers(VkCommandBuffer cmd, const Plan& plan, std::span<const Barrier> barriers) const {
    if (barriers.empty()) {
        return;
    }
    std::vector<VkImageMemoryBarrier2> images;
    std::vector<VkBufferMemoryBarrier2> buffers;
    std::vector<VkMemoryBarrier2> memory;
    for (const Barrier& b : barriers) {
        const PlannedResource& r = plan.resources[b.resource];
        const Physical& p = physical_[b.resource];
        if (b.aliasing || r.kind == ResourceKind::AccelStruct) {
            // Accesses through an aliased resource, or to an acceleration
            // structure (no object barrier exists for those), need a global one.
            VkMemoryBarrier2 m{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
            m.srcStageMask = b.srcStages;
            m.srcAccessMask = b.srcAccess;
            m.dstStageMask = b.dstStages;
            m.dstAccessMask = b.dstAccess;
            memory.push_back(m);
        }
        if (r.kind == ResourceKind::Texture) {
            VkImageMemoryBarrier2 i{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
            i.srcStageMask = b.srcStages;
            i.srcAccessMask = b.srcAccess;
            i.dstStageMask = b.dstStages;
            i.dstAccessMask = b.dstAccess;
            i.oldLayout = b.oldLayout;
            i.newLayout = b.newLayout;
            i.srcQueueFamilyIndex = i.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            i.image = p.image->handle();
            i.subresourceRange = {b.aspect, b.range.baseMip, b.range.mipCount, b.range.baseLayer, b.range.layerCount};
            images.push_back(i);
        } else if (r.kind == ResourceKind::Buffer) {
            VkBufferMemoryBarrier2 m{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
            m.srcStageMask = b.srcStages;
            m.srcAccessMask = b.srcAccess;
            m.dstStageMask = b.dstStages;
            m.dstAccessMask = b.dstAccess;
            m.srcQueueFamilyIndex = m.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            m.buffer = p.buffer->handle();
            m.offset = 0;
            m.size = VK_WHOLE_SIZE;
            buffers.push_back(m);
        }
    }
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = static_cast<uint32_t>(memory.size());
    dep.pMemoryBarriers = memory.data();
    dep.bufferMemoryBarrierCount = static_cast<uint32_t>(buffers.size());
    dep.pBufferMemoryBarriers = buffers.data();
    dep.imageMemoryBarrierCount = static_cast<uint32_t>(images.size());
    dep.pImageMemoryBarriers = images.data();
    vkCmdPipelineBarrier2(cmd, &dep);
}

// The caller's semaphores, placed on the plan's batches (indexed like
// Plan::batches); `unplaced` when the plan has no batch at all.
struct Executor::ExternalSync {
    std::vector<std::vector<VkSemaphoreSubmitInfo>> waits;
    std::vector<std::vector<VkSemaphoreSubmitInfo>> signals;
    std::vector<VkSemaphoreSubmitInfo> unplacedWaits;
    std::vector<VkSemaphoreSubmitInfo> unplacedSignals;
};

Executor::ExternalSync Executor::placeSemaphores(const Plan& plan, const FrameResources& imports) const {
    ExternalSync out;
    if (imports.waits_.empty() && imports.signals_.empty()) {
        return out;
    }
    out.waits.resize(plan.batches.size());
    out.signals.resize(plan.batches.size());
    const auto& decl = *plan.declaration;
    const auto imported = [&](uint32_t r, ResourceKind kind, const char* what) -> const ir::Resource& {
        if (r >= decl.resources.size() || decl.resources[r].kind != kind ||
            decl.resources[r].origin != ir::Origin::Imported) {
            throw gpu::GpuError(std::string("render graph: FrameResources::") + what + " names a " +
                                (kind == ResourceKind::Buffer ? "buffer" : "texture") +
                                " that is not an import of this plan");
        }
        return decl.resources[r];
    };
    const auto info = [](const FrameResources::SemaphoreUse& u, VkPipelineStageFlags2 stages) {
        VkSemaphoreSubmitInfo i{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        i.semaphore = u.semaphore;
        i.value = u.value;
        i.stageMask = stages;
        return i;
    };
    const uint32_t lastBatch = plan.batches.empty() ? kNoIndex : static_cast<uint32_t>(plan.batches.size() - 1);

    for (const FrameResources::SemaphoreUse& w : imports.waits_) {
        uint32_t batch = plan.batches.empty() ? kNoIndex : 0;
        VkPipelineStageFlags2 stages = w.stages;
        if (w.resource != kNoIndex) {
            const ir::Resource& res = imported(w.resource, w.kind, "waitSemaphore");
            const Plan::WaitPoint point = plan.firstUseOf(w.resource);
            if (point.batch != kNoIndex) batch = point.batch;
            if (stages == 0) {
                if (!res.hasInitial || boundaryScope(res.initial, ResourceKind::Texture).stages == 0) {
                    throw gpu::GpuError("render graph: '" + std::string(res.name) +
                                        "' waits on a semaphore, but its initial state names no stage, so its first "
                                        "layout transition would not wait for it: import it with "
                                        "BoundaryState::acquired(stages of its first use)");
                }
                stages = point.stages;
            }
        }
        if (stages == 0) {
            throw gpu::GpuError("render graph: FrameResources::waitSemaphore without a stage mask");
        }
        (batch == kNoIndex ? out.unplacedWaits : out.waits[batch]).push_back(info(w, stages));
    }

    for (const FrameResources::SemaphoreUse& sg : imports.signals_) {
        uint32_t batch = lastBatch;
        if (sg.resource != kNoIndex) {
            imported(sg.resource, sg.kind, "signalSemaphore");
            if (const uint32_t ending = plan.batchEnding(sg.resource); ending != kNoIndex) batch = ending;
        }
        (batch == kNoIndex ? out.unplacedSignals : out.signals[batch]).push_back(info(sg, sg.stages));
    }
    return out;
}

namespace {

// "passes 'a' to 'b' (n)", or "pass 'a'": what a failed submission held.
std::string batchPassNames(const Plan& plan, const Batch& batch) {
    const auto passes = plan.passesOf(batch);
    if (passes.empty()) return "no passes";
    const std::string first(plan.passName(passes.front()));
    if (passes.size() == 1) return "pass '" + first + "'";
    return "passes '" + first + "' to '" + std::string(plan.passName(passes.back())) + "' (" +
           std::to_string(passes.size()) + ")";
}

// vkQueueWaitIdle; throws naming `what` the host waited for.
void queueWaitIdle(gpu::Context& gpu, VkQueue queue, const std::string& what) {
    VkResult result = vkQueueWaitIdle(queue);
    if (result == VK_SUCCESS) result = gpu.faults().next(gpu::FaultSite::Wait);
    gpu::check(result, "vkQueueWaitIdle (render graph, " + what + ")");
}

} // namespace

void Executor::wait(const SubmittedFrame& frame) const {
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        if (frame.timelineValue[q] != 0) timelines_[q].wait(frame.timelineValue[q]);
    }
}

bool Executor::finished(const SubmittedFrame& frame) const {
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        if (frame.timelineValue[q] != 0 && timelines_[q].value() < frame.timelineValue[q]) return false;
    }
    return true;
}

SubmittedFrame Executor::run(const Plan& declared, const FrameResources& imports) {
    if (!declared.declaration) {
        throw gpu::GpuError("render graph: run() got an empty Plan");
    }
    // Passes skipped this frame (Builder::skip): recorded without their
    // execute callbacks, their barriers carried on and merged (skip.h).
    // The caller's semaphores go where the declared plan puts them: the
    // batches are the same.
    std::optional<Plan> carried;
    if (carrySkippedBarriers_ && hasSkippedPasses(declared)) {
        carried = skipPasses(declared);
        if (spdlog::should_log(spdlog::level::debug)) {
            const auto skipped = std::count_if(carried->passes.begin(), carried->passes.end(),
                                               [](const PlannedPass& p) { return p.skipped; });
            spdlog::debug("render graph frame {}: {} passes skipped, barrier calls {} -> {}", frame_, skipped,
                          declared.barrierCallCount(), carried->barrierCallCount());
        }
    }
    const Plan& plan = carried ? *carried : declared;
    const QueueCaps caps = queueCaps();
    if (plan.caps.separateComputeFamily != caps.separateComputeFamily) {
        throw gpu::GpuError(std::string("render graph: the plan was compiled for ") +
                            (plan.caps.separateComputeFamily ? "two queues" : "one queue") + " but device '" +
                            gpu_.caps().deviceName + "' has " + (caps.separateComputeFamily ? "two" : "one"));
    }

    // ---- the slot of this frame: wait for the frame that used it last
    FrameSlot& slot = *slots_[frame_ % framesInFlight_];
    if (slot.used) {
        try {
            for (uint32_t q = 0; q < kQueueCount; ++q) {
                timelines_[q].wait(slot.endValue[q]);
            }
        } catch (const gpu::GpuError& e) {
            throw gpu::GpuError("render graph: waiting for frame " + std::to_string(slot.frame) +
                                " to finish before frame " + std::to_string(frame_) + " reuses its command buffers: " +
                                e.what());
        }
    }
    slot.pools[0].reset();
    slot.pools[1].reset();
    // One pair per pass, and the span's after them.
    const uint32_t pairsNeeded = static_cast<uint32_t>(plan.passes.size()) + 1;
    if (slot.timer.pairCount() < pairsNeeded) {
        slot.timer = gpu::TimestampQueries(gpu_, std::max<uint32_t>(pairsNeeded, 32));
    }
    slot.timer.reset();
    slot.passes.clear();
    slot.frame = frame_;
    slot.used = true;
    slot.hostTimed = passTimer_ == PassTimer::HostSerial;
    slot.spanPair = pairsNeeded - 1;
    slot.spanRecorded = false;
    slot.spanMilliseconds.reset();

    // The span's first and last member passes that run, in submission
    // order. A skipped member records nothing: a span that began at it
    // would take in the next pass's barrier call, which a frame without
    // that member (or with it running) leaves before the span.
    const PlannedPass* spanFirst = nullptr;
    const PlannedPass* spanLast = nullptr;
    if (span_) {
        for (const Batch& batch : plan.batches) {
            for (const PlannedPass& p : plan.passesOf(batch)) {
                if (!span_->member(plan.passName(p)) || plan.declaration->passes[p.pass].skipped) continue;
                if (spanFirst && p.queue != spanFirst->queue) {
                    throw gpu::GpuError("render graph: timed span '" + span_->name + "' has passes on two queues ('" +
                                        std::string(plan.passName(*spanFirst)) + "' and '" + std::string(plan.passName(p)) + "')");
                }
                if (!spanFirst) spanFirst = &p;
                spanLast = &p;
            }
        }
    }
    const bool perPass = perPassTiming_ || !spanFirst;

    prepareTransients(plan);
    prepareHistory(plan);
    bindResources(plan, imports);
    bindUploads(plan, slot);
    const ExternalSync external = placeSemaphores(declared, imports);

    // ---- timeline values: this frame's batches count up from where the
    // previous frame ended on each queue (the plan may change between frames,
    // so values come from what was actually signalled, not from frame * n).
    uint64_t base[kQueueCount] = {lastSignal_[0], lastSignal_[1]};
    uint64_t previousEnd[kQueueCount] = {lastSignal_[0], lastSignal_[1]};

    PassContext ctx(*this, gpu_);
    ctx.frame_ = frame_;
    const bool hostTimed = passTimer_ == PassTimer::HostSerial;
    // A host-timed span: between its first pass and its last, and when its
    // commands were first submitted.
    bool inSpan = false;
    bool spanSubmitted = false;
    std::chrono::steady_clock::time_point spanStart;
    for (uint32_t batchIndex = 0; batchIndex < plan.batches.size(); ++batchIndex) {
        const Batch& batch = plan.batches[batchIndex];
        const uint32_t qi = static_cast<uint32_t>(batch.queue);
        const VkQueue queue = queueOf(batch.queue).queue;
        ctx.queue_ = batch.queue;

        std::vector<VkSemaphoreSubmitInfo> waits;
        for (const SemaphoreWait& w : plan.waitsOf(batch)) {
            const uint32_t wq = static_cast<uint32_t>(w.queue);
            uint64_t value = 0;
            if (w.frameOffset == 0) {
                value = base[wq] + w.batch + 1;
            } else {
                if (frame_ == 0) {
                    continue;  // no previous frame to wait for
                }
                // The previous frame's batch `w.batch`, never past its end
                // (its plan may have had fewer batches); or the queue's
                // last signal, whichever frame gave it.
                value = w.batch == SemaphoreWait::kLastSignalled
                            ? previousEnd[wq]
                            : std::min(previousBase_[wq] + w.batch + 1, previousEnd[wq]);
                if (value == 0) {
                    continue;  // that queue has signalled nothing yet
                }
            }
            VkSemaphoreSubmitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
            info.semaphore = timelines_[wq].handle();
            info.value = value;
            info.stageMask = w.stages;
            waits.push_back(info);
        }
        // The queue's timeline first, then the caller's semaphores placed here.
        const uint64_t signalValue = base[qi] + batch.ordinal + 1;
        std::vector<VkSemaphoreSubmitInfo> signals(1, {VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO});
        signals[0].semaphore = timelines_[qi].handle();
        signals[0].value = signalValue;
        signals[0].stageMask = kSemaphoreSignalStages;
        if (!external.waits.empty()) {
            waits.insert(waits.end(), external.waits[batchIndex].begin(), external.waits[batchIndex].end());
            signals.insert(signals.end(), external.signals[batchIndex].begin(), external.signals[batchIndex].end());
        }

        // One command buffer per batch; with host-timed passes, one per pass
        // (the batch's waits on the first, its signal on the last), or with
        // a host-timed span and no per-pass times, one before the span, one
        // for its part in this batch and one after it.
        VkCommandBuffer cmd = VK_NULL_HANDLE;
        bool first = true;
        const auto begin = [&] {
            cmd = slot.pools[qi].allocate();
            VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
            gpu::check(vkBeginCommandBuffer(cmd, &info), "vkBeginCommandBuffer (render graph)");
            ctx.cmd_ = cmd;
        };
        const auto submit = [&](bool last) {
            gpu::check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer (render graph)");
            VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
            cmdInfo.commandBuffer = cmd;
            VkSubmitInfo2 info{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
            if (first) {
                info.waitSemaphoreInfoCount = static_cast<uint32_t>(waits.size());
                info.pWaitSemaphoreInfos = waits.data();
            }
            info.commandBufferInfoCount = 1;
            info.pCommandBufferInfos = &cmdInfo;
            if (last) {
                info.signalSemaphoreInfoCount = static_cast<uint32_t>(signals.size());
                info.pSignalSemaphoreInfos = signals.data();
            }
            if (inSpan && !spanSubmitted) {
                spanStart = std::chrono::steady_clock::now();
                spanSubmitted = true;
            }
            VkResult result = gpu_.faults().next(gpu::FaultSite::Submit);
            if (result == VK_SUCCESS) result = vkQueueSubmit2(queue, 1, &info, VK_NULL_HANDLE);
            gpu::check(result, "vkQueueSubmit2 (render graph frame " + std::to_string(frame_) + ", " +
                                   std::string(toString(batch.queue)) + " batch " + std::to_string(batch.ordinal) +
                                   ": " + batchPassNames(plan, batch) + ")");
            first = false;
        };

        // Host-serial passes submitted alone, each waited for.
        const bool alone = hostTimed && perPass;
        if (!alone) {
            begin();
        }
        const auto batchPasses = plan.passesOf(batch);
        for (size_t k = 0; k < batchPasses.size(); ++k) {
            const PlannedPass& p = batchPasses[k];
            const bool lastPass = k + 1 == batchPasses.size();
            if (alone) {
                begin();
            } else if (hostTimed && &p == spanFirst) {
                // The span starts on an idle queue: what precedes it goes first.
                submit(false);
                queueWaitIdle(gpu_, queue, "before timed span '" + span_->name + "'");
                begin();
                inSpan = true;
            }
            recordBarriers(cmd, plan, plan.barriersBefore(p));
            ctx.name_ = plan.passName(p);
            ctx.plan_ = &plan;
            ctx.pass_ = &p;
            const uint32_t pair = p.timestampQuery / 2;
            if (slot.passes.size() <= pair) {
                slot.passes.resize(pair + 1);
            }
            // A skipped pass records nothing and takes no time: no
            // timestamps of its own (two around nothing still read a few
            // tenths of a microsecond), 0 ms wherever passes are timed.
            const bool skipped = plan.declaration->passes[p.pass].skipped;
            slot.passes[pair] = {ctx.name_, p.queue, std::nullopt, frame_};
            slot.passes[pair].skipped = skipped;
            if (skipped && perPass && !hostTimed) slot.passes[pair].milliseconds = 0.0;
            {
                gpu::ScopedLabel label(gpu_, cmd, ctx.name_);
                // ALL_COMMANDS: written once every earlier command of the queue
                // is done, so a pass is timed from when it can start, not from
                // when the command processor reached it while earlier passes
                // were still draining (a TOP_OF_PIPE start charges their tail
                // to this pass: a 2 MB clear read 0.8 ms on an H200).
                if (!hostTimed && &p == spanFirst) {
                    slot.timer.begin(cmd, slot.spanPair, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT);
                    slot.spanRecorded = true;
                }
                if (!hostTimed && perPass && !skipped) {
                    slot.timer.begin(cmd, pair, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT);
                }
                if (const ExecuteFn& execute = plan.execute(p); execute && !skipped) {
                    execute(ctx);
                }
                if (!hostTimed && perPass && !skipped) {
                    slot.timer.end(cmd, pair);
                }
                if (!hostTimed && &p == spanLast) {
                    slot.timer.end(cmd, slot.spanPair);
                }
            }
            if (hostTimed && !alone && &p == spanLast) {
                // The span's last commands: submitted and waited for; the
                // span ran from its first submission to here.
                if (lastPass) {
                    recordBarriers(cmd, plan, plan.barriersAfter(batch));
                }
                submit(lastPass);
                queueWaitIdle(gpu_, queue, "timed span '" + span_->name + "'");
                slot.spanMilliseconds =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - spanStart).count();
                slot.spanRecorded = true;
                inSpan = false;
                if (!lastPass) {
                    begin();
                } else {
                    cmd = VK_NULL_HANDLE;
                }
            }
            if (alone) {
                if (lastPass) {
                    recordBarriers(cmd, plan, plan.barriersAfter(batch));
                }
                // Everything earlier has finished (each submission is waited
                // for), so this submission's wall time is the pass's own.
                const auto start = std::chrono::steady_clock::now();
                const double cpuStart = processCpuMilliseconds();
                submit(lastPass);
                queueWaitIdle(gpu_, queue, "host-timed pass '" + ctx.name_ + "'");
                slot.passes[pair].milliseconds =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                slot.passes[pair].cpuMilliseconds = processCpuMilliseconds() - cpuStart;
                if (skipped) {
                    // What was measured is an empty submission's overhead.
                    slot.passes[pair].milliseconds = 0.0;
                    slot.passes[pair].cpuMilliseconds = 0.0;
                }
            }
        }
        if (!alone && cmd != VK_NULL_HANDLE) {
            recordBarriers(cmd, plan, plan.barriersAfter(batch));
            submit(true);
        } else if (alone && batchPasses.empty()) {
            begin();
            recordBarriers(cmd, plan, plan.barriersAfter(batch));
            submit(true);
        }
        lastSignal_[qi] = std::max(lastSignal_[qi], signalValue);
        // Kept up to date batch by batch: if a later submission fails, the
        // slot's next use still waits for what this frame did submit.
        slot.endValue[qi] = lastSignal_[qi];
    }
    if (!external.unplacedWaits.empty() || !external.unplacedSignals.empty()) {
        // No batch to carry them: a submission of their own keeps the
        // caller's semaphores balanced (an acquire waited, a present signalled).
        VkSubmitInfo2 info{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        info.waitSemaphoreInfoCount = static_cast<uint32_t>(external.unplacedWaits.size());
        info.pWaitSemaphoreInfos = external.unplacedWaits.data();
        info.signalSemaphoreInfoCount = static_cast<uint32_t>(external.unplacedSignals.size());
        info.pSignalSemaphoreInfos = external.unplacedSignals.data();
        VkResult result = gpu_.faults().next(gpu::FaultSite::Submit);
        if (result == VK_SUCCESS) result = vkQueueSubmit2(gpu_.graphicsQueue().queue, 1, &info, VK_NULL_HANDLE);
        gpu::check(result, "vkQueueSubmit2 (render graph, semaphores of an empty plan)");
    }
    SubmittedFrame submitted;
    submitted.frame = frame_;
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        previousBase_[q] = base[q];
        slot.endValue[q] = lastSignal_[q];
        submitted.timelineValue[q] = lastSignal_[q];
    }
    ++frame_;
    ++stats_.frames;
    stats_.commandBuffers = 0;
    for (const auto& s : slots_)
        for (const gpu::CommandPool& pool : s->pools) stats_.commandBuffers += uint32_t(pool.allocatedCount());
    return submitted;
}

void Executor::setTimedSpan(std::optional<TimedSpan> span, bool perPass) {
    if (span && !span->member) {
        throw gpu::GpuError("render graph: timed span '" + span->name + "' has no member test");
    }
    span_ = std::move(span);
    perPassTiming_ = perPass;
}

std::optional<double> Executor::spanTiming() const {
    const FrameSlot* slot = lastCompletedSlot();
    if (!slot || !slot->spanRecorded) return std::nullopt;
    if (slot->hostTimed) return slot->spanMilliseconds;
    const auto ms = slot->timer.readMilliseconds();
    return slot->spanPair < ms.size() ? ms[slot->spanPair] : std::nullopt;
}

const Executor::FrameSlot* Executor::lastCompletedSlot() const {
    // The newest slot whose frame is complete on every queue.
    const FrameSlot* best = nullptr;
    for (const auto& s : slots_) {
        if (!s->used) continue;
        bool done = true;
        for (uint32_t q = 0; q < kQueueCount; ++q) {
            done = done && timelines_[q].value() >= s->endValue[q];
        }
        if (done && (!best || s->frame > best->frame)) {
            best = s.get();
        }
    }
    return best;
}

std::vector<PassTiming> Executor::timings() const {
    const FrameSlot* best = lastCompletedSlot();
    if (!best) {
        return {};
    }
    std::vector<PassTiming> out = best->passes;
    if (best->hostTimed) {
        return out;
    }
    const auto ms = best->timer.readMilliseconds();
    for (size_t i = 0; i < out.size() && i < ms.size(); ++i) {
        if (!out[i].skipped) out[i].milliseconds = ms[i];
        out[i].frame = best->frame;
    }
    return out;
}

// ---------------------------------------------------------------- PassContext

const Executor::Physical& Executor::physical(uint32_t resource, std::string_view pass) const {
    if (resource >= physical_.size()) {
        throw gpu::GpuError("render graph: pass '" + std::string(pass) + "' asked for a resource not in this plan");
    }
    return physical_[resource];
}

const gpu::Image& PassContext::image(Texture handle) const {
    const auto& p = executor_.physical(handle.index, name_);
    if (!p.image) {
        throw gpu::GpuError("render graph: pass '" + name_ + "' asked for texture '" +
                            executor_.resourceNames_[handle.index] + "', which has no image this frame (culled?)");
    }
    return *p.image;
}

const gpu::Buffer& PassContext::buffer(Buffer handle) const {
    const auto& p = executor_.physical(handle.index, name_);
    if (!p.buffer) {
        throw gpu::GpuError("render graph: pass '" + name_ + "' asked for buffer '" +
                            executor_.resourceNames_[handle.index] + "', which has no buffer this frame (culled?)");
    }
    return *p.buffer;
}

const gpu::AccelerationStructure& PassContext::accel(AccelStruct handle) const {
    const auto& p = executor_.physical(handle.index, name_);
    if (!p.accel) {
        throw gpu::GpuError("render graph: pass '" + name_ + "' asked for acceleration structure '" +
                            executor_.resourceNames_[handle.index] + "', which is not bound this frame");
    }
    return *p.accel;
}

VkImageLayout PassContext::layout(Texture handle) const {
    for (const ir::Use& use : plan_->uses(*pass_)) {
        if (use.resource == handle.index) {
            return accessScope(use.kinds, ResourceKind::Texture, plan_->pipeline(*pass_)).layout;
        }
    }
    const std::string name = handle.index < executor_.resourceNames_.size() ? executor_.resourceNames_[handle.index]
                                                                            : std::string("(invalid handle)");
    throw gpu::GpuError("render graph: pass '" + name_ + "' asked for the layout of texture '" + name +
                        "', which it did not declare");
}

void PassContext::dispatch(const gpu::Pipeline& pipeline, uint32_t x, uint32_t y, uint32_t z) const {
    pipeline.bind(cmd_);
    vkCmdDispatch(cmd_, x, y, z);
}

void PassContext::dispatchIndirect(const gpu::Pipeline& pipeline, Buffer args, VkDeviceSize offset) const {
    pipeline.bind(cmd_);
    vkCmdDispatchIndirect(cmd_, buffer(args).handle(), offset);
}

} // namespace glint::rg
