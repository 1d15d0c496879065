#include "glint/graph/executor.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <mutex>
#include <tuple>
#include <unordered_map>

namespace glint::rg {

namespace {

gpu::ImageDesc imageDescOf(const TextureDesc& t, VkImageUsageFlags usage, std::string name, bool shared) {
    gpu::ImageDesc d;
    d.width = t.width;
    d.height = t.height;
    d.depth = t.depth;
    d.mips = t.mips;
    d.layers = t.layers;
    d.format = t.format;
    d.usage = usage;
    d.name = std::move(name);
    d.sharedAcrossQueues = shared;
    return d;
}

gpu::BufferDesc bufferDescOf(const BufferDesc& b, VkBufferUsageFlags usage, std::string name, bool shared) {
    gpu::BufferDesc d;
    d.size = b.size;
    d.usage = usage;
    d.memory = gpu::MemoryUsage::DeviceLocal;
    d.name = std::move(name);
    d.sharedAcrossQueues = shared;
    return d;
}

double processCpuMilliseconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// The name of a history pair: its halves are "<name>.previous" and "<name>.current".
std::string historyName(const std::string& halfName) { return halfName.substr(0, halfName.rfind('.')); }

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
    waits_.push_back({image.index, semaphore, stages, value});
}
void FrameResources::waitSemaphore(VkSemaphore semaphore, VkPipelineStageFlags2 stages, uint64_t value) {
    waits_.push_back({kNoIndex, semaphore, stages, value});
}
void FrameResources::signalSemaphore(Texture image, VkSemaphore semaphore, uint64_t value) {
    signals_.push_back({image.index, semaphore, kSemaphoreSignalStages, value});
}
void FrameResources::signalSemaphore(VkSemaphore semaphore, uint64_t value) {
    signals_.push_back({kNoIndex, semaphore, kSemaphoreSignalStages, value});
}

// ---------------------------------------------------------------- internal state

// Transient memory and the resources placed in it. `key` is everything that,
// if changed, means the placement must be redone.
struct Executor::Transients {
    using Key = std::vector<std::tuple<uint32_t, std::string, uint32_t, uint32_t, uint32_t, uint32_t, uint32_t,
                                       uint32_t, uint64_t, uint64_t, uint32_t, uint64_t, bool>>;
    Key key;
    std::vector<gpu::Allocation> heaps;
    std::vector<std::unique_ptr<gpu::Image>> images;
    std::vector<std::unique_ptr<gpu::Buffer>> buffers;
    std::map<uint32_t, Physical> byResource;
    uint64_t bytes = 0;
};

struct Executor::History {
    ResourceKind kind = ResourceKind::Texture;
    std::unique_ptr<gpu::Image> images[2];
    std::unique_ptr<gpu::Buffer> buffers[2];
    uint32_t current = 0;  // which of the two is this frame's `current`
    bool flippedThisFrame = false;
    // What the pair was made from, and the layout each image was left in
    // by the last frame that used it: a later plan may expect others.
    TextureDesc texture;
    BufferDesc buffer;
    VkImageUsageFlags imageUsage = 0;
    VkBufferUsageFlags bufferUsage = 0;
    bool shared = false;
    VkImageLayout layout[2] = {VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_UNDEFINED};
    // The uses of both halves in the last plan (queue, access kinds, writes,
    // in plan order): barriers at a frame's start assume the previous frame
    // ended the way this plan ends, so another plan needs a full barrier.
    uint64_t useSignature = 0;
};

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
};

// ---------------------------------------------------------------- Executor

// The driver's memory requirements by transient description. Asking is a
// driver call (and a name copied into the description it takes) per
// transient per compile; the descriptions repeat frame after frame. Locked:
// plans may be compiled on several threads with one executor's options.
struct Executor::RequirementsCache {
    struct Key {
        ResourceKind kind;
        TextureDesc texture;      // textures only
        uint64_t bufferSize;      // buffers only
        VkFlags usage;            // image or buffer usage
        friend bool operator==(const Key&, const Key&) = default;
    };
    struct Hash {
        size_t operator()(const Key& k) const noexcept {
            uint64_t h = uint64_t(k.kind) * 0x9E3779B97F4A7C15ull;
            for (const uint64_t v : {uint64_t(k.texture.width) << 32 | k.texture.height,
                                     uint64_t(k.texture.depth) << 32 | k.texture.layers,
                                     uint64_t(k.texture.mips) << 32 | uint32_t(k.texture.format), k.bufferSize,
                                     uint64_t(k.usage)})
                h = (h ^ v) * 0x100000001B3ull + (h >> 29);
            return size_t(h);
        }
    };
    std::mutex mutex;
    std::unordered_map<Key, MemoryRequirements, Hash> answers;
};

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

