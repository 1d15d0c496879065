#include "glint/graph/synthetic.h"

#include <algorithm>
#include <random>

namespace glint::rg::synthetic {

// ---- Replay -------------------------------------------------------------------------

namespace {

// What a slot holds: the handle its resource's create/import call returned
// (the three handle kinds share one layout), as a Texture whatever the kind,
// turned back into the right kind at each use. Small and written field by
// field: building a larger slot on the stack and copying it into the vector
// stalled on store forwarding, and the replay is part of what the bench
// times.
struct Slot {
    ResourceKind kind;
    Texture handle;
};

template <class To, ResourceKind K>
To as(Handle<K> h) {
    return To{h.index, h.version, h.graph};
}

template <ResourceKind K>
void addSlot(std::vector<Slot>& slots, Handle<K> handle) {
    Slot& s = slots.emplace_back();
    s.kind = K;
    s.handle = as<Texture>(handle);
}

} // namespace

std::vector<PassId> declare(Graph& graph, const Script& script) {
    std::vector<Slot> slots;
    slots.reserve(script.slotCount);
    for (const ScriptResource& r : script.resources) {
        switch (r.origin) {
            case ir::Origin::Transient:
                if (r.kind == ResourceKind::Texture)
                    addSlot(slots, graph.createTexture(r.name, r.texture));
                else
                    addSlot(slots, graph.createBuffer(r.name, r.buffer));
                break;
            case ir::Origin::Imported:
                if (r.kind == ResourceKind::Texture)
                    addSlot(slots, graph.importTexture(r.name, {r.texture, r.initial, r.final}));
                else if (r.kind == ResourceKind::Buffer)
                    addSlot(slots, graph.importBuffer(r.name, {r.buffer, r.initial, r.final}));
                else
                    addSlot(slots, graph.importAccelStruct(r.name, {r.initial, r.final}));
                break;
            case ir::Origin::HistoryPrevious:
            case ir::Origin::HistoryCurrent:
                if (r.kind == ResourceKind::Texture) {
                    const HistoryTexture h = graph.createHistoryTexture(r.name, r.texture);
                    addSlot(slots, h.previous);
                    addSlot(slots, h.current);
                } else {
                    const HistoryBuffer h = graph.createHistoryBuffer(r.name, r.buffer);
                    addSlot(slots, h.previous);
                    addSlot(slots, h.current);
                }
                break;
        }
    }

    std::vector<PassId> ids;
    ids.reserve(script.passes.size());
    // Writes take effect when a pass's setup ends, so new versions wait here
    // until then: a pass may read one mip of a handle and write another.
    std::vector<std::pair<uint32_t, uint32_t>> written;
    for (const ScriptPass& pass : script.passes) {
        written.clear();
        ids.push_back(graph.addPass(
            pass.name, pass.queue,
            [&](Builder& b) {
                b.setPipeline(pass.pipeline);
                if (pass.sideEffects) b.markSideEffects();
                if (pass.skipped) b.skip();
                for (const ScriptUse& u : pass.uses) {
                    const Slot& s = slots[u.slot];
                    if (!accessWrites(u.access)) {
                        switch (s.kind) {
                            case ResourceKind::Texture:
                                b.read(s.handle, u.access, u.range);
                                break;
                            case ResourceKind::Buffer:
                                b.read(as<Buffer>(s.handle), u.access);
                                break;
                            case ResourceKind::AccelStruct:
                                b.read(as<AccelStruct>(s.handle), u.access);
                                break;
                        }
                        continue;
                    }
                    uint32_t version = 0;
                    switch (s.kind) {
                        case ResourceKind::Texture:
                            version = b.write(s.handle, u.access, u.range).version;
                            break;
                        case ResourceKind::Buffer:
                            version = b.write(as<Buffer>(s.handle), u.access).version;
                            break;
                        case ResourceKind::AccelStruct:
                            version = b.write(as<AccelStruct>(s.handle), u.access).version;
                            break;
                    }
                    written.emplace_back(u.slot, version);
                }
            },
            [](PassContext&) {}));
        for (const auto& [slot, version] : written) slots[slot].handle.version = version;
    }
    for (uint32_t slot : script.outputs) {
        const Slot& s = slots[slot];
        switch (s.kind) {
            case ResourceKind::Texture:
                graph.markOutput(s.handle);
                break;
            case ResourceKind::Buffer:
                graph.markOutput(as<Buffer>(s.handle));
                break;
            case ResourceKind::AccelStruct:
                graph.markOutput(as<AccelStruct>(s.handle));
                break;
        }
    }
    return ids;
}

} // namespace glint::rg::synthetic

