// The hybrid's SSLR gate through the whole reflection frame
// (passes/feedback.h; run as glint-render runs it): on DamagedHelmet, a
// close-up whose reflections mostly leave the screen, SSLR resolves far
// fewer than sslrMinHitShare of the pixels, so after the first frames the
// hybrid traces exactly what rt mode traces and lists no SSLR ray, except
// on probe frames; with the gate off it keeps trying SSLR every frame.
// The host's side of the gate then renders those frames as rt: no feedback,
// pyramid or SSLR work, and rt mode's reflections exactly; its probe frames
// try SSLR and count its hits, and render as rt as well.
#include "support/gpu_test.h"

#include "common/reflection_run.h"
#include "glint/scene/builtin_scenes.h"

#include "glint/feedback_shared.h"

#include <filesystem>

using namespace glint;

namespace {

constexpr uint32_t kSize = 128;

app::ReflectionRunResult run(test::GpuTest& gpu, passes::ReflectionMode mode, uint32_t frames,
                             const passes::FeedbackSettings& feedback = {}, std::string_view debugView = {},
                             std::vector<uint32_t> cutFrames = {}) {
    const std::filesystem::path file = std::filesystem::path(GLINT_SCENES_DIR) / "DamagedHelmet" / "DamagedHelmet.gltf";
    REQUIRE_MESSAGE(std::filesystem::exists(file), "shared scene missing: " << file.string());
    scene::Scene scene = scene::loadScene(file.string());
    app::ReflectionRunOptions options;
    options.width = kSize;
    options.height = kSize;
    options.frames = frames;
    options.timeEveryFrame = false;
    options.frame.mode = mode;
    options.frame.feedback = feedback;
    options.frame.debugView = debugView;
    options.cutFrames = std::move(cutFrames);
    return app::runReflections(gpu.ctx(), scene, options);
}

// The gate's settings with one change.
passes::FeedbackSettings noMinHitShare() {
    passes::FeedbackSettings s;
    s.sslrMinHitShare = 0.0f;
    return s;
}
passes::FeedbackSettings gpuGateOnly() {
    passes::FeedbackSettings s;
    s.hostGate = false;
    return s;
}
// Probes at feedbackProbeFrame's every block, as the GPU's gate has them.
passes::FeedbackSettings noBackingOff() {
    passes::FeedbackSettings s;
    s.sslrProbeIntervalMax = s.sslrProbeInterval;
    return s;
}

// The smallest frame count from `least` on whose last frame (index
// count - 1) is, or is not, a probe frame.
uint32_t framesEndingOn(bool probe, uint32_t least) {
    const uint32_t interval = passes::FeedbackSettings{}.sslrProbeInterval;
    uint32_t frames = least;
    while (shader::feedbackProbeFrame(frames - 1, interval) != probe) ++frames;
    return frames;
}

} // namespace

TEST_CASE("the hybrid stops trying SSLR where it resolves too little, and tries it again on probe frames") {
    test::GpuTest gpu;
    // The last frame gated: no SSLR ray, and rt mode's rays exactly (the
    // helmet has no pixel beyond the reach, where only SSLR could go).
    const uint32_t gated = framesEndingOn(false, 6);
    const app::ReflectionRunResult hybrid = run(gpu, passes::ReflectionMode::Hybrid, gated);
    const app::ReflectionRunResult rt = run(gpu, passes::ReflectionMode::Rt, gated);
    REQUIRE(rt.rtRays > 500);
    CHECK(hybrid.sslrRays == 0);
    CHECK(hybrid.rtRays == rt.rtRays);
    // With the gate off the same frame tries SSLR on its hybrid pixels.
    const app::ReflectionRunResult always = run(gpu, passes::ReflectionMode::Hybrid, gated, noMinHitShare());
    CHECK(always.sslrRays > 100);
    CHECK(always.rtRays < rt.rtRays);
    // A probe frame tries SSLR on every hybrid pixel again (the host's
    // gate keeping every one of the GPU's probe frames).
    const app::ReflectionRunResult probe =
        run(gpu, passes::ReflectionMode::Hybrid, framesEndingOn(true, gated), noBackingOff());
    CHECK(probe.sslrRays > always.sslrRays);
}