CompileOptions Executor::compileOptions(bool aliasing) const {
    CompileOptions o;
    o.aliasing = aliasing;
    gpu::Context* gpu = &gpu_;
    RequirementsCache* cache = requirements_.get();
    o.memoryRequirements = [gpu, cache](const TransientDescription& d) {
        const bool texture = d.kind == ResourceKind::Texture;
        const RequirementsCache::Key key{d.kind, texture ? d.texture : TextureDesc{}, texture ? 0 : d.buffer.size,
                                         texture ? d.imageUsage : d.bufferUsage};
        {
            const std::lock_guard lock(cache->mutex);
            if (const auto it = cache->answers.find(key); it != cache->answers.end()) return it->second;
        }
        const VkMemoryRequirements r =
            texture ? gpu::Image::requirements(*gpu, imageDescOf(d.texture, d.imageUsage, std::string(d.name), false))
                    : gpu::Buffer::requirements(*gpu, bufferDescOf(d.buffer, d.bufferUsage, std::string(d.name), false));
        const MemoryRequirements answer{r.size, r.alignment, r.memoryTypeBits};
        const std::lock_guard lock(cache->mutex);
        cache->answers.emplace(key, answer);
        return answer;
    };
    return o;
}

const gpu::Queue& Executor::queueOf(Queue q) const {
    return q == Queue::AsyncCompute ? gpu_.computeQueue() : gpu_.graphicsQueue();
}

void Executor::waitIdle() {
    for (uint32_t q = 0; q < kQueueCount; ++q) {
        timelines_[q].wait(lastSignal_[q]);
    }
}

void Executor::prepareTransients(const Plan& plan) {
    const auto& decl = *plan.declaration;
    Transients::Key key;
    for (uint32_t i = 0; i < plan.resources.size(); ++i) {
        const PlannedResource& r = plan.resources[i];
        if (r.origin != ir::Origin::Transient || !r.used) {
            continue;
        }
        const ir::Resource& d = decl.resources[i];
        const uint32_t usage = r.kind == ResourceKind::Texture ? r.imageUsage : r.bufferUsage;
        key.emplace_back(i, d.name, uint32_t(r.kind), d.texture.width, d.texture.height,
                         d.texture.depth * 65536u + d.texture.layers, d.texture.mips * 65536u + uint32_t(d.texture.format),
                         usage, d.buffer.size, r.offset, r.heap, r.size, r.crossQueue);
    }
    for (const MemoryHeap& h : plan.heaps) {
        key.emplace_back(kNoIndex, "heap", uint32_t(h.queue), h.images, h.crossQueue, h.memoryTypeBits, 0, 0, h.size,
                         h.alignment, 0, 0, false);
    }
    if (transients_ && transients_->key == key) {
        return;
    }

    // The GPU may still use the old resources (frames in flight).
    waitIdle();
    auto t = std::make_unique<Transients>();
    t->key = std::move(key);
    for (uint32_t h = 0; h < plan.heaps.size(); ++h) {
        const MemoryHeap& heap = plan.heaps[h];
        // The plan keeps buffers and images inside a heap apart by
        // bufferImageGranularity; padding the heap to that granularity keeps
        // its edges apart from the allocator's neighbours too.
        const uint64_t granularity = std::max<uint64_t>(gpu_.caps().bufferImageGranularity, 1);
        const uint64_t alignment = std::max<uint64_t>({heap.alignment, granularity, 1});
        VkMemoryRequirements req{(heap.size + granularity - 1) / granularity * granularity, alignment,
                                 heap.memoryTypeBits};
        t->heaps.push_back(gpu_.memory().allocate(req, gpu::MemoryUsage::DeviceLocal, !heap.images,
                                                  "rg.heap" + std::to_string(h)));
        t->bytes += heap.size;
    }
    for (uint32_t i = 0; i < plan.resources.size(); ++i) {
        const PlannedResource& r = plan.resources[i];
        if (r.origin != ir::Origin::Transient || !r.used) {
            continue;
        }
        const ir::Resource& d = decl.resources[i];
        if (r.heap >= t->heaps.size()) {
            throw gpu::GpuError("render graph: transient '" + std::string(d.name) + "' has no heap in the plan");
        }
        gpu::MemoryRange range = t->heaps[r.heap].range();
        range.offset += r.offset;
        range.size = r.size;
        range.mapped = nullptr;
        Physical p;
        if (r.kind == ResourceKind::Texture) {
            t->images.push_back(std::make_unique<gpu::Image>(
                gpu_, imageDescOf(d.texture, r.imageUsage, std::string(d.name), r.crossQueue), range));
            p.image = t->images.back().get();
        } else {
            t->buffers.push_back(std::make_unique<gpu::Buffer>(
                gpu_, bufferDescOf(d.buffer, r.bufferUsage, std::string(d.name), r.crossQueue), range));
            p.buffer = t->buffers.back().get();
        }
        t->byResource[i] = p;
    }
    spdlog::info("render graph: transient memory {} KiB in {} heap(s), {} KiB without aliasing",
                 t->bytes >> 10, plan.heaps.size(), plan.stats.transientBytes >> 10);
    transients_ = std::move(t);
    ++stats_.transientRebuilds;
    stats_.transientBytes = transients_->bytes;
}

