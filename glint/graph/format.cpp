// Printing a Plan: text for logs and diffs, Graphviz DOT for looking at it,
// JSON for tools. All three are deterministic for a given Plan.

#include <cstdio>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "glint/graph/compile_state.h"
#include "glint/graph/plan.h"

namespace glint::rg {
namespace {

template <class Flags>
std::string flagNames(Flags flags, std::initializer_list<std::pair<Flags, const char*>> names) {
    if (!flags) return "NONE";
    std::string out;
    for (const auto& [bit, name] : names) {
        if ((flags & bit) != bit) continue;
        flags &= ~bit;
        if (!out.empty()) out += '|';
        out += name;
    }
    if (flags) {
        char hex[32];
        std::snprintf(hex, sizeof hex, "%s0x%llx", out.empty() ? "" : "|", static_cast<unsigned long long>(flags));
        out += hex;
    }
    return out;
}

std::string stageNames(VkPipelineStageFlags2 s) {
    return flagNames<VkPipelineStageFlags2>(s, {{VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, "ALL_COMMANDS"},
                                                {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, "TRANSFER"},
                                                {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, "DRAW_INDIRECT"},
                                                {VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, "VERTEX"},
                                                {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, "FRAGMENT"},
                                                {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT, "EARLY_TESTS"},
                                                {VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, "LATE_TESTS"},
                                                {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, "COLOR_OUTPUT"},
                                                {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, "COMPUTE"},
                                                {VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR, "RAY_TRACING"},
                                                {VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, "AS_BUILD"},
                                                {VK_PIPELINE_STAGE_2_HOST_BIT, "HOST"}});
}

std::string accessNames(VkAccessFlags2 a) {
    return flagNames<VkAccessFlags2>(a, {{VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, "SAMPLED_READ"},
                                         {VK_ACCESS_2_SHADER_STORAGE_READ_BIT, "STORAGE_READ"},
                                         {VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, "STORAGE_WRITE"},
                                         {VK_ACCESS_2_SHADER_READ_BIT, "SHADER_READ"},
                                         {VK_ACCESS_2_UNIFORM_READ_BIT, "UNIFORM_READ"},
                                         {VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT, "COLOR_READ"},
                                         {VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, "COLOR_WRITE"},
                                         {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, "DEPTH_READ"},
                                         {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, "DEPTH_WRITE"},
                                         {VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT, "INDIRECT_READ"},
                                         {VK_ACCESS_2_TRANSFER_READ_BIT, "TRANSFER_READ"},
                                         {VK_ACCESS_2_TRANSFER_WRITE_BIT, "TRANSFER_WRITE"},
                                         {VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR, "AS_READ"},
                                         {VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, "AS_WRITE"},
                                         {VK_ACCESS_2_MEMORY_READ_BIT, "MEMORY_READ"},
                                         {VK_ACCESS_2_MEMORY_WRITE_BIT, "MEMORY_WRITE"}});
}

std::string layoutName(VkImageLayout l) {
    switch (l) {
        case VK_IMAGE_LAYOUT_UNDEFINED:
            return "UNDEFINED";
        case VK_IMAGE_LAYOUT_GENERAL:
            return "GENERAL";
        case VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL:
            return "READ_ONLY";
        case VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL:
            return "ATTACHMENT";
        case VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL:
            return "TRANSFER_SRC";
        case VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL:
            return "TRANSFER_DST";
        case VK_IMAGE_LAYOUT_PRESENT_SRC_KHR:
            return "PRESENT_SRC";
        case VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL:
            return "SHADER_READ_ONLY";
        case VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL:
            return "COLOR_ATTACHMENT";
        case VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL:
            return "DEPTH_STENCIL_ATTACHMENT";
        default:
            return "layout " + std::to_string(static_cast<int>(l));
    }
}

std::string formatName(VkFormat f) {
    switch (f) {
        case VK_FORMAT_R8_UNORM:
            return "R8_UNORM";
        case VK_FORMAT_R8G8_UNORM:
            return "R8G8_UNORM";
        case VK_FORMAT_R8G8B8A8_UNORM:
            return "R8G8B8A8_UNORM";
        case VK_FORMAT_R8G8B8A8_SRGB:
            return "R8G8B8A8_SRGB";
        case VK_FORMAT_B8G8R8A8_UNORM:
            return "B8G8R8A8_UNORM";
        case VK_FORMAT_B8G8R8A8_SRGB:
            return "B8G8R8A8_SRGB";
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
            return "A2B10G10R10_UNORM";
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
            return "B10G11R11_UFLOAT";
        case VK_FORMAT_R16_SFLOAT:
            return "R16_SFLOAT";
        case VK_FORMAT_R16G16_SFLOAT:
            return "R16G16_SFLOAT";
        case VK_FORMAT_R16G16B16A16_SFLOAT:
            return "R16G16B16A16_SFLOAT";
        case VK_FORMAT_R32_SFLOAT:
            return "R32_SFLOAT";
        case VK_FORMAT_R32_UINT:
            return "R32_UINT";
        case VK_FORMAT_R32G32_SFLOAT:
            return "R32G32_SFLOAT";
        case VK_FORMAT_R32G32B32A32_SFLOAT:
            return "R32G32B32A32_SFLOAT";
        case VK_FORMAT_D16_UNORM:
            return "D16_UNORM";
        case VK_FORMAT_D32_SFLOAT:
            return "D32_SFLOAT";
        case VK_FORMAT_D24_UNORM_S8_UINT:
            return "D24_UNORM_S8_UINT";
        case VK_FORMAT_D32_SFLOAT_S8_UINT:
            return "D32_SFLOAT_S8_UINT";
        default:
            return "format " + std::to_string(static_cast<int>(f));
    }
}

std::string originName(ir::Origin o) {
    switch (o) {
        case ir::Origin::Transient:
            return "transient";
        case ir::Origin::Imported:
            return "imported";
        case ir::Origin::HistoryPrevious:
            return "history-previous";
        case ir::Origin::HistoryCurrent:
            return "history-current";
    }
    return "?";
}

std::string mib(uint64_t bytes) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
    return buf;
}

std::string accessSetNames(AccessSet kinds) {
    std::string out;
    for (uint32_t k = 0; k < kAccessCount; ++k) {
        if ((kinds & (1u << k)) == 0) continue;
        if (!out.empty()) out += '+';
        out += toString(static_cast<Access>(k));
    }
    return out;
}

std::string barrierText(const Plan& plan, const Barrier& b) {
    return detail::describeBarrier(plan.resourceName(b.resource), b, plan.resources[b.resource].kind);
}

std::string waitText(const SemaphoreWait& w) {
    if (w.batch == SemaphoreWait::kLastSignalled) {
        return std::string(toString(w.queue)) + "'s last signal at " + stageNames(w.stages);
    }
    return std::string(toString(w.queue)) + " batch " + std::to_string(w.batch) +
           (w.frameOffset < 0 ? " of the previous frame" : "") + " at " + stageNames(w.stages);
}

std::string describeResource(const Plan& plan, uint32_t r) {
    const ir::Resource& res = plan.declaration->resources[r];
    if (res.kind == ResourceKind::Texture) {
        const TextureDesc& t = res.texture;
        std::string s = std::to_string(t.width) + "x" + std::to_string(t.height);
        if (t.depth > 1) s += "x" + std::to_string(t.depth);
        if (t.layers > 1) s += "[" + std::to_string(t.layers) + "]";
        if (t.mips > 1) s += " " + std::to_string(t.mips) + " mips";
        return s + " " + formatName(t.format);
    }
    if (res.kind == ResourceKind::Buffer) return std::to_string(res.buffer.size) + " bytes";
    return "acceleration structure";
}

// Graphviz node ids: a letter and an index.
std::string nodeId(char kind, size_t index) {
    std::string id(1, kind);
    id += std::to_string(index);
    return id;
}

std::string dotEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out;
}

} // namespace