namespace glint::rg::synthetic {
namespace {

// Collects a script: slots in creation order, passes with their uses.
class ScriptBuilder {
public:
    explicit ScriptBuilder(std::string prefix = {}) : prefix_(std::move(prefix)) {}

    uint32_t texture(const std::string& name, TextureDesc desc) {
        return add({prefix_ + name, ResourceKind::Texture, ir::Origin::Transient, desc, {}, {}, {}});
    }
    uint32_t buffer(const std::string& name, uint64_t size) {
        return add({prefix_ + name, ResourceKind::Buffer, ir::Origin::Transient, {}, {size}, {}, {}});
    }
    uint32_t importTexture(const std::string& name, TextureDesc desc, BoundaryState initial, BoundaryState final) {
        return add({prefix_ + name, ResourceKind::Texture, ir::Origin::Imported, desc, {}, initial, final});
    }
    uint32_t importBuffer(const std::string& name, uint64_t size, BoundaryState initial, BoundaryState final) {
        return add({prefix_ + name, ResourceKind::Buffer, ir::Origin::Imported, {}, {size}, initial, final});
    }
    uint32_t importAccel(const std::string& name, BoundaryState initial, BoundaryState final) {
        return add({prefix_ + name, ResourceKind::AccelStruct, ir::Origin::Imported, {}, {}, initial, final});
    }
    // Returns the `previous` slot; `current` is the next one.
    uint32_t historyTexture(const std::string& name, TextureDesc desc) {
        return add({prefix_ + name, ResourceKind::Texture, ir::Origin::HistoryCurrent, desc, {}, {}, {}}, 2);
    }
    uint32_t historyBuffer(const std::string& name, uint64_t size) {
        return add({prefix_ + name, ResourceKind::Buffer, ir::Origin::HistoryCurrent, {}, {size}, {}, {}}, 2);
    }

    ScriptPass& pass(const std::string& name, Queue queue, Pipeline pipeline = Pipeline::Compute) {
        script_.passes.push_back({prefix_ + name, queue, pipeline, false, {}});
        return script_.passes.back();
    }

    void output(uint32_t slot) { script_.outputs.push_back(slot); }
    Script take() { return std::move(script_); }
    Script& script() { return script_; }

private:
    uint32_t add(ScriptResource r, uint32_t slots = 1) {
        const uint32_t slot = script_.slotCount;
        script_.slotCount += slots;
        script_.resources.push_back(std::move(r));
        return slot;
    }