namespace {

// A history half's layout between frames: the layout its role starts a
// frame in (a half no pass reads or writes there is kept in GENERAL).
VkImageLayout restingLayout(VkImageLayout entry) {
    return entry == VK_IMAGE_LAYOUT_UNDEFINED ? VK_IMAGE_LAYOUT_GENERAL : entry;
}

// FNV-1a over how `plan` uses resources a and b.
uint64_t useSignature(const Plan& plan, uint32_t a, uint32_t b) {
    uint64_t h = 1469598103934665603ull;
    const auto mix = [&h](uint64_t v) {
        for (int i = 0; i < 8; ++i) {
            h ^= (v >> (8 * i)) & 0xFFu;
            h *= 1099511628211ull;
        }
    };
    for (const PlannedPass& p : plan.passes) {
        for (const ir::Use& use : plan.uses(p)) {
            if (use.resource != a && use.resource != b) continue;
            mix(use.resource == a ? 1u : 2u);
            mix(uint64_t(p.queue));
            mix(uint64_t(use.kinds));
            mix(use.writes ? 1u : 0u);
        }
    }
    return h;
}

} // namespace

void Executor::prepareHistory(const Plan& plan) {
    const auto& decl = *plan.declaration;
    for (auto& [name, h] : history_) {
        h->flippedThisFrame = false;
    }
    // A plan expects each history half in the layout its role starts the
    // frame in, as if the previous frame had run the same plan (the graph
    // plans the cycle of one plan). When the plan changes (a mode, a debug
    // view, a culled pass), the images are moved to the layouts this plan
    // expects; when the description changes (a resize), the pair starts
    // afresh. Both wait for the device: they are rare, and correct beats
    // fast there.
    struct Relayout {
        History* history;
        VkImageLayout from[2];
        VkImageLayout to[2];
    };
    std::vector<Relayout> relayouts;
    for (uint32_t i = 0; i < plan.resources.size(); ++i) {
        const PlannedResource& r = plan.resources[i];
        if (r.origin != ir::Origin::HistoryCurrent || !r.used) {
            continue;
        }
        const ir::Resource& current = decl.resources[i];
        const std::string name = historyName(std::string(current.name));
        const PlannedResource& prevPlan = plan.resources[r.partner];
        const bool shared = r.crossQueue || prevPlan.crossQueue;
        auto it = history_.find(name);
        if (it != history_.end()) {
            History& existing = *it->second;
            const bool sameDesc = existing.kind == r.kind &&
                                  (r.kind == ResourceKind::Texture ? existing.texture == current.texture
                                                                   : existing.buffer == current.buffer) &&
                                  (existing.imageUsage & r.imageUsage) == r.imageUsage &&
                                  (existing.bufferUsage & r.bufferUsage) == r.bufferUsage && existing.shared == shared;
            if (!sameDesc) {
                spdlog::info("render graph: history '{}' recreated: its description or usage changed", name);
                waitIdle();
                history_.erase(it);
            } else {
                const uint64_t signature = useSignature(plan, i, r.partner);
                const bool samePlan = signature == existing.useSignature;
                existing.useSignature = signature;
                if (!existing.flippedThisFrame) {
                    existing.current ^= 1u;
                    existing.flippedThisFrame = true;
                }
                if (existing.kind == ResourceKind::Texture) {
                    const uint32_t k = existing.current;
                    const VkImageLayout wantCurrent = restingLayout(r.entryLayout);
                    const VkImageLayout wantPrevious = restingLayout(prevPlan.entryLayout);
                    if (!samePlan || existing.layout[k] != wantCurrent || existing.layout[1u - k] != wantPrevious) {
                        Relayout move{&existing, {existing.layout[0], existing.layout[1]}, {}};
                        move.to[k] = wantCurrent;
                        move.to[1u - k] = wantPrevious;
                        relayouts.push_back(move);
                    }
                    // After this frame the roles swap: `current` starts the
                    // next frame as `previous`, and the other way round.
                    existing.layout[k] = wantPrevious;
                    existing.layout[1u - k] = wantCurrent;
                }
                continue;
            }
        }
        auto h = std::make_unique<History>();
        h->kind = r.kind;
        h->flippedThisFrame = true;
        h->texture = current.texture;
        h->buffer = current.buffer;
        h->imageUsage = r.imageUsage;
        h->bufferUsage = r.bufferUsage;
        h->shared = shared;
        h->useSignature = useSignature(plan, i, r.partner);
        for (uint32_t k = 0; k < 2; ++k) {
            const std::string halfName = name + "[" + std::to_string(k) + "]";
            if (r.kind == ResourceKind::Texture) {
                h->images[k] = std::make_unique<gpu::Image>(
                    gpu_, imageDescOf(current.texture, r.imageUsage | VK_IMAGE_USAGE_TRANSFER_DST_BIT, halfName, shared));
            } else {
                h->buffers[k] = std::make_unique<gpu::Buffer>(
                    gpu_, bufferDescOf(current.buffer, r.bufferUsage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, halfName, shared));
            }
        }
        gpu::submitAndWait(gpu_, gpu_.graphicsQueue(), "render graph: clearing history '" + name + "'", [&](VkCommandBuffer cmd) {
            for (uint32_t k = 0; k < 2; ++k) {
                const VkImageLayout entry = k == h->current ? r.entryLayout : prevPlan.entryLayout;
                if (r.kind == ResourceKind::Texture) {
                    const gpu::Image& img = *h->images[k];
                    // From every earlier command: a recreated pair may sit in
                    // the memory of the one it replaces (waited for, but the
                    // ordering is stated, not left to the host wait).
                    gpu::imageBarrier(cmd, img, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                      VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
                    const VkImageSubresourceRange range = img.fullRange();
                    if (img.aspect() & VK_IMAGE_ASPECT_COLOR_BIT) {
                        const VkClearColorValue zero{};
                        vkCmdClearColorImage(cmd, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1, &range);
                    } else {
                        const VkClearDepthStencilValue zero{};
                        vkCmdClearDepthStencilImage(cmd, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                                                    &range);
                    }
                    gpu::imageBarrier(cmd, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, restingLayout(entry),
                                      VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                      VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
                } else {
                    // From every earlier command, as for images: the new
                    // buffer may sit in memory an earlier frame's buffer read.
                    // The fill's stage is ALL_TRANSFER: the spec puts
                    // vkCmdFillBuffer in CLEAR, the validation layer 1.3.239
                    // in COPY (a barrier to CLEAR alone left a WRITE_AFTER_READ
                    // on the H200); ALL_TRANSFER holds both.
                    gpu::bufferBarrier(cmd, *h->buffers[k], VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                       VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
                    vkCmdFillBuffer(cmd, h->buffers[k]->handle(), 0, VK_WHOLE_SIZE, 0);
                    gpu::bufferBarrier(cmd, *h->buffers[k], VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                       VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                       VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
                }
            }
        });
        // After frame 0 the roles swap (see above).
        h->layout[h->current] = restingLayout(prevPlan.entryLayout);
        h->layout[1u - h->current] = restingLayout(r.entryLayout);
        spdlog::debug("render graph: history '{}' created", name);
        history_[name] = std::move(h);
    }
    if (relayouts.empty()) {
        return;
    }
    waitIdle();
    gpu::submitAndWait(gpu_, gpu_.graphicsQueue(), "rg.history.relayout", [&](VkCommandBuffer cmd) {
        for (const Relayout& move : relayouts) {
            // A barrier even where the layout stays: the plan's own first
            // barrier assumes its own last accesses, not the old plan's.
            for (uint32_t j = 0; j < 2; ++j) {
                {
                    gpu::imageBarrier(cmd, *move.history->images[j], move.from[j], move.to[j],
                                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                      VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                      VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
                }
            }
        }
    });
    spdlog::debug("render graph: {} history pair(s) moved to this plan's layouts", relayouts.size());
}

void Executor::bindResources(const Plan& plan, const FrameResources& imports) {
    const auto& decl = *plan.declaration;
    physical_.assign(plan.resources.size(), Physical{});
    resourceNames_.resize(plan.resources.size());
    for (uint32_t i = 0; i < plan.resources.size(); ++i) {
        const PlannedResource& r = plan.resources[i];
        const ir::Resource& d = decl.resources[i];
        resourceNames_[i] = d.name;
        if (!r.used) {
            continue;
        }
        Physical& p = physical_[i];
        switch (r.origin) {
        case ir::Origin::Transient: p = transients_->byResource.at(i); break;
        case ir::Origin::HistoryPrevious:
        case ir::Origin::HistoryCurrent: {
            const History& h = *history_.at(historyName(std::string(d.name)));
            const uint32_t k = r.origin == ir::Origin::HistoryCurrent ? h.current : 1u - h.current;
            p.image = h.images[k].get();
            p.buffer = h.buffers[k].get();
            break;
        }
        case ir::Origin::Imported: {
            bool bound = false;
            if (r.kind == ResourceKind::Texture) {
                const auto it = imports.images_.find(i);
                bound = it != imports.images_.end();
                if (bound) p.image = it->second;
            } else if (r.kind == ResourceKind::Buffer) {
                const auto it = imports.buffers_.find(i);
                bound = it != imports.buffers_.end();
                if (bound) p.buffer = it->second;
            } else {
                const auto it = imports.accels_.find(i);
                bound = it != imports.accels_.end();
                if (bound) p.accel = it->second;
            }
            if (!bound) {
                throw gpu::GpuError("render graph: imported " + std::string(toString(r.kind)) + " '" + std::string(d.name) +
                                    "' has no resource bound for this frame (FrameResources::bind)");
            }
            if (r.crossQueue && plan.caps.separateComputeFamily &&
                ((p.image && !p.image->desc().sharedAcrossQueues) || (p.buffer && !p.buffer->desc().sharedAcrossQueues) ||
                 (p.accel && !p.accel->buffer().desc().sharedAcrossQueues))) {
                throw gpu::GpuError("render graph: imported '" + std::string(d.name) +
                                    "' is used on both queues but was not created with sharedAcrossQueues");
            }
            break;
        }
        }
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
    const auto importedTexture = [&](uint32_t r, const char* what) -> const ir::Resource& {
        if (r >= decl.resources.size() || decl.resources[r].kind != ResourceKind::Texture ||
            decl.resources[r].origin != ir::Origin::Imported) {
            throw gpu::GpuError(std::string("render graph: FrameResources::") + what +
                                " names a texture that is not an import of this plan");
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
        if (w.texture != kNoIndex) {
            const ir::Resource& res = importedTexture(w.texture, "waitSemaphore");
            const Plan::WaitPoint point = plan.firstUseOf(w.texture);
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
        if (sg.texture != kNoIndex) {
            importedTexture(sg.texture, "signalSemaphore");
            if (const uint32_t ending = plan.batchEnding(sg.texture); ending != kNoIndex) batch = ending;
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

SubmittedFrame Executor::run(const Plan& plan, const FrameResources& imports) {
    if (!plan.declaration) {
        throw gpu::GpuError("render graph: run() got an empty Plan");
    }
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

    // The span's first and last member passes, in submission order.
    const PlannedPass* spanFirst = nullptr;
    const PlannedPass* spanLast = nullptr;
    if (span_) {
        for (const Batch& batch : plan.batches) {
            for (const PlannedPass& p : plan.passesOf(batch)) {
                if (!span_->member(plan.passName(p))) continue;
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
    const ExternalSync external = placeSemaphores(plan, imports);

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
            slot.passes[pair] = {ctx.name_, p.queue, std::nullopt, frame_};
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
                if (!hostTimed && perPass) {
                    slot.timer.begin(cmd, pair, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT);
                }
                if (const ExecuteFn& execute = plan.execute(p)) {
                    execute(ctx);
                }
                if (!hostTimed && perPass) {
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
        out[i].milliseconds = ms[i];
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
