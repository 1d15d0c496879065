// ---- Cull -------------------------------------------------------------------
// A pass survives when something observable depends on it: it has side
// effects, or it produces a version that is an output, or a surviving pass
// uses what it produced. Outputs are the versions marked with markOutput()
// plus the last version of every import and of every history `current`
// (both are seen after this frame). A write depends on the version it
// overwrites: storage writes and attachment loads keep whatever they do not
// touch, so the earlier writer stays.

#include <algorithm>

#include <spdlog/spdlog.h>

#include "glint/graph/compile_state.h"

namespace glint::rg::detail {

void cull(CompileState& st) {
    const ir::Declaration& d = st.decl;
    const auto passCount = static_cast<uint32_t>(d.passes.size());
    // One slot past the passes absorbs "no producer" (kNoIndex), so marking
    // a producer needs no branch: std::min sends kNoIndex there.
    st.alive.assign(passCount + 1, 0);
    uint8_t* const alive = st.alive.data();

    // Local pointers, and each pass's use count read once: the byte stores
    // could alias the vectors' data pointers and the count.
    const ir::Pass* const passes = d.passes.data();
    const ir::Use* const allUses = d.uses.data();
    for (uint32_t p = 0; p < passCount; ++p) alive[p] = passes[p].sideEffects ? 1 : 0;
    for (const ir::Output& o : d.outputs) alive[std::min(o.producer, passCount)] = 1;
    for (const ir::Resource& r : d.resources)
        if (r.origin == ir::Origin::Imported || r.origin == ir::Origin::HistoryCurrent)
            alive[std::min(r.lastWriter, passCount)] = 1;

    // A use's producer was declared before the pass using it (a version
    // exists only once its writer's setup has ended), so one sweep from the
    // last pass back reaches every pass after everything that uses it: no
    // work list needed.
    for (uint32_t p = passCount; p-- > 0;) {
        if (!alive[p]) continue;
        const ir::Use* const uses = allUses + passes[p].firstUse;
        const uint32_t useCount = passes[p].useCount;
        for (uint32_t u = 0; u < useCount; ++u) alive[std::min(uses[u].producer, passCount)] = 1;
    }
    st.alive.pop_back();

    for (uint32_t p = 0; p < passCount; ++p) {
        if (alive[p]) continue;
        st.plan.culled.push_back(p);
        if (st.log) spdlog::debug("rg cull: '{}' (nothing observable depends on it)", d.passes[p].name);
    }
}

} // namespace glint::rg::detail
