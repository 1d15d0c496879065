// A Plan prints as text, Graphviz DOT and JSON.

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "graph_test_util.h"

using namespace glint::rg;
using namespace glint::rg::test;

namespace {

Plan reflection(const QueueCaps& caps) {
    Graph g(caps);
    synthetic::declare(g, synthetic::reflectionFrame({}));
    return compileChecked(g);
}

size_t count(const std::string& text, std::string_view what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
    return n;
}

} // namespace

TEST_CASE("the text form lists batches, waits, passes, barriers and memory") {
    const Plan plan = reflection(twoQueues());
    const std::string text = plan.toText();
    CHECK(count(text, "\nbatch ") == plan.batches.size());
    CHECK(count(text, "  wait ") == plan.waits.size());
    CHECK(count(text, "  pass '") == plan.passes.size());
    CHECK(count(text, "barrier '") == plan.barriers.size());
    CHECK(contains(text, "pass 'sslr'"));
    CHECK(contains(text, "wait async-compute batch 0 at COMPUTE"));
    CHECK(contains(text, "of the previous frame at AS_BUILD"));
    CHECK(contains(text, "ATTACHMENT -> PRESENT_SRC"));
    CHECK(contains(text, "saved)"));
}

TEST_CASE("the DOT form has a node per pass and used resource, and an edge per semaphore") {
    const Plan plan = reflection(twoQueues());
    const std::string dot = plan.toDot();
    CHECK(dot.rfind("digraph plan {", 0) == 0);
    CHECK(count(dot, "[shape=box") == plan.passes.size());
    size_t used = 0;
    for (const PlannedResource& r : plan.resources) used += r.used;
    CHECK(count(dot, "[shape=ellipse") == used);
    CHECK(count(dot, "subgraph cluster_batch") == plan.batches.size());
    CHECK(count(dot, "label=\"semaphore") == plan.waits.size());
    CHECK(contains(dot, "async-compute batch 0"));
    CHECK(count(dot, "{") == count(dot, "}"));
}

TEST_CASE("the JSON form parses and matches the plan") {
    const Plan plan = reflection(twoQueues());
    const nlohmann::json j = nlohmann::json::parse(plan.toJson());
    REQUIRE(j["batches"].size() == plan.batches.size());
    size_t passes = 0, barriers = 0, waits = 0;
    for (const auto& b : j["batches"]) {
        passes += b["passes"].size();
        waits += b["waits"].size();
        barriers += b["endBarriers"].size();
        for (const auto& p : b["passes"]) barriers += p["barriers"].size();
    }
    CHECK(passes == plan.passes.size());
    CHECK(barriers == plan.barriers.size());
    CHECK(waits == plan.waits.size());
    CHECK(j["resources"].size() == plan.resources.size());
    CHECK(j["stats"]["transientBytes"].get<uint64_t>() == plan.stats.transientBytes);
    CHECK(j["caps"]["separateComputeFamily"].get<bool>());
    CHECK(j["batches"][0]["passes"][0]["name"] == "bvh_update");
}

TEST_CASE("printing is deterministic") {
    const Plan a = reflection(twoQueues());
    const Plan b = reflection(twoQueues());
    CHECK(a.toText() == b.toText());
    CHECK(a.toDot() == b.toDot());
    CHECK(a.toJson() == b.toJson());
    const Plan one = reflection(oneQueue());
    CHECK(one.toText() != a.toText());
}
