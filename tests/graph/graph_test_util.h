#pragma once

// Helpers for the render-graph tests: compile-and-verify, lookups by name,
// and plan surgery for the verifier's negative tests.

#include <doctest/doctest.h>

#include <string>
#include <string_view>
#include <vector>

#include "glint/graph/compile.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan.h"
#include "glint/graph/synthetic.h"
#include "glint/graph/verify.h"

namespace glint::rg::test {

inline QueueCaps twoQueues() { return synthetic::twoQueueCaps(); }
inline QueueCaps oneQueue() { return synthetic::oneQueueCaps(); }

inline TextureDesc tex(uint32_t size = 64, VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT, uint32_t mips = 1,
                       uint32_t layers = 1) {
    return TextureDesc{size, size, 1, layers, mips, format};
}

inline void noop(PassContext&) {}

// Every plan a test looks at must also satisfy the verifier.
inline Plan compileChecked(const Graph& graph, const QueueCaps& caps, const CompileOptions& options = {}) {
    Plan plan = compile(graph, caps, options);
    const VerifyReport report = verify(plan);
    INFO(plan.toText());
    INFO(report.text());
    CHECK(report.ok());
    return plan;
}

inline Plan compileChecked(const Graph& graph) { return compileChecked(graph, graph.caps()); }

inline const PlannedPass& passNamed(const Plan& plan, std::string_view name) {
    const PlannedPass* p = plan.findPass(name);
    INFO("pass " << name);
    REQUIRE(p != nullptr);
    return *p;
}

inline uint32_t resourceNamed(const Plan& plan, std::string_view name) {
    const uint32_t r = plan.findResource(name);
    INFO("resource " << name);
    REQUIRE(r != kNoIndex);
    return r;
}

// Barriers recorded before `pass` on `resource`.
inline std::vector<Barrier> barriersOn(const Plan& plan, std::string_view pass, std::string_view resource) {
    std::vector<Barrier> out;
    const uint32_t r = resourceNamed(plan, resource);
    for (const Barrier& b : plan.barriersBefore(passNamed(plan, pass)))
        if (b.resource == r) out.push_back(b);
    return out;
}

inline const Batch& batchOf(const Plan& plan, std::string_view pass) {
    return plan.batches[passNamed(plan, pass).batch];
}

inline bool culled(const Plan& plan, std::string_view pass) {
    for (uint32_t p : plan.culled)
        if (plan.declaration->passes[p].name == pass) return true;
    return false;
}

// Position of a pass in submission order.
inline uint32_t indexOf(const Plan& plan, std::string_view pass) {
    return static_cast<uint32_t>(&passNamed(plan, pass) - plan.passes.data());
}

// Plan surgery, keeping every range consistent.
inline Plan withoutBarrier(const Plan& plan, uint32_t index) {
    Plan m = plan;
    m.barriers.erase(m.barriers.begin() + index);
    for (PlannedPass& p : m.passes) {
        if (p.firstBarrier > index)
            --p.firstBarrier;
        else if (index < p.firstBarrier + p.barrierCount)
            --p.barrierCount;
    }
    for (Batch& b : m.batches) {
        if (b.firstEndBarrier > index)
            --b.firstEndBarrier;
        else if (index < b.firstEndBarrier + b.endBarrierCount)
            --b.endBarrierCount;
    }
    return m;
}

inline Plan withoutWait(const Plan& plan, uint32_t index) {
    Plan m = plan;
    m.waits.erase(m.waits.begin() + index);
    for (Batch& b : m.batches) {
        if (b.firstWait > index)
            --b.firstWait;
        else if (index < b.firstWait + b.waitCount)
            --b.waitCount;
    }
    return m;
}

inline uint32_t barrierIndex(const Plan& plan, std::string_view pass, std::string_view resource) {
    const PlannedPass& p = passNamed(plan, pass);
    const uint32_t r = resourceNamed(plan, resource);
    for (uint32_t i = p.firstBarrier; i < p.firstBarrier + p.barrierCount; ++i)
        if (plan.barriers[i].resource == r) return i;
    FAIL("no barrier on " << resource << " before " << pass);
    return kNoIndex;
}

inline bool contains(const std::string& text, std::string_view part) { return text.find(part) != std::string::npos; }

} // namespace glint::rg::test
