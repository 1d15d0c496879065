// libFuzzer target: render graph declarations decoded from the input
// (resources of every kind and origin, boundary states, passes on either
// queue with any pipeline, uses of any access on any resource and
// subresource range, outputs), declared, compiled for one or two queues
// and verified. An illegal declaration must end in a GraphError; whatever
// compiles must satisfy the verifier. Anything else (a crash, another
// exception, a plan the verifier rejects) aborts: a finding.
#include "fuzz_input.h"

#include "glint/graph/compile.h"
#include "glint/graph/error.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan.h"
#include "glint/graph/skip.h"
#include "glint/graph/synthetic.h"
#include "glint/graph/verify.h"

#include <cstdio>
#include <cstdlib>
#include <string>

using namespace glint;
using namespace glint::rg;

namespace {

constexpr VkFormat kFormats[] = {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT,
                                 VK_FORMAT_R32_UINT, VK_FORMAT_UNDEFINED};

// Reads in statement order: the order a function's arguments are
// evaluated in differs between compilers, and the replay build (GCC) must
// decode an input as the fuzz build (clang) did.
BoundaryState boundary(fuzz::Input& in) {
    const auto access = Access(in.below(kAccessCount));
    const auto queue = Queue(in.below(kQueueCount));
    const auto pipeline = Pipeline(in.below(3));
    return BoundaryState::of(access, queue, pipeline);
}

synthetic::Script decode(fuzz::Input& in) {
    synthetic::Script s;
    const uint32_t resources = 1 + in.below(8);
    for (uint32_t r = 0; r < resources; ++r) {
        synthetic::ScriptResource res;
        res.name = "r" + std::to_string(r);
        res.kind = ResourceKind(in.below(3));
        const uint32_t origin = in.below(4);
        res.origin = origin == 3 ? ir::Origin::HistoryCurrent : origin == 2 ? ir::Origin::Imported : ir::Origin::Transient;
        res.texture = {1 + in.below(64), 1 + in.below(64), 1 + (in.flag() ? in.below(3) : 0), 1 + in.below(3),
                       1 + in.below(4), kFormats[in.below(5)]};
        res.buffer = {in.below(4096)};
        if (res.origin == ir::Origin::Imported) {
            if (in.flag()) res.initial = boundary(in);
            if (in.flag()) res.final = boundary(in);
        }
        s.resources.push_back(res);
        s.slotCount += res.origin == ir::Origin::HistoryCurrent ? 2 : 1;
    }
    const uint32_t passes = 1 + in.below(12);
    for (uint32_t p = 0; p < passes; ++p) {
        synthetic::ScriptPass pass;
        pass.name = "p" + std::to_string(p);
        pass.queue = Queue(in.below(kQueueCount));
        pass.pipeline = Pipeline(in.below(3));
        pass.sideEffects = in.flag();
        const uint32_t uses = in.below(5);
        for (uint32_t u = 0; u < uses; ++u) {
            synthetic::ScriptUse use;
            use.slot = in.below(s.slotCount);  // the script is trusted to name its own slots
            use.access = Access(in.below(kAccessCount));
            if (in.flag()) {
                use.range = {in.below(4), in.flag() ? Subresource::kAll : in.below(4), in.below(3),
                             in.flag() ? Subresource::kAll : in.below(3)};
            }
            pass.uses.push_back(use);
        }
        s.passes.push_back(pass);
    }
    const uint32_t outputs = in.below(3);
    for (uint32_t o = 0; o < outputs; ++o) s.outputs.push_back(in.below(s.slotCount));
    return s;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    fuzz::Input in(data, size);
    const QueueCaps caps = in.flag() ? synthetic::twoQueueCaps() : synthetic::oneQueueCaps();
    const bool aliasing = in.flag();
    synthetic::Script script = decode(in);
    // What is left of the input says which passes this frame skips.
    bool skips = false;
    for (synthetic::ScriptPass& pass : script.passes) skips |= pass.skipped = in.flag();
    try {
        Graph graph(caps);
        synthetic::declare(graph, script);
        CompileOptions options;
        options.aliasing = aliasing;
        const Plan plan = compile(graph, caps, options);
        const VerifyReport report = verify(plan);
        if (!report.ok()) {
            std::fprintf(stderr, "graph fuzz: the verifier rejects a compiled plan:\n%s\n%s\n", report.text().c_str(),
                         plan.toText().c_str());
            std::abort();
        }
        if (skips) {
            // The frame as the executor runs it: the skipped passes'
            // barriers carried on and merged. Redundancy is not asked: a
            // carried barrier may have served only the pass that skipped.
            const Plan frame = skipPasses(plan);
            VerifyOptions noRedundancy;
            noRedundancy.checkRedundancy = false;
            const VerifyReport skipped = verify(frame, noRedundancy);
            if (!skipped.ok()) {
                std::fprintf(stderr, "graph fuzz: the verifier rejects a plan with skipped passes:\n%s\n%s\n",
                             skipped.text().c_str(), frame.toText().c_str());
                std::abort();
            }
        }
    } catch (const GraphError&) {
        // An illegal declaration, said so: what the graph must do.
    }
    return 0;
}