TEST_CASE("the host renders the hybrid's frames as rt where SSLR does not pay: rt's reflections, probes included") {
    test::GpuTest gpu;
    const uint32_t gated = framesEndingOn(false, 10);
    // Integrate's output of the last frame: this frame's rays alone, before
    // the temporal history mixes in the earlier (hybrid, probe) frames.
    const app::ReflectionRunResult hybrid = run(gpu, passes::ReflectionMode::Hybrid, gated, {}, "reflections");
    const app::ReflectionRunResult rt = run(gpu, passes::ReflectionMode::Rt, gated, {}, "reflections");
    CHECK(hybrid.lastScreenSpaceIdle);
    // The first frames try SSLR until a report of one says it does not pay
    // (read back some frames later); then every frame but the probes.
    CHECK(hybrid.screenSpaceIdleFrames >= gated - 6);
    CHECK(hybrid.sslrRays == 0);
    CHECK(hybrid.rtRays == rt.rtRays);
    REQUIRE(hybrid.rgba.size() == rt.rgba.size());
    CHECK(hybrid.rgba == rt.rgba);
    // The GPU's gate alone: the same rays, but the hybrid's passes ran.
    const app::ReflectionRunResult gpuGate = run(gpu, passes::ReflectionMode::Hybrid, gated, gpuGateOnly());
    CHECK(gpuGate.screenSpaceIdleFrames == 0);
    CHECK(gpuGate.rtRays == rt.rtRays);
    // A probe frame tries SSLR again and counts its hits for the report,
    // but while the gate is closed it renders as rt too
    // (FeedbackSettings::probesRenderAsRt): SSLR hands every ray on.
    const uint32_t probeFrames = framesEndingOn(true, gated);
    const app::ReflectionRunResult probe =
        run(gpu, passes::ReflectionMode::Hybrid, probeFrames, noBackingOff(), "reflections");
    const app::ReflectionRunResult rtProbe = run(gpu, passes::ReflectionMode::Rt, probeFrames, {}, "reflections");
    CHECK_FALSE(probe.lastScreenSpaceIdle);
    CHECK(probe.sslrRays > 100);
    CHECK(probe.rtRays == rtProbe.rtRays);
    REQUIRE(probe.rgba.size() == rtProbe.rgba.size());
    CHECK(probe.rgba == rtProbe.rgba);
    // A probe that uses what SSLR resolves: fewer RT rays, another image.
    passes::FeedbackSettings usesSslr = noBackingOff();
    usesSslr.probesRenderAsRt = false;
    const app::ReflectionRunResult hybridProbe =
        run(gpu, passes::ReflectionMode::Hybrid, probeFrames, usesSslr, "reflections");
    CHECK_FALSE(hybridProbe.lastScreenSpaceIdle);
    CHECK(hybridProbe.rtRays < rtProbe.rtRays);
    CHECK(hybridProbe.rgba != rtProbe.rgba);
}

TEST_CASE("the host's gate probes less often while SSLR keeps not paying") {
    test::GpuTest gpu;
    // Probes in every block of 2 frames at first; backing off to one in 16.
    passes::FeedbackSettings often;
    often.sslrProbeInterval = 2;
    often.sslrProbeIntervalMax = 2;
    passes::FeedbackSettings backingOff = often;
    backingOff.sslrProbeIntervalMax = 16;
    constexpr uint32_t kFrames = 40;
    const app::ReflectionRunResult fixed = run(gpu, passes::ReflectionMode::Hybrid, kFrames, often);
    const app::ReflectionRunResult backed = run(gpu, passes::ReflectionMode::Hybrid, kFrames, backingOff);
    MESSAGE("frames rendered as rt of " << kFrames << ": " << fixed.screenSpaceIdleFrames << " probing every block, "
                                        << backed.screenSpaceIdleFrames << " backing off");
    CHECK(fixed.screenSpaceIdleFrames > 0);
    // The spacing the renderer reports: the interval, and backed off all the way.
    CHECK(fixed.lastSslrProbeSpacing == 2);
    CHECK(backed.lastSslrProbeSpacing == 16);
    CHECK(backed.screenSpaceIdleFrames > fixed.screenSpaceIdleFrames + 8);
    // Backing off (strides 1, 2, 4, 8, then 8: hostProbeFrame) keeps fewer
    // than half of feedbackProbeFrame's probes, the first frames before the
    // gate closes included, and still at least one in every 16 frames.
    uint32_t everyBlock = 0;
    for (uint64_t frame = 0; frame < kFrames; ++frame) everyBlock += passes::hostProbeFrame(frame, 2, 1);
    CHECK(kFrames - backed.screenSpaceIdleFrames < everyBlock / 2);
    CHECK(kFrames - backed.screenSpaceIdleFrames >= kFrames / 16);
    // A cut forgets the backing off: SSLR is tried again, and once a report
    // says it still does not pay the probes start at every block again.
    const app::ReflectionRunResult cut =
        run(gpu, passes::ReflectionMode::Hybrid, kFrames, backingOff, {}, {kFrames - 6});
    MESSAGE("after a cut 6 frames before the end: a probe every " << cut.lastSslrProbeSpacing << " frames");
    CHECK(cut.lastSslrProbeSpacing > 0);
    CHECK(cut.lastSslrProbeSpacing < backed.lastSslrProbeSpacing);
}

TEST_CASE("where SSLR pays, the host renders no hybrid frame as rt") {
    test::GpuTest gpu;
    scene::Scene scene = scene::makePlaza();
    app::ReflectionRunOptions options;
    options.width = kSize;
    options.height = kSize;
    options.frames = 16;
    options.timeEveryFrame = false;
    // glint-render's pose: wet ground reflecting the buildings on screen
    // (at 0 s, at this size, SSLR resolves just under the 2% it must).
    options.startSeconds = 3.0f;
    const app::ReflectionRunResult plaza = app::runReflections(gpu.ctx(), scene, options);
    CHECK(plaza.screenSpaceIdleFrames == 0);
    CHECK(plaza.sslrRays > 100);
}
