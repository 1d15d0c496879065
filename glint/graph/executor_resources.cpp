// The physical resources behind a Plan, made ready before a frame is
// recorded: transients placed in aliased heaps (rebuilt only when the
// placement changes), history pairs (created, cleared and moved to the
// layouts each plan expects), imports bound; and the driver's memory
// requirements that compileOptions() hands the compiler.

#include "glint/graph/executor_internal.h"

#include "glint/gpu/error.h"

#include <spdlog/spdlog.h>

#include <algorithm>

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

// The name of a history pair: its halves are "<name>.previous" and "<name>.current".
std::string historyName(const std::string& halfName) { return halfName.substr(0, halfName.rfind('.')); }

} // namespace

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
            // An upload (Graph::uploadBuffer) is bound next, by bindUploads.
            const auto isUpload = [&] {
                return std::any_of(decl.uploads.begin(), decl.uploads.end(),
                                   [&](const ir::Declaration::Upload& u) { return u.resource == i; });
            };
            if (!bound && r.kind == ResourceKind::Buffer && isUpload()) break;
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

} // namespace glint::rg