    std::string prefix_;
    Script script_;
};

void read(ScriptPass& p, uint32_t slot, Access a, Subresource range = {}) { p.uses.push_back({slot, a, range}); }
void write(ScriptPass& p, uint32_t slot, Access a, Subresource range = {}) { p.uses.push_back({slot, a, range}); }

TextureDesc tex(uint32_t w, uint32_t h, VkFormat f, uint32_t layers = 1, uint32_t mips = 1) {
    return TextureDesc{w, h, 1, layers, mips, f};
}

void appendReflectionFrame(ScriptBuilder& sb, uint32_t w, uint32_t h, Pipeline trace) {
    const uint32_t tiles = ((w + 7) / 8) * ((h + 7) / 8); // 8x8 tiles (FidelityFX Hybrid Reflections)
    const uint64_t perPixelU32 = uint64_t{w} * h * 4;
    constexpr Queue G = Queue::Graphics;
    constexpr Queue A = Queue::AsyncCompute;

    // Owned by the BVH manager and the scene, imported every frame. The TLAS
    // ends each frame read by the trace passes on graphics and is rebuilt on
    // async compute in the next: the write-after-read edge across frames.
    const BoundaryState tlasState = BoundaryState::of(Access::AccelRead, G, trace);
    const uint32_t tlas = sb.importAccel("bvh.tlas", tlasState, tlasState);
    const uint32_t particleTlas = sb.importAccel("bvh.particle_tlas", tlasState, tlasState);
    const BoundaryState buildInput = BoundaryState::of(Access::AccelBuildInput, A);
    const uint32_t instances = sb.importBuffer("scene.instances", 64 * 1024, buildInput, buildInput);
    const uint32_t vertices = sb.importBuffer("scene.cs_vertices", 16u << 20, buildInput, buildInput);
    const BoundaryState scratchState = BoundaryState::of(Access::AccelBuildWrite, A);
    const uint32_t scratch = sb.importBuffer("bvh.scratch", 32u << 20, scratchState, scratchState);
    const BoundaryState traced = BoundaryState::of(Access::StorageRead, G, trace);
    const uint32_t primitives = sb.importBuffer("scene.primitives", 24u << 20, traced, traced);
    const uint32_t offsets = sb.importBuffer("scene.primitive_offsets", 1u << 20, traced, traced);
    const uint32_t particleData = sb.importBuffer("scene.particles", 1u << 20, traced, traced);
    const BoundaryState sampled = BoundaryState::of(Access::SampledRead, G);
    const uint32_t blueNoise = sb.importTexture("blue_noise", tex(128, 128, VK_FORMAT_R8G8_UNORM), sampled, sampled);
    const uint32_t envMap =
        sb.importTexture("env_map", tex(512, 512, VK_FORMAT_R16G16B16A16_SFLOAT, 6), sampled, sampled);
    // A swapchain image: the acquire semaphore is waited at colour output.
    const uint32_t output = sb.importTexture(
        "output", tex(w, h, VK_FORMAT_B8G8R8A8_UNORM),
        BoundaryState::raw(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED, G),
        BoundaryState::of(Access::Present, G));

    const uint32_t feedback = sb.historyBuffer("feedback_counters", uint64_t{tiles} * 4); // one u32 per tile
    const uint32_t history = sb.historyTexture("reflection_history", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));