namespace detail {

std::string describeBarrier(std::string_view resource, const Barrier& b, ResourceKind kind) {
    std::string s = "'";
    s += resource;
    s += "'";
    if (kind == ResourceKind::Texture)
        s += " mips " + std::to_string(b.range.baseMip) + "+" + std::to_string(b.range.mipCount) + " layers " +
             std::to_string(b.range.baseLayer) + "+" + std::to_string(b.range.layerCount);
    s += ": " + stageNames(b.srcStages) + " [" + accessNames(b.srcAccess) + "] -> " + stageNames(b.dstStages) + " [" +
         accessNames(b.dstAccess) + "]";
    if (kind == ResourceKind::Texture) s += ", " + layoutName(b.oldLayout) + " -> " + layoutName(b.newLayout);
    if (b.aliasing) s += ", aliasing";
    return s;
}

} // namespace detail

std::string Plan::toText() const {
    std::string out;
    out += "plan: " + std::to_string(passes.size()) + " passes, " + std::to_string(batches.size()) + " batches, " +
           std::to_string(barriers.size()) + " barriers, " + std::to_string(waits.size()) + " waits\n";
    out += "queues: graphics family " + std::to_string(family(Queue::Graphics)) +
           (caps.separateComputeFamily ? ", async-compute family " + std::to_string(family(Queue::AsyncCompute))
                                       : ", async compute runs on graphics") +
           "\n";
    if (!culled.empty()) {
        out += "culled:";
        for (uint32_t p : culled) out += " '" + std::string(declaration->passes[p].name) + "'";
        out += "\n";
    }
    // Negative on tiny graphs: padding placements to bufferImageGranularity
    // can cost more than sharing saves.
    const double saved = stats.transientBytes ? 100.0 * (1.0 - static_cast<double>(stats.aliasedTransientBytes) /
                                                                   static_cast<double>(stats.transientBytes))
                                              : 0.0;
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.1f%%", saved);
    out += "transients: " + mib(stats.transientBytes) + " unaliased, " + mib(stats.aliasedTransientBytes) + " in " +
           std::to_string(heaps.size()) + " heaps (" + pct + " saved)\n";
    for (uint32_t b = 0; b < batches.size(); ++b) {
        const Batch& batch = batches[b];
        out += "batch " + std::to_string(b) + ": " + std::string(toString(batch.queue)) + " #" +
               std::to_string(batch.ordinal) + "\n";
        for (const SemaphoreWait& w : waitsOf(batch)) out += "  wait " + waitText(w) + "\n";
        for (const PlannedPass& p : passesOf(batch)) {
            out += "  pass '" + std::string(passName(p)) + "' (" + std::string(toString(pipeline(p))) + ", timestamps " +
                   std::to_string(p.timestampQuery) + "-" + std::to_string(p.timestampQuery + 1) +
                   (p.skipped ? ", skipped" : "") + ")\n";
            for (const Barrier& br : barriersBefore(p)) out += "    barrier " + barrierText(*this, br) + "\n";
            for (const ir::Use& u : uses(p))
                out += std::string("    ") + (u.writes ? "write " : "read  ") + "'" + std::string(resourceName(u.resource)) + "' " +
                       accessSetNames(u.kinds) + "\n";
        }
        for (const Barrier& br : barriersAfter(batch)) out += "  end barrier " + barrierText(*this, br) + "\n";
        out += "  signal " + std::string(toString(batch.queue)) + " timeline\n";
    }
    for (uint32_t r = 0; r < resources.size(); ++r) {
        const PlannedResource& res = resources[r];
        if (!res.used && res.origin != ir::Origin::Imported) continue;
        out += "resource '" + std::string(resourceName(r)) + "' " + originName(res.origin) + " " + describeResource(*this, r);
        if (res.heap != kNoIndex)
            out += ", heap " + std::to_string(res.heap) + " @" + std::to_string(res.offset) + " +" +
                   std::to_string(res.size);
        if (res.crossQueue) out += ", both queues (concurrent)";
        if (res.used)
            out += ", passes " + std::to_string(res.firstPass) + ".." + std::to_string(res.lastPass);
        else
            out += ", unused";
        out += "\n";
    }
    return out;
}

