// The viewer's parts that need no window: command line, panel model, fly
// camera, and its graph passes compiled and verified without a GPU.

#include <doctest/doctest.h>

#include "glint/graph/access.h"
#include "glint/graph/compile.h"
#include "glint/graph/plan.h"
#include "glint/graph/synthetic.h"
#include "glint/graph/verify.h"
#include "imgui_layer.h"
#include "plan_view.h"
#include "present_passes.h"
#include "viewer_model.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

using namespace glint;

namespace {

app::Args argsOf(std::vector<std::string> words) {
    std::vector<char*> argv;
    static std::string program = "glint-viewer";
    argv.push_back(program.data());
    for (std::string& w : words) argv.push_back(w.data());
    return app::Args(int(argv.size()), argv.data(), viewer::kUsage, viewer::viewerFlags(), viewer::viewerSwitches());
}

} // namespace

TEST_CASE("the command line gives the scene and the window size") {
    const viewer::ViewerOptions defaults = viewer::viewerOptions(argsOf({}));
    CHECK(defaults.scene == "plaza");
    CHECK(defaults.width == 1280);
    CHECK(defaults.height == 720);
    CHECK(defaults.frames == 0);
    CHECK_FALSE(defaults.graphPanel);
    CHECK(viewer::viewerOptions(argsOf({"--graph-panel"})).graphPanel);
    const viewer::ViewerOptions o =
        viewer::viewerOptions(argsOf({"--scene", "hard-cases", "--size", "800x600", "--frames", "3"}));
    CHECK(o.scene == "hard-cases");
    CHECK(o.width == 800);
    CHECK(o.height == 600);
    CHECK(o.frames == 3);
    CHECK(viewer::parseWindowSize("512") == glm::uvec2(512, 512));
}

TEST_CASE("a window size outside 64..8192 or not WxH is refused, naming the flag") {
    for (const char* bad : {"0x600", "800x", "x600", "800x60", "9000x600", "800x600x2", "-800x600", "abc", ""}) {
        INFO(bad);
        CHECK_THROWS_WITH_AS(viewer::parseWindowSize(bad), doctest::Contains("--size"), std::runtime_error);
    }
    CHECK_THROWS_AS(argsOf({"--set", "sslr_steps=8"}), std::exception);  // glint-render's flag, not the viewer's
}

TEST_CASE("debug views a mode does not produce are unavailable, every other one is") {
    using passes::ReflectionMode;
    for (const passes::DebugViewInfo& info : passes::debugViews()) {
        CHECK(viewer::debugViewAvailable(info.name, ReflectionMode::Hybrid));
    }
    CHECK_FALSE(viewer::debugViewAvailable("no_such_view", ReflectionMode::Hybrid));
    CHECK_FALSE(viewer::debugViewAvailable("sslr_confidence", ReflectionMode::Rt));
    CHECK_FALSE(viewer::debugViewAvailable("rt_hit_distance", ReflectionMode::Ssr));
    CHECK_FALSE(viewer::debugViewAvailable("tile_modes", ReflectionMode::Ssr));
    CHECK_FALSE(viewer::debugViewAvailable("feedback_counters", ReflectionMode::Rt));
    CHECK(viewer::debugViewAvailable("reflection_source", ReflectionMode::Ssr));
    CHECK(viewer::debugViewAvailable("ray_classes", ReflectionMode::Rt));
    CHECK(viewer::debugViewAvailable("final", ReflectionMode::Rt));
}

TEST_CASE("every tunable parameter has a slider whose range holds its default") {
    const std::vector<viewer::ParameterSlider> sliders = viewer::parameterSliders();
    REQUIRE(sliders.size() == app::parameters().size());
    const app::ReflectionRunOptions defaults;
    for (const viewer::ParameterSlider& s : sliders) {
        INFO(s.parameter.name);
        const double v = app::getParameter(defaults, s.parameter.name);
        CHECK(s.min <= v);
        CHECK(v <= s.max);
        CHECK(s.min < s.max);
    }
}

TEST_CASE("every parameter's bench sweep lies in its range, runs in some mode and is accepted by setParameter") {
    uint32_t swept = 0;
    for (const app::Parameter& p : app::parameters()) {
        INFO(p.name);
        CHECK(p.quickSweep.size() <= p.sweep.size());
        const bool anyMode = p.sweepModes[0] || p.sweepModes[1] || p.sweepModes[2];
        CHECK(anyMode == !p.sweep.empty());
        for (const std::vector<double>* values : {&p.sweep, &p.quickSweep}) {
            for (const double v : *values) {
                CAPTURE(v);
                CHECK(p.min <= v);
                CHECK(v <= p.max);
                app::ReflectionRunOptions o;
                app::setParameter(o, p.name, std::to_string(v));
                CHECK(app::getParameter(o, p.name) == doctest::Approx(v));
            }
        }
        swept += p.sweep.empty() ? 0u : 1u;
    }
    CHECK(swept >= 10u);
}