    const uint32_t depth = sb.texture("gbuffer.depth", tex(w, h, VK_FORMAT_D32_SFLOAT));
    const uint32_t normal = sb.texture("gbuffer.normal", tex(w, h, VK_FORMAT_A2B10G10R10_UNORM_PACK32));
    const uint32_t albedo = sb.texture("gbuffer.albedo", tex(w, h, VK_FORMAT_R8G8B8A8_UNORM));
    const uint32_t roughness = sb.texture("gbuffer.roughness_metal", tex(w, h, VK_FORMAT_R8G8_UNORM));
    const uint32_t motion = sb.texture("gbuffer.motion", tex(w, h, VK_FORMAT_R16G16_SFLOAT));
    const uint32_t lit = sb.texture("gbuffer.lit", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));
    const uint32_t rays = sb.buffer("rays.list", perPixelU32);
    const uint32_t tileList = sb.buffer("rays.tiles", uint64_t{tiles} * 4);
    const uint32_t rayArgs = sb.buffer("rays.args", 64);
    const uint32_t ssRadiance = sb.texture("sslr.radiance", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));
    const uint32_t ssConfidence = sb.texture("sslr.confidence", tex(w, h, VK_FORMAT_R8_UNORM));
    const uint32_t rtList = sb.buffer("sslr.rt_list", perPixelU32);
    const uint32_t rtArgs = sb.buffer("sslr.rt_args", 64);
    const uint32_t rtRadiance = sb.texture("rt.radiance", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));
    const uint32_t hitDistance = sb.texture("rt.hit_distance", tex(w, h, VK_FORMAT_R16_SFLOAT));
    const uint32_t particleRadiance = sb.texture("particles.radiance", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));
    const uint32_t reflection = sb.texture("integrate.radiance", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));
    const uint32_t reflectionMotion = sb.texture("reflection.motion", tex(w, h, VK_FORMAT_R16G16_SFLOAT));
    const uint32_t filtered = sb.texture("spatial.radiance", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));
    const uint32_t hdr = sb.texture("composite.hdr", tex(w, h, VK_FORMAT_R16G16B16A16_SFLOAT));

    ScriptPass* p = &sb.pass("bvh_update", A);
    read(*p, instances, Access::AccelBuildInput);
    read(*p, vertices, Access::AccelBuildInput);
    write(*p, scratch, Access::AccelBuildWrite);
    write(*p, tlas, Access::AccelBuildWrite);
    write(*p, particleTlas, Access::AccelBuildWrite);

    p = &sb.pass("gbuffer", G, Pipeline::Raster);
    write(*p, depth, Access::DepthWrite);
    for (uint32_t target : {normal, albedo, roughness, motion, lit}) write(*p, target, Access::ColorAttachment);

    p = &sb.pass("generate_rays", G);
    for (uint32_t in : {depth, normal, roughness, blueNoise}) read(*p, in, Access::SampledRead);
    read(*p, feedback, Access::StorageRead); // last frame's counters
    for (uint32_t out : {rays, tileList, rayArgs}) write(*p, out, Access::StorageWrite);

    p = &sb.pass("sslr", G);
    read(*p, depth, Access::SampledRead);
    read(*p, lit, Access::SampledRead);
    read(*p, rays, Access::StorageRead);
    read(*p, tileList, Access::StorageRead);
    read(*p, rayArgs, Access::IndirectArgs);
    read(*p, tlas, Access::AccelRead); // validates screen-space hits with a short ray query
    for (uint32_t out : {ssRadiance, ssConfidence, rtList, rtArgs}) write(*p, out, Access::StorageWrite);

    p = &sb.pass("trace_reflections", G, trace);
    read(*p, tlas, Access::AccelRead);
    read(*p, primitives, Access::StorageRead);
    read(*p, offsets, Access::StorageRead);
    read(*p, envMap, Access::SampledRead);
    read(*p, rtList, Access::StorageRead);
    read(*p, rtArgs, Access::IndirectArgs);
    write(*p, rtRadiance, Access::StorageWrite);
    write(*p, hitDistance, Access::StorageWrite);

    p = &sb.pass("trace_particles", G, trace);
    read(*p, particleTlas, Access::AccelRead);
    read(*p, particleData, Access::StorageRead);
    read(*p, rtList, Access::StorageRead);
    read(*p, rtArgs, Access::IndirectArgs);
    write(*p, particleRadiance, Access::StorageWrite);

    p = &sb.pass("integrate", G);
    for (uint32_t in : {ssRadiance, ssConfidence, rtRadiance, particleRadiance, envMap})
        read(*p, in, Access::SampledRead);
    write(*p, reflection, Access::StorageWrite);
    write(*p, feedback + 1, Access::StorageWrite); // this frame's counters

    p = &sb.pass("reflection_motion", G);
    read(*p, hitDistance, Access::SampledRead);
    read(*p, motion, Access::SampledRead);
    write(*p, reflectionMotion, Access::StorageWrite);

    p = &sb.pass("temporal", G);
    for (uint32_t in : {reflection, reflectionMotion, hitDistance, history}) read(*p, in, Access::SampledRead);
    write(*p, history + 1, Access::StorageWrite);

    p = &sb.pass("spatial_filter", G);
    read(*p, history + 1, Access::SampledRead);
    write(*p, filtered, Access::StorageWrite);

    p = &sb.pass("composite", G);
    read(*p, filtered, Access::SampledRead);
    read(*p, lit, Access::SampledRead);
    write(*p, hdr, Access::StorageWrite);

    p = &sb.pass("tonemap", G, Pipeline::Raster);
    read(*p, hdr, Access::SampledRead);
    write(*p, output, Access::ColorAttachment);
    (void)albedo;
}

} // namespace