std::string Plan::toDot() const {
    std::string out = "digraph plan {\n  rankdir=LR;\n  compound=true;\n  node [fontname=\"monospace\"];\n";
    for (uint32_t b = 0; b < batches.size(); ++b) {
        const Batch& batch = batches[b];
        out += "  subgraph cluster_batch" + std::to_string(b) + " {\n    label=\"" +
               std::string(toString(batch.queue)) + " batch " + std::to_string(batch.ordinal) +
               "\";\n    style=rounded; color=" + (batch.queue == Queue::Graphics ? "steelblue" : "darkorange") + ";\n";
        for (const PlannedPass& p : passesOf(batch)) {
            std::string label = std::string(passName(p));
            for (const Barrier& br : barriersBefore(p)) label += "\\n| " + barrierText(*this, br);
            out += "    " + nodeId('p', static_cast<size_t>(&p - passes.data())) + " [shape=box, label=\"" +
                   dotEscape(label) + "\"];\n";
        }
        if (batch.endBarrierCount) {
            std::string label = "end of frame";
            for (const Barrier& br : barriersAfter(batch)) label += "\\n| " + barrierText(*this, br);
            out += "    " + nodeId('e', b) + " [shape=note, label=\"" + dotEscape(label) + "\"];\n";
        }
        out += "  }\n";
    }
    for (uint32_t r = 0; r < resources.size(); ++r) {
        if (!resources[r].used) continue;
        out += "  " + nodeId('r', r) + " [shape=ellipse, label=\"" +
               dotEscape(std::string(resourceName(r)) + "\\n" + describeResource(*this, r)) + "\"" +
               (resources[r].origin == ir::Origin::Transient ? "" : ", style=dashed") + "];\n";
    }
    for (uint32_t i = 0; i < passes.size(); ++i) {
        for (const ir::Use& u : uses(passes[i])) {
            const std::string pass = nodeId('p', i), res = nodeId('r', u.resource);
            out += "  " + (u.writes ? pass + " -> " + res : res + " -> " + pass) + " [label=\"" +
                   dotEscape(accessSetNames(u.kinds)) + "\"];\n";
        }
    }
    // Semaphores: from the signalling batch's last pass to the waiting batch's first.
    for (uint32_t b = 0; b < batches.size(); ++b) {
        const Batch& batch = batches[b];
        for (const SemaphoreWait& w : waitsOf(batch)) {
            uint32_t from = kNoIndex;
            for (uint32_t s = 0; s < batches.size(); ++s)
                if (batches[s].queue == w.queue && batches[s].ordinal == w.batch) from = s;
            if (from == kNoIndex || !batches[from].passCount) continue;
            const std::string tail = nodeId('p', batches[from].firstPass + batches[from].passCount - 1);
            const std::string head = batch.passCount ? nodeId('p', batch.firstPass) : nodeId('e', b);
            out += "  " + tail + " -> " + head + " [style=" + (w.frameOffset < 0 ? "dotted" : "dashed") +
                   ", color=red, constraint=false, label=\"" +
                   dotEscape("semaphore" + std::string(w.frameOffset < 0 ? " (next frame)" : "") + " @ " +
                             stageNames(w.stages)) +
                   "\"];\n";
        }
    }
    out += "}\n";
    return out;
}

