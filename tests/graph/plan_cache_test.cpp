// Plan reuse (plan_cache.h): a reused plan is exactly what a fresh compile
// of the same declaration gives, with that declaration's callbacks; every
// kind of change to a declaration misses the cache.

#include <doctest/doctest.h>

#include <functional>
#include <string>

#include "glint/graph/plan_cache.h"
#include "glint/graph/verify.h"
#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

synthetic::Script randomScript(uint64_t seed) {
    synthetic::RandomOptions options;
    options.seed = seed;
    options.passes = 6 + static_cast<uint32_t>(seed % 40);
    options.asyncCompute = seed % 3 != 0;
    return synthetic::randomFrame(options);
}

// Compiles `script` through the cache and, separately, afresh; both must
// agree, and the cached plan must call this declaration's callbacks.
Plan throughCache(PlanCache& cache, const synthetic::Script& script, const QueueCaps& caps,
                  const CompileOptions& options = {}) {
    Graph g(caps);
    synthetic::declare(g, script);
    Plan cached = cache.compile(g, options);
    const Plan fresh = compile(g, caps, options);
    REQUIRE(cached.declaration.get() == &g.declaration());
    REQUIRE(cached.toText() == fresh.toText());  // every pass, batch, wait, barrier and placement
    return cached;
}

} // namespace

TEST_CASE("a reused plan is the plan a fresh compile gives, over 2000 random graphs") {
    for (const QueueCaps& caps : {synthetic::twoQueueCaps(), synthetic::oneQueueCaps()}) {
        PlanCache cache(2);
        for (uint64_t seed = 1; seed <= 1000; ++seed) {
            INFO("seed " << seed << ", " << (caps.separateComputeFamily ? "two queues" : "one queue"));
            const synthetic::Script script = randomScript(seed);
            const uint64_t hits = cache.hits(), misses = cache.misses();
            throughCache(cache, script, caps);  // first sight: compiled
            CHECK(cache.misses() == misses + 1);
            const Plan reused = throughCache(cache, script, caps);  // the same shape again: reused
            CHECK(cache.hits() == hits + 1);
            if (seed % 16 == 0) REQUIRE(verify(reused).ok());
        }
    }
}

TEST_CASE("a reused plan holds the new frame's declaration, and the cache keeps nothing of an old frame's") {
    PlanCache cache;
    auto token = std::make_shared<int>(7);
    const std::weak_ptr<int> watch = token;
    for (int frame = 0; frame < 2; ++frame) {
        Graph g(oneQueue());
        Texture t = g.createTexture("t", tex());
        g.addPass("write", Queue::Graphics, [&](Builder& b) { t = b.write(t, Access::StorageWrite); },
                  [keep = frame == 0 ? token : nullptr](PassContext&) {});
        g.markOutput(t);
        const Plan plan = cache.compile(g);
        REQUIRE(plan.passes.size() == 1);
        CHECK(plan.declaration.get() == &g.declaration());  // this frame's names and callbacks
    }
    CHECK(cache.hits() == 1);
    token.reset();
    // Frame 0's callback (and what it captured) went with frame 0's plan
    // and graph: the cached plan holds no declaration.
    CHECK(watch.expired());
}