Script reflectionFrame(const ReflectionOptions& o) {
    ScriptBuilder sb(o.prefix);
    appendReflectionFrame(sb, o.width, o.height, o.tracePipeline);
    return sb.take();
}

Script tiledReflectionFrames(uint32_t passes, uint32_t width, uint32_t height) {
    Script all;
    for (uint32_t copy = 0; all.passes.size() < passes; ++copy) {
        ScriptBuilder sb(std::string("f").append(std::to_string(copy)).append("/"));
        appendReflectionFrame(sb, width, height, Pipeline::Compute);
        Script one = sb.take();
        const uint32_t base = all.slotCount;
        for (ScriptResource& r : one.resources) all.resources.push_back(std::move(r));
        all.slotCount += one.slotCount;
        for (ScriptPass& p : one.passes) {
            if (all.passes.size() == passes) break;
            for (ScriptUse& u : p.uses) u.slot += base;
            all.passes.push_back(std::move(p));
        }
    }
    return all;
}

// ---- Random frames -------------------------------------------------------------------

namespace {

class RandomFrame {
public:
    explicit RandomFrame(const RandomOptions& o) : o_(o), rng_(o.seed) {}

    Script build() {
        if (o_.imports) addImports();
        if (o_.history) addHistory();
        for (uint32_t i = 0; i < o_.passes; ++i) addPass(i);
        // A couple of transients as explicit outputs; the rest must be reached
        // through imports, history and side effects, or be culled.
        for (uint32_t tries = 0, marked = 0; tries < 8 && marked < 2 && !live_.empty(); ++tries) {
            const Live& l = live_[pick(live_.size())];
            if (l.transient && l.readable) {
                sb_.output(l.slot);
                ++marked;
            }
        }
        Script s = sb_.take();
        std::sort(s.outputs.begin(), s.outputs.end());
        s.outputs.erase(std::unique(s.outputs.begin(), s.outputs.end()), s.outputs.end());
        return s;
    }

private:
    struct Live {
        uint32_t slot;
        ResourceKind kind;
        bool readable;
        bool depth = false;
        bool transient = false;
        bool writable = true;
        uint32_t mips = 1;
        uint32_t layers = 1;
    };

    size_t pick(size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng_); }
    bool chance(uint32_t oneIn) { return pick(oneIn) == 0; }
    template <class T>
    T choose(std::initializer_list<T> options) {
        return *(options.begin() + pick(options.size()));
    }

    Queue randomQueue() { return o_.asyncCompute && chance(3) ? Queue::AsyncCompute : Queue::Graphics; }

    BoundaryState state(std::initializer_list<BoundaryState> options) { return choose(options); }

    void addImports() {
        constexpr Queue G = Queue::Graphics, A = Queue::AsyncCompute;
        const uint32_t e = o_.extent;
        {
            const BoundaryState initial =
                state({BoundaryState::of(Access::None), BoundaryState::of(Access::SampledRead, G),
                       BoundaryState::of(Access::StorageWrite, A), BoundaryState::of(Access::ColorAttachment, G)});
            const BoundaryState final =
                chance(3)
                    ? initial
                    : state({BoundaryState::of(Access::SampledRead, G), BoundaryState::of(Access::Present, G),
                             BoundaryState::of(Access::StorageRead, A), BoundaryState::of(Access::TransferSrc, G)});
            const uint32_t slot =
                sb_.importTexture("import.color", tex(e, e, VK_FORMAT_R8G8B8A8_UNORM), initial, final);
            live_.push_back({slot, ResourceKind::Texture, initial.access != Access::None});
        }
        {
            const BoundaryState initial =
                state({BoundaryState::of(Access::None), BoundaryState::of(Access::StorageWrite, G),
                       BoundaryState::of(Access::StorageRead, A), BoundaryState::of(Access::TransferDst, G)});
            const BoundaryState final =
                chance(3)
                    ? initial
                    : state({BoundaryState::of(Access::StorageRead, G), BoundaryState::of(Access::IndirectArgs, A),
                             BoundaryState::of(Access::TransferSrc, G)});
            const uint32_t slot = sb_.importBuffer("import.buffer", 4096, initial, final);
            live_.push_back({slot, ResourceKind::Buffer, initial.access != Access::None});
        }
        {
            const bool persistent = chance(2);
            const BoundaryState read = BoundaryState::of(Access::AccelRead, G, Pipeline::Compute);
            const BoundaryState initial = persistent ? read : BoundaryState::of(Access::AccelBuildWrite, A);
            const BoundaryState final =
                persistent ? read : BoundaryState::of(Access::AccelRead, G, Pipeline::RayTracing);
            const uint32_t slot = sb_.importAccel("import.tlas", initial, final);
            live_.push_back({slot, ResourceKind::AccelStruct, true});
        }
    }