std::string Plan::toJson() const {
    using nlohmann::json;
    json j;
    j["caps"] = {{"separateComputeFamily", caps.separateComputeFamily},
                 {"graphicsFamily", caps.graphicsFamily},
                 {"computeFamily", caps.computeFamily},
                 {"rayQuery", caps.rayQuery},
                 {"rayTracingPipeline", caps.rayTracingPipeline}};
    j["stats"] = {{"declaredPasses", stats.declaredPasses},
                  {"culledPasses", stats.culledPasses},
                  {"transientBytes", stats.transientBytes},
                  {"aliasedTransientBytes", stats.aliasedTransientBytes}};
    json culledNames = json::array();
    for (uint32_t p : culled) culledNames.push_back(declaration->passes[p].name);
    j["culled"] = culledNames;

    auto barrierJson = [&](const Barrier& b) {
        json o = {{"resource", resourceName(b.resource)},  {"srcStages", stageNames(b.srcStages)},
                  {"srcAccess", accessNames(b.srcAccess)}, {"dstStages", stageNames(b.dstStages)},
                  {"dstAccess", accessNames(b.dstAccess)}, {"aliasing", b.aliasing}};
        if (resources[b.resource].kind == ResourceKind::Texture) {
            o["mips"] = {b.range.baseMip, b.range.mipCount};
            o["layers"] = {b.range.baseLayer, b.range.layerCount};
            o["oldLayout"] = layoutName(b.oldLayout);
            o["newLayout"] = layoutName(b.newLayout);
        }
        return o;
    };

    json batchArray = json::array();
    for (const Batch& batch : batches) {
        json b;
        b["queue"] = toString(batch.queue);
        b["ordinal"] = batch.ordinal;
        json waitArray = json::array();
        for (const SemaphoreWait& w : waitsOf(batch))
            waitArray.push_back({{"queue", toString(w.queue)},
                                 {"batch", w.batch},
                                 {"frameOffset", w.frameOffset},
                                 {"stages", stageNames(w.stages)}});
        b["waits"] = waitArray;
        json passArray = json::array();
        for (const PlannedPass& p : passesOf(batch)) {
            json pj;
            pj["name"] = passName(p);
            pj["pipeline"] = toString(pipeline(p));
            pj["timestampQuery"] = p.timestampQuery;
            json barrierArray = json::array();
            for (const Barrier& br : barriersBefore(p)) barrierArray.push_back(barrierJson(br));
            pj["barriers"] = barrierArray;
            json useArray = json::array();
            for (const ir::Use& u : uses(p))
                useArray.push_back({{"resource", resourceName(u.resource)},
                                    {"access", accessSetNames(u.kinds)},
                                    {"writes", u.writes},
                                    {"version", u.version}});
            pj["uses"] = useArray;
            passArray.push_back(pj);
        }
        b["passes"] = passArray;
        json endArray = json::array();
        for (const Barrier& br : barriersAfter(batch)) endArray.push_back(barrierJson(br));
        b["endBarriers"] = endArray;
        batchArray.push_back(b);
    }
    j["batches"] = batchArray;

    json resourceArray = json::array();
    for (uint32_t r = 0; r < resources.size(); ++r) {
        const PlannedResource& res = resources[r];
        json o = {{"name", resourceName(r)},
                  {"kind", toString(res.kind)},
                  {"origin", originName(res.origin)},
                  {"description", describeResource(*this, r)},
                  {"used", res.used},
                  {"crossQueue", res.crossQueue},
                  {"imageUsage", res.imageUsage},
                  {"bufferUsage", res.bufferUsage}};
        if (res.used) o["passes"] = {res.firstPass, res.lastPass};
        if (res.heap != kNoIndex) o["memory"] = {{"heap", res.heap}, {"offset", res.offset}, {"size", res.size}};
        if (res.partner != kNoIndex) {
            o["partner"] = resourceName(res.partner);
            o["entryLayout"] = layoutName(res.entryLayout);
        }
        resourceArray.push_back(o);
    }
    j["resources"] = resourceArray;

    json heapArray = json::array();
    for (const MemoryHeap& h : heaps)
        heapArray.push_back({{"queue", toString(h.queue)},
                             {"crossQueue", h.crossQueue},
                             {"images", h.images},
                             {"buffers", h.buffers},
                             {"memoryTypeBits", h.memoryTypeBits},
                             {"size", h.size},
                             {"alignment", h.alignment}});
    j["heaps"] = heapArray;
    return j.dump(2);
}

} // namespace glint::rg