TEST_CASE("an integer parameter takes integers from its own least value, and says which when refused") {
    app::ReflectionRunOptions o;
    app::setParameter(o, "spatial_noise_free_radius", "0");  // a radius: 0 turns it off
    CHECK(o.frame.temporal.spatialNoiseFreeRadius == 0u);
    CHECK_THROWS_WITH_AS(app::setParameter(o, "sslr_steps", "0"), doctest::Contains("not an integer in 1..4096"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(app::setParameter(o, "spatial_noise_free_radius", "1.5"),
                         doctest::Contains("not an integer in 0..4096"), std::invalid_argument);
    CHECK(o.frame.sslr.linearSteps == passes::SslrSettings{}.linearSteps);
}

TEST_CASE("a slider sets its parameter through setParameter, clamped and rounded") {
    const std::vector<viewer::ParameterSlider> sliders = viewer::parameterSliders();
    const auto find = [&](std::string_view name) {
        for (const auto& s : sliders)
            if (s.parameter.name == name) return s;
        FAIL("no slider " << name);
        return sliders.front();
    };
    app::ReflectionRunOptions o;
    viewer::applySlider(o, find("sslr_threshold"), 0.5f);
    CHECK(o.frame.confidenceThreshold == doctest::Approx(0.5f));
    viewer::applySlider(o, find("sslr_threshold"), 7.0f);
    CHECK(o.frame.confidenceThreshold == doctest::Approx(1.0f));
    viewer::applySlider(o, find("sslr_steps"), 31.6f);
    CHECK(o.frame.sslr.linearSteps == 32u);
    viewer::applySlider(o, find("sslr_steps"), NAN);
    CHECK(o.frame.sslr.linearSteps == 1u);
}

TEST_CASE("only the BVH's reflection LODs need a new renderer (the reach is the frame's)") {
    for (const viewer::ParameterSlider& s : viewer::parameterSliders()) {
        INFO(s.parameter.name);
        CHECK(s.rendererOption == (s.parameter.name == "reflection_lods"));
        // One end of the range or the other moves the field off its default.
        bool differs = false;
        for (const float value : {s.min, s.max}) {
            app::ReflectionRunOptions o;
            const passes::ReflectionRendererOptions before = o.renderer;
            viewer::applySlider(o, s, value);
            differs = differs || viewer::rendererOptionsDiffer(before, o.renderer);
        }
        CHECK(differs == s.rendererOption);
    }
}

TEST_CASE("the fly camera keeps the direction it starts from and moves along its own axes") {
    scene::CameraPose pose;
    pose.position = {1.0f, 2.0f, 3.0f};
    pose.target = {4.0f, 2.0f, 7.0f};  // level, towards +x +z
    viewer::FlyCamera c = viewer::FlyCamera::lookingAlong(pose);
    CHECK(c.pitch == doctest::Approx(0.0f));
    const glm::vec3 f = c.forward();
    CHECK(f.x == doctest::Approx(0.6f));
    CHECK(f.z == doctest::Approx(0.8f));
    CHECK(glm::dot(c.right(), f) == doctest::Approx(0.0f).epsilon(1e-6));
    CHECK(glm::cross(c.right(), f).y == doctest::Approx(1.0f));  // right x forward = up: right-handed
    c.move({0.0f, 0.0f, 1.0f}, 5.0f);
    CHECK(c.position.x == doctest::Approx(4.0f));
    CHECK(c.position.z == doctest::Approx(7.0f));
    c.move({0.0f, 1.0f, 0.0f}, 2.0f);
    CHECK(c.position.y == doctest::Approx(4.0f));
    c.turn({0.0f, -1e6f}, 0.01f);  // far up: stops short of vertical
    CHECK(c.pitch == doctest::Approx(viewer::FlyCamera::kMaxPitch));
    CHECK(std::isfinite(glm::length(c.pose().target)));
}

namespace {

// The barriers after the frame's batches on `resource`.
std::vector<rg::Barrier> endBarriersOn(const rg::Plan& plan, uint32_t resource) {
    std::vector<rg::Barrier> out;
    for (const rg::Batch& batch : plan.batches)
        for (const rg::Barrier& b : plan.barriersAfter(batch))
            if (b.resource == resource) out.push_back(b);
    return out;
}

} // namespace

TEST_CASE("the viewer's passes draw into the acquired swapchain image, end it in PRESENT_SRC and verify clean") {
    // UNORM swapchains are drawn into directly; SRGB-only ones get the frame
    // composed in a UNORM image and copied in.
    for (const bool composeFirst : {false, true}) {
        for (const bool countRays : {false, true}) {
            INFO("compose first " << composeFirst << ", count rays " << countRays);
            rg::Graph graph(rg::synthetic::twoQueueCaps());
            const VkExtent2D extent{96, 64};
            struct Frame {
                rg::Texture color;
                rg::Buffer counts;
            };
            // Stands in for the reflection frame: a compute pass writing the
            // RGBA8 output (and the counts).
            const Frame& frame = graph.addPass<Frame>(
                "composite", rg::Queue::Graphics,
                [&](rg::Builder& b, Frame& d) {
                    d.color = b.write(b.createTexture("composite.color", {.width = extent.width,
                                                                         .height = extent.height,
                                                                         .format = VK_FORMAT_R8G8B8A8_UNORM}),
                                      rg::Access::StorageWrite);
                    d.counts = b.write(b.createBuffer("stats.counts", {28}), rg::Access::StorageWrite);
                },
                [](const Frame&, rg::PassContext&) {});
            graph.markOutput(frame.color);
            viewer::ViewerPassesInputs in;
            in.output = frame.color;
            in.extent = extent;
            in.composeFormat = VK_FORMAT_B8G8R8A8_UNORM;
            in.swapchainFormat = composeFirst ? VK_FORMAT_B8G8R8A8_SRGB : VK_FORMAT_B8G8R8A8_UNORM;
            const viewer::ViewerPasses passes = viewer::addViewerPasses(graph, in);
            CHECK(passes.swapchain.valid());
            CHECK(passes.compose.valid() == composeFirst);
            if (countRays) viewer::addCountsReadback(graph, frame.counts, 28);

            const rg::Plan plan = graph.compile();
            const rg::VerifyReport report = rg::verify(plan);
            INFO(plan.toText());
            INFO(report.text());
            CHECK(report.ok());
            CHECK(plan.findPass("viewer.blit") != nullptr);
            CHECK(plan.findPass("viewer.imgui") != nullptr);
            CHECK((plan.findPass("viewer.present_copy") != nullptr) == composeFirst);
            CHECK((plan.findPass("viewer.read_counts") != nullptr) == countRays);

            // The UI pass sees the layout the UI render pass was made for.
            CHECK(rg::accessScope(rg::Access::ColorAttachment, rg::ResourceKind::Texture, rg::Pipeline::Raster)
                      .layout == viewer::kUiTargetLayout);

            // The swapchain image's first barrier starts at the acquire
            // wait's stages (so its transition follows the wait)...
            const uint32_t swapchain = plan.findResource("viewer.swapchain");
            REQUIRE(swapchain != rg::kNoIndex);
            const rg::PlannedPass* first = plan.findPass(composeFirst ? "viewer.present_copy" : "viewer.blit");
            REQUIRE(first != nullptr);
            bool afterAcquire = false;
            for (const rg::Barrier& b : plan.barriersBefore(*first)) {
                if (b.resource == swapchain) {
                    afterAcquire = b.srcStages == viewer::kAcquireWaitStages &&
                                   b.oldLayout == VK_IMAGE_LAYOUT_UNDEFINED;
                }
            }
            CHECK(afterAcquire);
            // ... and its last one leaves it in PRESENT_SRC inside the
            // render-finished signal's scope.
            const auto last = endBarriersOn(plan, swapchain);
            REQUIRE(last.size() == 1);
            CHECK(last[0].newLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
            CHECK((last[0].dstStages & rg::kSemaphoreSignalStages) == rg::kSemaphoreSignalStages);

            if (composeFirst) {
                // The compose image ends read by the copy, and the next
                // frame's blit waits for that read.
                const uint32_t compose = plan.findResource("viewer.compose");
                REQUIRE(compose != rg::kNoIndex);
                bool afterCopy = false;
                for (const rg::Barrier& b : plan.barriersBefore(*plan.findPass("viewer.blit"))) {
                    if (b.resource == compose) afterCopy = (b.srcStages & VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT) != 0;
                }
                CHECK(afterCopy);
            }
        }
    }
}

TEST_CASE("the starting mode, backend and debug view come from the command line, checked like the panel") {
    const viewer::ViewerOptions o =
        viewer::viewerOptions(argsOf({"--mode", "rt", "--backend", "pipeline", "--debug-view", "rt_hit_distance"}));
    CHECK(o.mode == passes::ReflectionMode::Rt);
    CHECK(o.backend == passes::RtBackend::Pipeline);
    CHECK(o.debugView == "rt_hit_distance");
    CHECK_THROWS_WITH_AS(viewer::viewerOptions(argsOf({"--mode", "fast"})), doctest::Contains("--mode"),
                         std::runtime_error);
    CHECK_THROWS_WITH_AS(viewer::viewerOptions(argsOf({"--debug-view", "nope"})),
                         doctest::Contains("--debug-view nope"), std::runtime_error);
    CHECK_THROWS_WITH_AS(viewer::viewerOptions(argsOf({"--mode", "ssr", "--debug-view", "rt_radiance"})),
                         doctest::Contains("not produced in mode ssr"), std::runtime_error);
}

TEST_CASE("the render graph panel shows every planned pass on its queue, the waits, barriers, times and aliasing") {
    rg::Graph graph(rg::synthetic::twoQueueCaps());
    rg::synthetic::declare(graph, rg::synthetic::reflectionFrame({.width = 640, .height = 360}));
    const rg::Plan plan = graph.compile();
    REQUIRE(plan.findPass("bvh_update") != nullptr);
    std::vector<rg::PassTiming> timings = {{"bvh_update", rg::Queue::AsyncCompute, 0.25, 3, std::nullopt}};
    const viewer::PlanView view = viewer::planView(plan, timings);

    // Every planned pass once, on its queue, in submission order.
    size_t rows = 0, barriers = 0, waits = 0;
    std::set<std::string> names;
    for (uint32_t q = 0; q < 2; ++q) {
        uint32_t lastBatch = 0;
        for (const viewer::PlanViewPass& p : view.lanes[q]) {
            const rg::PlannedPass* planned = plan.findPass(p.name);
            REQUIRE(planned != nullptr);
            CHECK(uint32_t(planned->queue) == q);
            CHECK(p.batch >= lastBatch);
            lastBatch = p.batch;
            CHECK(p.barriers == planned->barrierCount);
            REQUIRE(p.barrierList.size() == p.barriers);
            for (size_t i = 0; i < p.barrierList.size(); ++i) {
                const rg::Barrier& b = plan.barriersBefore(*planned)[i];
                CHECK(p.barrierList[i].resource == plan.resourceName(b.resource));
                CHECK(p.barrierList[i].newLayout == b.newLayout);
            }
            barriers += p.barriers;
            waits += p.waits.size();
            CHECK((p.waits.empty() || p.batchStart));
            names.insert(p.name);
            ++rows;
        }
    }
    CHECK(rows == plan.passes.size());
    CHECK(names.size() == rows);
    CHECK(!view.lanes[1].empty());  // the BVH update on async compute
    CHECK(waits == plan.waits.size());
    size_t planned = 0;
    for (const rg::PlannedPass& p : plan.passes) planned += p.barrierCount;
    CHECK(barriers == planned);

    // The time of a pass comes from the timing of its name.
    const auto bvh = std::find_if(view.lanes[1].begin(), view.lanes[1].end(),
                                  [](const viewer::PlanViewPass& p) { return p.name == "bvh_update"; });
    REQUIRE(bvh != view.lanes[1].end());
    REQUIRE(bvh->milliseconds.has_value());
    CHECK(*bvh->milliseconds == doctest::Approx(0.25));
    CHECK(!bvh->uses.empty());

    // Every used transient placed once, and aliasing shown both ways.
    size_t placements = 0, aliased = 0;
    for (const viewer::PlanViewHeap& heap : view.heaps) {
        for (const viewer::PlanViewPlacement& p : heap.placements) {
            ++placements;
            CHECK(p.offset + p.size <= heap.size);
            if (!p.aliases.empty()) ++aliased;
            for (const std::string& other : p.aliases) {
                const auto it = std::find_if(heap.placements.begin(), heap.placements.end(),
                                             [&](const viewer::PlanViewPlacement& o) { return o.resource == other; });
                REQUIRE(it != heap.placements.end());
                CHECK(std::count(it->aliases.begin(), it->aliases.end(), p.resource) == 1);
            }
        }
    }
    size_t transients = 0;
    for (const rg::PlannedResource& r : plan.resources) {
        if (r.origin == rg::ir::Origin::Transient && r.used) ++transients;
    }
    CHECK(placements == transients);
    CHECK(view.aliasedBytes < view.transientBytes);
    CHECK(aliased > 0);
}