    void addHistory() {
        const uint32_t t =
            sb_.historyTexture("history.texture", tex(o_.extent, o_.extent, VK_FORMAT_R16G16B16A16_SFLOAT));
        live_.push_back({t, ResourceKind::Texture, true, false, false, false}); // previous: read only
        live_.push_back({t + 1, ResourceKind::Texture, false});
        const uint32_t b = sb_.historyBuffer("history.buffer", 1024);
        live_.push_back({b, ResourceKind::Buffer, true, false, false, false});
        live_.push_back({b + 1, ResourceKind::Buffer, false});
    }

    Access readAccess(const Live& l, Pipeline pipeline) {
        switch (l.kind) {
            case ResourceKind::Texture:
                if (l.depth) return pipeline == Pipeline::Raster && chance(2) ? Access::DepthRead : Access::SampledRead;
                return choose({Access::SampledRead, Access::StorageRead, Access::TransferSrc});
            case ResourceKind::Buffer:
                return choose({Access::SampledRead, Access::StorageRead, Access::IndirectArgs, Access::TransferSrc,
                               Access::AccelBuildInput});
            case ResourceKind::AccelStruct:
                return chance(4) ? Access::AccelBuildInput : Access::AccelRead;
        }
        return Access::SampledRead;
    }

    Access writeAccess(const Live& l, Queue q, Pipeline pipeline) {
        const bool raster = q == Queue::Graphics && pipeline == Pipeline::Raster;
        switch (l.kind) {
            case ResourceKind::Texture:
                if (l.depth) return raster && chance(2) ? Access::DepthWrite : Access::TransferDst;
                if (raster && chance(2)) return Access::ColorAttachment;
                if (l.readable && chance(3)) return Access::StorageReadWrite;
                return chance(4) ? Access::TransferDst : Access::StorageWrite;
            case ResourceKind::Buffer:
                if (l.readable && chance(3)) return Access::StorageReadWrite;
                return choose({Access::StorageWrite, Access::TransferDst, Access::AccelBuildWrite});
            case ResourceKind::AccelStruct:
                return Access::AccelBuildWrite;
        }
        return Access::StorageWrite;
    }

    Subresource someOf(const Live& l) {
        if (l.kind != ResourceKind::Texture) return {};
        Subresource r;
        if (l.mips > 1 && chance(2)) r = Subresource::mip(static_cast<uint32_t>(pick(l.mips)));
        if (l.layers > 1 && chance(2)) {
            r.baseLayer = static_cast<uint32_t>(pick(l.layers));
            r.layerCount = 1;
        }
        return r;
    }