TEST_CASE("every kind of change to a declaration misses the cache, and its plan is a fresh compile's") {
    const synthetic::Script base = synthetic::reflectionFrame({.width = 640, .height = 360});
    const QueueCaps caps = synthetic::twoQueueCaps();
    PlanCache cache(64);
    throughCache(cache, base, caps);
    throughCache(cache, base, caps);
    REQUIRE(cache.hits() == 1);

    // Each change on a copy of the base frame, compiled after the base and
    // all earlier changes are cached: it must be a miss.
    const auto expectMiss = [&](const char* what, const std::function<void(synthetic::Script&)>& change,
                                const QueueCaps& withCaps, const CompileOptions& options) {
        INFO(what);
        synthetic::Script s = base;
        change(s);
        const uint64_t misses = cache.misses();
        throughCache(cache, s, withCaps, options);
        CHECK(cache.misses() == misses + 1);
    };
    const auto none = [](synthetic::Script&) {};
    const auto firstTexture = [](synthetic::Script& s) -> synthetic::ScriptResource& {
        for (synthetic::ScriptResource& r : s.resources)
            if (r.kind == ResourceKind::Texture && r.origin == glint::rg::ir::Origin::Transient) return r;
        FAIL("no transient texture");
        return s.resources.front();
    };
    expectMiss("a texture's width", [&](synthetic::Script& s) { firstTexture(s).texture.width += 1; }, caps, {});
    expectMiss("a texture's format",
               [&](synthetic::Script& s) {
                   synthetic::ScriptResource& r = firstTexture(s);
                   r.texture.format = r.texture.format == VK_FORMAT_R16G16B16A16_SFLOAT ? VK_FORMAT_R32G32B32A32_SFLOAT
                                                                                        : VK_FORMAT_R16G16B16A16_SFLOAT;
               },
               caps, {});
    expectMiss("a buffer's size",
               [](synthetic::Script& s) {
                   for (synthetic::ScriptResource& r : s.resources)
                       if (r.kind == ResourceKind::Buffer && r.origin == glint::rg::ir::Origin::Transient) {
                           r.buffer.size += 256;
                           return;
                       }
                   FAIL("no transient buffer");
               },
               caps, {});
    expectMiss("an access",
               [](synthetic::Script& s) {
                   for (synthetic::ScriptPass& p : s.passes)
                       for (synthetic::ScriptUse& u : p.uses)
                           if (u.access == Access::SampledRead && p.pipeline == Pipeline::Compute &&
                               s.resources[u.slot].kind == ResourceKind::Texture) {
                               u.access = Access::StorageRead;
                               return;
                           }
                   FAIL("no sampled texture read in a compute pass");
               },
               caps, {});
    expectMiss("a pass's queue",
               [](synthetic::Script& s) {
                   for (synthetic::ScriptPass& p : s.passes)
                       if (p.queue == Queue::AsyncCompute) {
                           p.queue = Queue::Graphics;
                           return;
                       }
                   FAIL("no async pass");
               },
               caps, {});
    expectMiss("a pass with side effects", [](synthetic::Script& s) { s.passes.back().sideEffects = true; }, caps,
               {});
    expectMiss("an import's boundary state",
               [](synthetic::Script& s) {
                   for (synthetic::ScriptResource& r : s.resources)
                       if (r.origin == glint::rg::ir::Origin::Imported && r.kind == ResourceKind::Texture &&
                           r.final) {
                           r.final = BoundaryState::of(r.final->access == Access::TransferSrc ? Access::SampledRead
                                                                                            : Access::TransferSrc);
                           return;
                       }
                   FAIL("no imported texture with a final state");
               },
               caps, {});
    expectMiss("one more pass",
               [](synthetic::Script& s) {
                   synthetic::ScriptPass p = s.passes.back();
                   p.name += ".again";
                   s.passes.push_back(p);
               },
               caps, {});
    expectMiss("aliasing off", none, caps, CompileOptions{.aliasing = false});
    expectMiss("one queue", none, synthetic::oneQueueCaps(), {});
    QueueCaps granularity = caps;
    granularity.bufferImageGranularity = 1024;
    expectMiss("the buffer-image granularity", none, granularity, {});

    // Names alone are not structure: a renamed frame reuses the plan, with
    // its own names.
    synthetic::Script renamed = base;
    for (synthetic::ScriptPass& p : renamed.passes) p.name = "renamed." + p.name;
    const uint64_t hits = cache.hits();
    const Plan plan = throughCache(cache, renamed, caps);
    CHECK(cache.hits() == hits + 1);
    CHECK(std::string(plan.passName(plan.passes.front())).rfind("renamed.", 0) == 0);
}

TEST_CASE("the cache keeps its capacity's worth of shapes, dropping the least recently used") {
    PlanCache cache(2);
    const QueueCaps caps = synthetic::oneQueueCaps();
    const synthetic::Script a = randomScript(11), b = randomScript(12), c = randomScript(13);
    throughCache(cache, a, caps);
    throughCache(cache, b, caps);
    throughCache(cache, a, caps);  // a is now the most recent
    throughCache(cache, c, caps);  // b goes
    CHECK(cache.size() == 2);
    const uint64_t misses = cache.misses();
    throughCache(cache, a, caps);
    CHECK(cache.misses() == misses);
    throughCache(cache, b, caps);
    CHECK(cache.misses() == misses + 1);
}
