// glint-graph-bench: how long declaring and compiling a frame takes, per
// pass, for reflection-like and random graphs of 16, 128 and 1024 passes;
// and how much transient memory aliasing saves on the synthetic reflection
// frame (glint/graph/synthetic.h; the real frame's saving is measured by
// tests/gpu/reflection_frame_plan_test.cpp) at 1920x1080; and a steady
// frame's cost with plan reuse (rg::PlanCache: declare, the shape compared
// with the cached one, the cached plan rebound). The last line is machine-readable:
//   compile_us_per_pass_1024=<number> alias_saving_1080p=<percent> reuse_us_per_pass_1024=<number>
// where the first number is the worse of the two 1024-pass shapes
// (declare + compile, barriers and aliasing included, two-queue device)
// and the last the worse of their declare + reuse.
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
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "glint/graph/compile.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan_cache.h"
#include "glint/graph/synthetic.h"
#include "glint/graph/verify.h"

namespace {

using namespace glint::rg;
using Clock = std::chrono::steady_clock;

struct Timing {
    double declareUs; // per pass
    double compileUs; // per pass
    double reuseUs;   // per pass: a cache hit (the shape compared, the plan rebound)
    size_t barriers;
    size_t batches;
};

double median(std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

// Median of `runs` frames. Each frame declares a new graph (replaying a
// prepared script, so the generator's own cost stays out of the figure) and
// compiles it into the previous frame's plan, as a frame loop would; then
// declares it again and takes its plan from a PlanCache (a hit after the
// first frame: the steady state of a frame loop whose shape holds).
Timing measure(const synthetic::Script& script, const QueueCaps& caps, int runs) {
    std::vector<double> declare, compile, reuse;
    size_t barriers = 0, batches = 0;
    const auto passes = static_cast<double>(script.passes.size());
    Plan plan;
    PlanCache cache;
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
        // The same frame again through the cache: after the first run,
        // every one is a hit.
        Graph steady(caps);
        steady.reserve(static_cast<uint32_t>(script.passes.size()), static_cast<uint32_t>(script.slotCount),
                       static_cast<uint32_t>(script.passes.size() * 8));
        synthetic::declare(steady, script);
        const auto t4 = Clock::now();
        const Plan& reused = cache.compile(steady);
        (void)reused;
        const auto t5 = Clock::now();
        if (i > 0) reuse.push_back(std::chrono::duration<double, std::micro>(t5 - t4).count() / passes);
    }
    if (cache.hits() + 1 != uint64_t(runs)) throw std::runtime_error("the plan cache missed a steady frame");
    return {median(declare), median(compile), reuse.empty() ? 0.0 : median(reuse), barriers, batches};
}

int run(int runsOverride, uint32_t onlyPasses) {
    const QueueCaps caps = synthetic::twoQueueCaps();
    std::printf("glint-graph-bench: declare + compile per pass (median), two-queue device\n");
    std::printf("%-16s %6s %12s %12s %12s %9s %8s %10s %10s\n", "shape", "passes", "declare_us", "compile_us",
                "total_us", "barriers", "batches", "reuse_us", "steady_us");
    double worst1024 = 0, worstReuse1024 = 0;
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
            std::printf("%-16s %6zu %12.3f %12.3f %12.3f %9zu %8zu %10.3f %10.3f\n", name, script->passes.size(),
                        t.declareUs, t.compileUs, t.declareUs + t.compileUs, t.barriers, t.batches, t.reuseUs,
                        t.declareUs + t.reuseUs);
            if (passes == 1024) {
                worst1024 = std::max(worst1024, t.declareUs + t.compileUs);
                worstReuse1024 = std::max(worstReuse1024, t.declareUs + t.reuseUs);
            }
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
    std::printf("compile_us_per_pass_1024=%.3f alias_saving_1080p=%.1f reuse_us_per_pass_1024=%.3f\n", worst1024,
                saving, worstReuse1024);
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
