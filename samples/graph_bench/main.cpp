// glint-graph-bench: how long declaring and compiling a frame takes, per
// pass, for reflection-like and random graphs of 16, 128 and 1024 passes;
// and how much transient memory aliasing saves on the synthetic reflection
// frame (glint/graph/synthetic.h; the real frame's saving is measured by
// tests/gpu/reflection_frame_plan_test.cpp) at 1920x1080. The last line is machine-readable:
//   compile_us_per_pass_1024=<number> alias_saving_1080p=<percent>
// where the first number is the worse of the two 1024-pass shapes
// (declare + compile, barriers and aliasing included, two-queue device).
//
//   glint-graph-bench [--runs N] [--passes P]
// --runs N times each shape N times (default 41 at 1024 passes, 201 below);
// --passes P times only the graphs of P passes (16, 128 or 1024). A
// profiler wants both.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "glint/graph/compile.h"
#include "glint/graph/graph.h"
#include "glint/graph/synthetic.h"
#include "glint/graph/verify.h"

namespace {

using namespace glint::rg;
using Clock = std::chrono::steady_clock;

struct Timing {
    double declareUs; // per pass
    double compileUs; // per pass
    size_t barriers;
    size_t batches;
};

// Median of `runs` frames. Each frame declares a new graph (replaying a
// prepared script, so the generator's own cost stays out of the figure) and
// compiles it into the previous frame's plan, as a frame loop would.
Timing measure(const synthetic::Script& script, const QueueCaps& caps, int runs) {
    std::vector<double> declare, compile;
    size_t barriers = 0, batches = 0;
    const auto passes = static_cast<double>(script.passes.size());
    Plan plan;
    for (int i = 0; i < runs; ++i) {
        const auto t0 = Clock::now();
        Graph graph(caps);
        graph.reserve(static_cast<uint32_t>(script.passes.size()), static_cast<uint32_t>(script.slotCount),
                      static_cast<uint32_t>(script.passes.size() * 8));
        synthetic::declare(graph, script);
        const auto t1 = Clock::now();
        plan = graph.compile({}, std::move(plan));
        const auto t2 = Clock::now();
        declare.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / passes);
        compile.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count() / passes);
        barriers = plan.barriers.size();
        batches = plan.batches.size();
    }
    std::nth_element(declare.begin(), declare.begin() + runs / 2, declare.end());
    std::nth_element(compile.begin(), compile.begin() + runs / 2, compile.end());
    return {declare[runs / 2], compile[runs / 2], barriers, batches};
}

int run(int runsOverride, uint32_t onlyPasses) {
    const QueueCaps caps = synthetic::twoQueueCaps();
    std::printf("glint-graph-bench: declare + compile per pass (median), two-queue device\n");
    std::printf("%-16s %6s %12s %12s %12s %9s %8s\n", "shape", "passes", "declare_us", "compile_us", "total_us",
                "barriers", "batches");
    double worst1024 = 0;
    for (const uint32_t passes : {16u, 128u, 1024u}) {
        if (onlyPasses != 0 && passes != onlyPasses) continue;
        const int runs = runsOverride > 0 ? runsOverride : passes == 1024 ? 41 : 201;
        const synthetic::Script reflection = synthetic::tiledReflectionFrames(passes, 1920, 1080);
        synthetic::RandomOptions options;
        options.passes = passes;
        options.seed = 2024;
        const synthetic::Script random = synthetic::randomFrame(options);
        for (const auto& [name, script] : {std::pair{"reflection-like", &reflection}, std::pair{"random", &random}}) {
            const Timing t = measure(*script, caps, runs);
            std::printf("%-16s %6zu %12.3f %12.3f %12.3f %9zu %8zu\n", name, script->passes.size(), t.declareUs,
                        t.compileUs, t.declareUs + t.compileUs, t.barriers, t.batches);
            if (passes == 1024) worst1024 = std::max(worst1024, t.declareUs + t.compileUs);
        }
    }

    // Transient memory of one synthetic reflection frame at 1080p.
    Graph graph(caps);
    synthetic::declare(graph, synthetic::reflectionFrame({}));
    const Plan plan = graph.compile();
    const VerifyReport report = verify(plan);
    if (!report.ok()) {
        std::fprintf(stderr, "glint-graph-bench: the reflection plan fails verification:\n%s", report.text().c_str());
        return 1;
    }
    const double mib = 1024.0 * 1024.0;
    const double unaliased = static_cast<double>(plan.stats.transientBytes);
    const double aliased = static_cast<double>(plan.stats.aliasedTransientBytes);
    const double saving = 100.0 * (1.0 - aliased / unaliased);
    std::printf("synthetic reflection frame 1920x1080: transients %.1f MiB without aliasing, %.1f MiB with (%zu heaps)\n",
                unaliased / mib, aliased / mib, plan.heaps.size());
    std::printf("compile_us_per_pass_1024=%.3f alias_saving_1080p=%.1f\n", worst1024, saving);
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    // No GPU here: this links Glint::graph alone, so it parses its two
    // flags with CLI11 itself rather than through the samples' app::Args.
    int runs = 0;
    uint32_t passes = 0;
    CLI::App cli("glint-graph-bench: declare + compile cost of the render graph per pass, and what aliasing saves");
    cli.set_help_flag("-h,--help", "print this help and exit");
    cli.add_option("--runs", runs, "time each shape N times (default 41 at 1024 passes, 201 below)")
        ->check(CLI::PositiveNumber);
    cli.add_option("--passes", passes, "time only the graphs of P passes")->check(CLI::IsMember({16, 128, 1024}));
    try {
        cli.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::printf("%s", cli.help().c_str());
        return 0;
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "glint-graph-bench: error: %s (--help lists the flags)\n", e.what());
        return 2;
    }
    try {
        return run(runs, passes);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glint-graph-bench: %s\n", e.what());
        return 1;
    }
}