    void addPass(uint32_t index) {
        const Queue q = randomQueue();
        Pipeline pipeline = Pipeline::Compute;
        if (q == Queue::Graphics)
            pipeline = chance(4) ? Pipeline::Raster : (chance(6) ? Pipeline::RayTracing : Pipeline::Compute);
        else if (chance(6))
            pipeline = Pipeline::RayTracing;
        ScriptPass& pass = sb_.pass("pass" + std::to_string(index), q, pipeline);
        pass.sideEffects = chance(16);
        std::vector<uint32_t> used;
        auto unused = [&](uint32_t slot) { return std::find(used.begin(), used.end(), slot) == used.end(); };

        // A mip-chain step: read one mip, write the next.
        if (o_.subresources && chance(6)) {
            for (uint32_t tries = 0; tries < 4 && !live_.empty(); ++tries) {
                Live& l = live_[pick(live_.size())];
                if (l.kind != ResourceKind::Texture || l.mips < 2 || !l.readable || !l.writable || l.depth) continue;
                const auto m = static_cast<uint32_t>(pick(l.mips - 1));
                read(pass, l.slot, Access::SampledRead, Subresource::mip(m));
                write(pass, l.slot, Access::StorageWrite, Subresource::mip(m + 1));
                used.push_back(l.slot);
                break;
            }
        }
        const size_t reads = pick(4);
        for (size_t i = 0; i < reads && !live_.empty(); ++i) {
            const Live& l = live_[pick(live_.size())];
            if (!l.readable || !unused(l.slot)) continue;
            Access a = readAccess(l, pipeline);
            if (a == Access::DepthRead && pipeline != Pipeline::Raster) a = Access::SampledRead;
            read(pass, l.slot, a, someOf(l));
            used.push_back(l.slot);
        }
        const size_t writes = 1 + pick(2);
        for (size_t i = 0; i < writes; ++i) {
            if (live_.empty() || chance(3)) {
                used.push_back(createAndWrite(pass, q, pipeline));
                continue;
            }
            Live& l = live_[pick(live_.size())];
            if (!l.writable || !unused(l.slot)) continue;
            const Access a = writeAccess(l, q, pipeline);
            // The first write covers everything so later reads of any part are legal.
            write(pass, l.slot, a, l.readable ? someOf(l) : Subresource{});
            if (a == Access::StorageReadWrite && !l.readable) pass.uses.back().access = Access::StorageWrite;
            l.readable = true;
            used.push_back(l.slot);
        }
    }

    uint32_t createAndWrite(ScriptPass& pass, Queue q, Pipeline pipeline) {
        const bool raster = q == Queue::Graphics && pipeline == Pipeline::Raster;
        const std::string name = std::string("t").append(std::to_string(live_.size()));
        Live l{0, chance(3) ? ResourceKind::Buffer : ResourceKind::Texture, true, false, true};
        Access a = Access::StorageWrite;
        if (l.kind == ResourceKind::Buffer) {
            l.slot = sb_.buffer(name, 256u << pick(6));
            a = choose({Access::StorageWrite, Access::TransferDst, Access::AccelBuildWrite});
        } else {
            l.depth = raster && chance(3);
            if (!l.depth && o_.subresources) {
                l.mips = chance(3) ? 3 : 1;
                l.layers = chance(4) ? 2 : 1;
            }
            const VkFormat format =
                l.depth ? VK_FORMAT_D32_SFLOAT
                        : choose({VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R32_SFLOAT});
            l.slot = sb_.texture(name, tex(o_.extent, o_.extent, format, l.layers, l.mips));
            if (l.depth)
                a = Access::DepthWrite;
            else if (raster && chance(2))
                a = Access::ColorAttachment;
            else
                a = chance(4) ? Access::TransferDst : Access::StorageWrite;
        }
        write(pass, l.slot, a);
        live_.push_back(l);
        return l.slot;
    }

    const RandomOptions& o_;
    std::mt19937_64 rng_;
    ScriptBuilder sb_;
    std::vector<Live> live_;
};

} // namespace

Script randomFrame(const RandomOptions& options) { return RandomFrame(options).build(); }

QueueCaps twoQueueCaps() { return QueueCaps{true, 0, 1, true, true}; }
QueueCaps oneQueueCaps() { return QueueCaps{false, 0, 0, true, true}; }

} // namespace glint::rg::synthetic
