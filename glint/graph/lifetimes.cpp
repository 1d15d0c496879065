// ---- Lifetimes --------------------------------------------------------------
// First and last use of every resource in schedule order, the queues that
// touch it and the access kinds it takes, counting surviving passes only:
// usage flags come from here, after culling, so a culled pass cannot leave
// a usage bit (or a memory cost) behind. Device-dependent misuse is caught
// here too, since only compile() knows the device.

#include <algorithm>
#include <string>

#include <spdlog/spdlog.h>

#include "glint/graph/compile_state.h"
#include "glint/graph/error.h"
#include "glint/graph/memory.h"

namespace glint::rg::detail {
namespace {

[[noreturn]] void rayQueryUnsupported(const CompileState& st, const ir::Pass& pass) {
    const ir::Declaration& d = st.decl;
    const ir::Use* uses = d.uses.data() + pass.firstUse;
    uint32_t u = 0;
    while (!(uses[u].kinds & accessBit(Access::AccelRead))) ++u;
    throw GraphError(ErrorKind::UnsupportedFeature, pass.name, d.resources[uses[u].resource].name,
                     "reads an acceleration structure with a ray query, which the device does not support");
}

} // namespace

void computeLifetimes(CompileState& st) {
    const ir::Declaration& d = st.decl;
    st.lifetimes.assign(d.resources.size(), Lifetime{});
    // Reading a structure outside a ray tracing pipeline is a ray query.
    // Checked once per pass on the union of its uses' kinds (which the pass
    // keeps), not per use: the error names the first offending use either
    // way.
    const AccessSet rayQueryRead = st.caps.rayQuery ? AccessSet{0} : accessBit(Access::AccelRead);

    // The loops work through local pointers: their byte-sized stores (queue
    // bits, flags) may alias anything as far as the compiler knows, which
    // would reload every vector's data pointer after each one.
    Lifetime* const lifetimes = st.lifetimes.data();
    const uint32_t* const order = st.order.data();
    const Queue* const queueOf = st.queueOf.data();
    const ir::Use* const allUses = d.uses.data();
    const auto scheduled = static_cast<uint32_t>(st.order.size());
    for (uint32_t pos = 0; pos < scheduled; ++pos) {
        const uint32_t p = order[pos];
        const ir::Pass& pass = d.passes[p];
        const uint8_t queueBit = static_cast<uint8_t>(1u << queueIndex(queueOf[p]));
        if (pass.pipeline == Pipeline::RayTracing && !st.caps.rayTracingPipeline)
            throw GraphError(ErrorKind::UnsupportedFeature, pass.name,
                             pass.useCount ? d.resources[d.uses[pass.firstUse].resource].name : std::string(),
                             "uses a ray tracing pipeline, which the device does not support");
        if ((pass.kinds & rayQueryRead) && pass.pipeline != Pipeline::RayTracing) rayQueryUnsupported(st, pass);
        const ir::Use* const uses = allUses + pass.firstUse;
        const uint32_t useCount = pass.useCount;
        for (uint32_t u = 0; u < useCount; ++u) {
            const ir::Use& use = uses[u];
            Lifetime& life = lifetimes[use.resource];
            // Positions only grow and kNoIndex is the largest: the minimum
            // keeps the first use without a branch.
            life.first = std::min(life.first, pos);
            life.last = pos;
            life.queues |= queueBit;
            life.kinds |= use.kinds;
        }
    }

    const auto resourceCount = static_cast<uint32_t>(d.resources.size());
    st.plan.resources.assign(resourceCount, PlannedResource{});
    PlannedResource* const planned = st.plan.resources.data();
    const ir::Resource* const resources = d.resources.data();
    std::vector<uint32_t>& startKnown = st.startKnown;
    startKnown.clear();
    for (uint32_t r = 0; r < resourceCount; ++r) {
        const ir::Resource& res = resources[r];
        const Lifetime& life = lifetimes[r];
        PlannedResource& out = planned[r];
        if (res.origin != ir::Origin::Transient || life.crossQueue()) startKnown.push_back(r);
        out.kind = res.kind;
        out.origin = res.origin;
        out.partner = res.partner;
        out.used = life.used();
        out.crossQueue = life.crossQueue();
        out.queue = life.used() ? queueOf[order[life.first]] : Queue::Graphics;
        // A history pair's two images trade roles every frame, so each needs
        // the usage of both roles.
        AccessSet kinds = life.kinds;
        if (res.partner != kNoIndex) {
            const Lifetime& partner = lifetimes[res.partner];
            kinds |= partner.kinds;
            out.crossQueue = out.crossQueue || partner.crossQueue() || (life.queues | partner.queues) == 3;
        }
        if (res.kind == ResourceKind::Texture) {
            out.imageUsage = imageUsageFor(kinds);
            out.aspect = aspectOf(res.texture.format);
        } else if (res.kind == ResourceKind::Buffer) {
            out.bufferUsage = bufferUsageFor(kinds);
        }
    }
}

} // namespace glint::rg::detail
