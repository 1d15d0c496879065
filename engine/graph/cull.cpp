// ---- Cull -------------------------------------------------------------------
// A pass survives when something observable depends on it: it has side
// effects, or it produces a version that is an output, or a surviving pass
// uses what it produced. Outputs are the versions marked with markOutput()
// plus the last version of every import and of every history `current`
// (both are seen after this frame). A write depends on the version it
// overwrites: storage writes and attachment loads keep whatever they do not
// touch, so the earlier writer stays.

#include <spdlog/spdlog.h>

#include "graph/compile_state.h"

namespace glint::rg::detail {
namespace {

// The work list, kept between compiles on this thread so a frame loop does
// not allocate it every frame.
std::vector<uint32_t>& stackScratch() {
    thread_local std::vector<uint32_t> stack;
    return stack;
}

} // namespace

void cull(CompileState& st) {
    const ir::Declaration& d = st.decl;
    const auto passCount = static_cast<uint32_t>(d.passes.size());
    st.alive.assign(passCount, 0);
    std::vector<uint32_t>& stack = stackScratch();
    stack.clear();
    stack.reserve(passCount);

    auto keep = [&](uint32_t pass) {
        if (pass != kNoIndex && !st.alive[pass]) {
            st.alive[pass] = 1;
            stack.push_back(pass);
        }
    };

    for (uint32_t p = 0; p < passCount; ++p)
        if (d.passes[p].sideEffects) keep(p);
    for (const ir::Output& o : d.outputs) keep(o.producer);
    for (const ir::Resource& r : d.resources)
        if (r.origin == ir::Origin::Imported || r.origin == ir::Origin::HistoryCurrent) keep(r.lastWriter);

    while (!stack.empty()) {
        const uint32_t p = stack.back();
        stack.pop_back();
        const ir::Pass& pass = d.passes[p];
        const ir::Use* uses = d.uses.data() + pass.firstUse;
        for (uint32_t u = 0; u < pass.useCount; ++u) keep(uses[u].producer);
    }

    for (uint32_t p = 0; p < passCount; ++p) {
        if (st.alive[p]) continue;
        st.plan.culled.push_back(p);
        if (st.log) spdlog::debug("rg cull: '{}' (nothing observable depends on it)", d.passes[p].name);
    }
}

} // namespace glint::rg::detail
