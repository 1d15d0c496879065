#include "common/reflection_run.h"

#include "glint/graph/executor.h"
#include "glint/graph/transfer.h"
#include "glint/graph/graph.h"
#include "glint/graph/plan_cache.h"
#include "glint/graph/skip.h"
#include "glint/graph/verify.h"
#include "glint/scene/animation.h"

#include "glint/occlusion_shared.h"
#include "glint/reflection_frame_shared.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>

namespace glint::app {

namespace {


double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double mean(const std::vector<double>& values) {
    if (values.empty()) return 0.0;
    double sum = 0.0;
    for (const double v : values) sum += v;
    return sum / double(values.size());
}

// Each parameter: its name, the field, and where it lives.
struct ParameterSlot {
    Parameter parameter;
    float* (*floatField)(ReflectionRunOptions&);
    uint32_t* (*uintField)(ReflectionRunOptions&);
    bool* (*boolField)(ReflectionRunOptions&) = nullptr;  // 0 or 1
};

// Modes a sweep runs in (hybrid, ssr, rt).
constexpr std::array<bool, 3> kHybrid{true, false, false};
constexpr std::array<bool, 3> kScreenSpace{true, true, false};
constexpr std::array<bool, 3> kTraced{true, false, true};
constexpr std::array<bool, 3> kEveryMode{true, true, true};

// The one table of parameters: name, field, the viewer's range, the
// bench's sweep, and where the value lives.
const std::array<ParameterSlot, 34> kParameters = {{
    // A confidence; the talk's 0.9 (default) bracketed from "trust SSLR
    // often" to "almost never".
    {{"sslr_threshold", "ReflectionFrameSettings::confidenceThreshold", 0.0f, 1.0f, false, {0.5, 0.7, 0.8, 0.95, 0.99},
      {0.7}, kHybrid},
     [](ReflectionRunOptions& o) { return &o.frame.confidenceThreshold; }, nullptr},
    // 64 linear steps (default, the talk) against fewer and more.
    {{"sslr_steps", "SslrSettings::linearSteps", 1.0f, 256.0f, true, {16, 32, 96, 128}, {16, 32}, kScreenSpace},
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.sslr.linearSteps; }},
    // Steps no finer than a pixel (default 1); 0: every step whatever the
    // ray's screen length.
    {{"sslr_min_step_pixels", "SslrSettings::minStepPixels", 0.0f, 8.0f, false, {0, 2, 4}, {0, 2}, kScreenSpace},
     [](ReflectionRunOptions& o) { return &o.frame.sslr.minStepPixels; }, nullptr},
    // A hit lies at most this share of its view distance behind the depth
    // buffer's surface (default 0.01; 0.02 until 2026-12-07, then 0.005),
    // or what a slanted surface's depth changes over half a pixel: thinner misses
    // more hits and hands them on, thicker takes rays passing behind an
    // object for hits.
    {{"sslr_thickness", "SslrSettings::thickness", 0.001f, 0.5f, false, {0.002, 0.005, 0.02}, {}, kScreenSpace},
     [](ReflectionRunOptions& o) { return &o.frame.sslr.thickness; }, nullptr},
    // SSLR's hits re-lit for the ray's direction (default on); 0: the lit
    // colour as the camera sees it.
    {{"sslr_relight", "SslrSettings::relightHits (0 or 1)", 0.0f, 1.0f, true, {0}, {}, kScreenSpace}, nullptr,
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.sslr.relightHits; }},
    // A roughness; 0.3 (default) against FidelityFX's 0.22: lower sends
    // more pixels to the environment, higher traces more.
    {{"roughness_cutoff", "RayGenerationSettings::roughnessCutoff", 0.0f, 1.0f, false, {0.1, 0.15, 0.22, 0.5}, {0.5},
      kEveryMode},
     [](ReflectionRunOptions& o) { return &o.frame.rays.roughnessCutoff; }, nullptr},
    // Quads at or above this roughness share one ray: 0, every traced quad
    // shares (1 sample per quad); 1 (above any traced roughness), none does
    // (4 per quad).
    {{"reuse_roughness", "RayGenerationSettings::reuseRoughness (samples per quad: 1 above it, 4 below)", 0.0f, 1.0f,
      false, {0.0, 0.05, 0.1, 1.0}, {0.0}, kEveryMode},
     [](ReflectionRunOptions& o) { return &o.frame.rays.reuseRoughness; }, nullptr},
    // SSLR and hybrid rays at least this rough cone-trace the lit pyramid
    // (default 0.05): noise-free but blurred by a box filter and limited to
    // what is on screen; 1 (above any traced roughness) never does, each
    // ray then takes the lit colour at its own hit.
    {{"cone_roughness", "RayGenerationSettings::coneRoughness (SSLR rays this rough cone-trace)", 0.0f, 1.0f, false,
      {0.1, 0.2, 1.0}, {}, kScreenSpace},
     [](ReflectionRunOptions& o) { return &o.frame.rays.coneRoughness; }, nullptr},
    // The spatial filter's radius at the cone trace's hits (noise-free,
    // already blurred by the pyramid); 0 (default) leaves them alone, 2 is
    // the filter's own.
    {{"spatial_noise_free_radius", "TemporalSettings::spatialNoiseFreeRadius", 0.0f, 4.0f, true, {1, 2}, {},
      kScreenSpace},
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.temporal.spatialNoiseFreeRadius; }},
    // Glossy pixels look their history up once, at the blended motion (on
    // by default); 0 at the reflected point's and the surface's, blended.
    {{"one_history_candidate", "TemporalSettings::oneHistoryCandidate (0 or 1)", 0.0f, 1.0f, true, {0}, {},
      kEveryMode},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.frame.temporal.oneHistoryCandidate; }},
    // Pixels nearer than this go straight to RT (default 3 world units): 0
    // tries SSLR first everywhere.
    {{"rt_near_distance", "RayGenerationSettings::rtMaxDistance", 0.0f, 50.0f, false, {0, 1, 6, 10}, {0}, kHybrid},
     [](ReflectionRunOptions& o) { return &o.frame.rays.rtMaxDistance; }, nullptr},
    // The BVH radius, the talk's 100 (default) around the camera: smaller
    // drops distant BLASes and shortens the rays; the SSLR-only distance
    // and the particle trace's range follow it.
    {{"reach", "ReflectionFrameSettings::reach", 1.0f, 500.0f, false, {10, 25, 50, 200}, {25}, kTraced},
     [](ReflectionRunOptions& o) { return &o.frame.reach; }, nullptr},
    {{"frustum_culling", "GBufferSettings::frustumCulling (0 or 1)", 0.0f, 1.0f, true, {}, {}, {}}, nullptr, nullptr,
     [](ReflectionRunOptions& o) { return &o.frame.gbuffer.frustumCulling; }},
    {{"occlusion_culling", "GBufferSettings::occlusionCulling (0 or 1)", 0.0f, 1.0f, true, {}, {}, {}}, nullptr,
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.gbuffer.occlusionCulling; }},
    {{"facet_culling", "GBufferSettings::facetCulling (0 or 1)", 0.0f, 1.0f, true, {}, {}, {}}, nullptr, nullptr,
     [](ReflectionRunOptions& o) { return &o.frame.gbuffer.facetCulling; }},
    // Half-rate RT on a checkerboard (default off).
    {{"rt_checkerboard", "RayGenerationSettings::checkerboard (0 or 1)", 0.0f, 1.0f, true, {1}, {1}, kTraced}, nullptr,
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.rays.checkerboard; }},
    // A tile goes RT-only when at most this share of its SSLR rays hit
    // (default 0, the talk's rule): higher stops paying for SSLR where it
    // rarely succeeds.
    {{"feedback_rt_hit_fraction", "FeedbackSettings::rtHitFraction", 0.0f, 1.0f, false, {0.05, 0.1, 0.25}, {0.1},
      kHybrid},
     [](ReflectionRunOptions& o) { return &o.frame.feedback.rtHitFraction; }, nullptr},
    // SSLR is tried on the hybrid pixels only while last frame's SSLR hits
    // reach this share of the pixels (default 0.02); 0: always.
    {{"feedback_sslr_min_hit_share", "FeedbackSettings::sslrMinHitShare", 0.0f, 1.0f, false, {0, 0.01, 0.05, 0.1},
      {0}, kHybrid},
     [](ReflectionRunOptions& o) { return &o.frame.feedback.sslrMinHitShare; }, nullptr},
    // While SSLR does not pay, one frame in this many tries it again (default 8).
    {{"feedback_sslr_probe_interval", "FeedbackSettings::sslrProbeInterval", 1.0f, 64.0f, true, {4, 16}, {}, kHybrid},
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.feedback.sslrProbeInterval; }},
    // The host's gate backs off to one probe in this many frames (default
    // 32); equal to the probe interval, it does not back off.
    {{"feedback_sslr_probe_interval_max", "FeedbackSettings::sslrProbeIntervalMax", 1.0f, 256.0f, true, {8}, {},
      kHybrid},
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.feedback.sslrProbeIntervalMax; }},
    // The same gate on the host (default on): frames where SSLR does not
    // pay render as rt, with no feedback, pyramid or SSLR work; 0: the GPU's
    // gate alone, which still runs those passes empty.
    {{"feedback_host_gate", "FeedbackSettings::hostGate (0 or 1)", 0.0f, 1.0f, true, {0}, {}, kHybrid}, nullptr,
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.feedback.hostGate; }},
    // While the host's gate is closed its probes render as rt, SSLR's hits
    // counted but not used (default on); 0: a probe uses what SSLR resolves.
    {{"feedback_probes_render_as_rt", "FeedbackSettings::probesRenderAsRt (0 or 1)", 0.0f, 1.0f, true, {0}, {},
      kHybrid},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.frame.feedback.probesRenderAsRt; }},
    // The frames the host renders as rt skip the feedback, pyramid and SSLR
    // passes, whose barriers are carried on into the next pass's (default
    // on); 0: each stays a barrier call of its own, as before.
    {{"graph_carry_skipped_barriers", "rg::Executor::setCarrySkippedBarriers (0 or 1)", 0.0f, 1.0f, true, {0}, {},
      kHybrid},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.carrySkippedBarriers; }},
    // Particles drawn before SSLR, which reflects them where it resolves
    // the ray; the particle trace only where it does not (default off:
    // every particle traced).
    {{"sslr_particles", "ReflectionFrameSettings::sslrParticles (0 or 1)", 0.0f, 1.0f, true, {1}, {1}, kScreenSpace},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.frame.sslrParticles; }},
    // No particles in the reflections (default on): what the particle TLAS
    // and trace cost.
    {{"reflect_particles", "ReflectionFrameSettings::reflectParticles (0 or 1)", 0.0f, 1.0f, true, {0}, {0}, kTraced},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.frame.reflectParticles; }},
    // Rays see alpha-tested geometry opaque (default: through its
    // cut-outs): what the test costs.
    {{"alpha_test", "RtTraceSettings::alphaTest (0 or 1)", 0.0f, 1.0f, true, {0}, {0}, kTraced}, nullptr, nullptr,
     [](ReflectionRunOptions& o) { return &o.frame.rt.alphaTest; }},
    // Hits lit unshadowed (default: a shadow ray to the sun from each hit
    // that faces it): what the shadow rays cost.
    {{"rt_shadows", "RtTraceSettings::shadows (0 or 1)", 0.0f, 1.0f, true, {0}, {}, kTraced}, nullptr, nullptr,
     [](ReflectionRunOptions& o) { return &o.frame.rt.shadows; }},
    // Hits the shadow map covers take its visibility (default on) against
    // a shadow ray from every hit: the G-buffer's shadows or exact ones.
    {{"rt_shadow_map", "RtTraceSettings::shadowMapAtHits (0 or 1)", 0.0f, 1.0f, true, {0}, {}, kTraced}, nullptr,
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.rt.shadowMapAtHits; }},
    // BLASes from full detail instead of the reflection LODs (default on):
    // what the LODs cost in error.
    {{"reflection_lods", "BvhSettings::reflectionLods (0: BLASes from full detail)", 0.0f, 1.0f, true, {0}, {0},
      kTraced},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.renderer.bvh.reflectionLods; }},
    // Spatiotemporal blue noise (default) against the hashed
    // low-discrepancy sequences.
    {{"blue_noise", "RayGenerationSettings::blueNoise (1: spatiotemporal blue noise, 0: hashed sequences)", 0.0f,
      1.0f, true, {0}, {0}, kEveryMode},
     nullptr, nullptr, [](ReflectionRunOptions& o) { return &o.frame.rays.blueNoise; }},
    // The longest temporal history (default 64 frames): longer averages
    // more noise away (less flicker) and trails further behind what the
    // clamp lets through.
    {{"history_frames", "TemporalSettings::maxHistoryFrames", 1.0f, 256.0f, false, {8, 16, 64, 128}, {}, kEveryMode},
     [](ReflectionRunOptions& o) { return &o.frame.temporal.maxHistoryFrames; }, nullptr},
    // The neighbourhood clamp's width in standard deviations (default 1.25):
    // narrower rejects stale history sooner and lets more noise through.
    {{"clamp_gamma", "TemporalSettings::clampGamma", 0.25f, 4.0f, false, {0.75, 1.0, 1.5, 2.0}, {}, kEveryMode},
     [](ReflectionRunOptions& o) { return &o.frame.temporal.clampGamma; }, nullptr},
    // The clamp's neighbourhood radius where quads share rays (default 2:
    // 5x5; 3x3 elsewhere): wider estimates the box from more independent
    // rays.
    {{"clamp_radius", "TemporalSettings::clampRadius", 1.0f, 3.0f, true, {2, 3}, {}, kEveryMode}, nullptr,
     [](ReflectionRunOptions& o) { return &o.frame.temporal.clampRadius; }},
    // Reflected objects' own motion in the reprojection (default on): off,
    // only the camera's motion reprojects, as before it.
    {{"reflected_motion", "ReflectionFrameSettings::reflectedMotion (0 or 1)", 0.0f, 1.0f, true, {0}, {}, kEveryMode},
     nullptr,
     nullptr, [](ReflectionRunOptions& o) { return &o.frame.reflectedMotion; }},
}};

const ParameterSlot& findParameter(std::string_view name) {
    for (const ParameterSlot& slot : kParameters) {
        if (slot.parameter.name == name) return slot;
    }
    std::string names;
    for (const ParameterSlot& slot : kParameters) names += (names.empty() ? "" : ", ") + std::string(slot.parameter.name);
    throw std::invalid_argument("unknown parameter '" + std::string(name) + "' (" + names + ")");
}

} // namespace

std::span<const Parameter> parameters() {
    static const std::vector<Parameter> list = [] {
        std::vector<Parameter> out;
        for (const ParameterSlot& slot : kParameters) out.push_back(slot.parameter);
        return out;
    }();
    return list;
}

void setParameter(ReflectionRunOptions& options, std::string_view name, std::string_view value) {
    const ParameterSlot& slot = findParameter(name);
    const std::string text(value);
    size_t used = 0;
    double v = 0.0;
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v) || v < 0.0) {
        throw std::invalid_argument("parameter " + std::string(name) + "=" + text + ": not a non-negative number");
    }
    if (slot.boolField) {
        if (v != 0.0 && v != 1.0) {
            throw std::invalid_argument("parameter " + std::string(name) + "=" + text + ": not 0 or 1");
        }
        *slot.boolField(options) = v == 1.0;
    } else if (slot.uintField) {
        // From the parameter's own least value (a count of steps starts at
        // 1, a radius at 0); the settings' checks bound the rest.
        const double least = slot.parameter.min;
        if (v != std::floor(v) || v < least || v > 4096.0) {
            throw std::invalid_argument("parameter " + std::string(name) + "=" + text + ": not an integer in " +
                                        std::to_string(int(least)) + "..4096");
        }
        *slot.uintField(options) = uint32_t(v);
    } else {
        *slot.floatField(options) = float(v);
    }
}

void setParameters(ReflectionRunOptions& options, std::string_view list) {
    for (size_t start = 0; start < list.size();) {
        const size_t end = std::min(list.find(',', start), list.size());
        const std::string item(list.substr(start, end - start));
        const size_t eq = item.find('=');
        if (eq == std::string::npos) throw std::runtime_error("--set " + item + ": expected NAME=VALUE");
        try {
            setParameter(options, item.substr(0, eq), item.substr(eq + 1));
        } catch (const std::invalid_argument& e) {
            throw std::runtime_error(std::string("--set: ") + e.what());
        }
        start = end + 1;
    }
}

double getParameter(const ReflectionRunOptions& options, std::string_view name) {
    const ParameterSlot& slot = findParameter(name);
    auto& o = const_cast<ReflectionRunOptions&>(options);  // the accessors are shared with setParameter
    if (slot.boolField) return *slot.boolField(o) ? 1.0 : 0.0;
    return slot.uintField ? double(*slot.uintField(o)) : double(*slot.floatField(o));
}

std::string parameterListing() {
    const ReflectionRunOptions defaults;
    const auto number = [](double v) {
        char text[32];
        std::snprintf(text, sizeof(text), "%g", v);
        return std::string(text);
    };
    std::string out;
    char line[256];
    std::snprintf(line, sizeof(line), "%-33s %-8s %-10s %-16s %s\n", "name", "default", "range", "bench sweeps in",
                  "field");
    out += line;
    for (const ParameterSlot& slot : kParameters) {
        const Parameter& p = slot.parameter;
        const std::string range = number(p.min) + ".." + number(p.max);
        std::string modes = std::string(p.sweepModes[0] ? "hybrid " : "") + (p.sweepModes[1] ? "ssr " : "") +
                            (p.sweepModes[2] ? "rt" : "");
        if (p.sweep.empty() || modes.empty()) modes = "-";
        std::snprintf(line, sizeof(line), "%-33.*s %-8s %-10s %-16s %.*s\n", int(p.name.size()), p.name.data(),
                      number(getParameter(defaults, p.name)).c_str(), range.c_str(), modes.c_str(),
                      int(p.field.size()), p.field.data());
        out += line;
    }
    return out;
}

scene::CameraPose cameraPoseAt(const scene::Scene& scene, const ReflectionRunOptions& options, uint32_t frame) {
    const float seconds = options.startSeconds + float(frame) * options.frameSeconds;
    if (scene.cameraPath.keys.size() != 1) {
        return scene.cameraPath.evaluate(seconds);
    }
    // A quarter degree per frame around the view's target, about the up axis.
    const scene::CameraPathKey& key = scene.cameraPath.keys.front();
    const float angle = glm::radians(0.25f) * float(frame);
    const glm::mat4 orbit = glm::rotate(glm::mat4(1.0f), angle, glm::vec3(0.0f, 1.0f, 0.0f));
    scene::CameraPose pose;
    pose.position = key.target + glm::vec3(orbit * glm::vec4(key.position - key.target, 0.0f));
    pose.target = key.target;
    return pose;
}

namespace {

// The reference's settings on top of the caller's (see ReferenceOptions).
ReflectionRunOptions referenceSettings(const ReflectionRunOptions& in) {
    ReflectionRunOptions o = in;
    const ReferenceOptions& r = in.reference;
    if (r.checkEvery == 0 || r.minFrames == 0 || r.maxFrames < r.minFrames || r.maxFrames > 2048 ||
        !(r.tolerance > 0.0)) {
        throw std::invalid_argument("reference: need 0 < tolerance, checkEvery >= 1, 1 <= minFrames <= maxFrames <= 2048");
    }
    o.frames = r.maxFrames;
    o.jitter = false;
    o.frame.mode = passes::ReflectionMode::Rt;
    o.frame.rays.reuse = false;
    // The reference converges on the low-discrepancy sequences, whichever
    // noise the measured runs use.
    o.frame.rays.blueNoise = false;
    o.frame.rays.roughnessCutoff = 1.0f;  // rough pixels are traced too: the environment is an approximation
    // Every object in the BVH, rays without end (the long-range group
    // reaches at least as far).
    o.frame.reach = 1e30f;
    // Exact shadows: a shadow ray from every hit, not the shadow map.
    o.frame.rt.shadowMapAtHits = false;
    // Full detail: the reference is the scene itself, not its reflection LODs.
    o.renderer.bvh.reflectionLods = false;
    // Every BLAS on the first frame: the reference accumulates from there.
    o.renderer.bvh.maxFirstBuildsPerFrame = std::numeric_limits<uint32_t>::max();
    o.renderer.bvh.maxFirstBuildTrianglesPerFrame = std::numeric_limits<uint64_t>::max();
    o.frame.temporal.maxHistoryFrames = float(r.maxFrames);
    o.frame.temporal.neighbourhoodClamp = false;
    o.frame.temporal.spatialRadius = 0;
    o.frame.debugView.clear();
    o.freezeTime = true;
    o.captureFrames.clear();
    return o;
}

// The resolved reflections (RGBA16F) as floats.
std::vector<float> resolvedFloats(const rg::HostReadback& resolved, size_t pixels) {
    const auto halves = resolved.as<uint16_t>();
    std::vector<float> out(pixels * 4);
    for (size_t k = 0; k < out.size(); ++k) out[k] = glm::unpackHalf1x16(halves[k]);
    return out;
}

// The G-buffer's roughness (RGBA8 unorm, r) where a reflection exists, -1
// elsewhere.
std::vector<float> roughnessFloats(const rg::HostReadback& roughnessMetal, const std::vector<float>& resolved) {
    const auto bytes = roughnessMetal.as<uint8_t>();
    std::vector<float> out(resolved.size() / 4);
    for (size_t p = 0; p < out.size(); ++p) {
        out[p] = resolved[p * 4 + 3] > 0.0f ? float(bytes[p * 4]) / 255.0f : -1.0f;
    }
    return out;
}

// Mean of the reflected radiance (rgb summed) over the pixels that reflect.
double meanReflection(const rg::HostReadback& resolved, uint32_t pixels) {
    const auto halves = resolved.as<uint16_t>();
    double sum = 0.0;
    uint64_t n = 0;
    for (uint32_t p = 0; p < pixels; ++p) {
        if (glm::unpackHalf1x16(halves[p * 4 + 3]) < 0.5f) continue;
        sum += double(glm::unpackHalf1x16(halves[p * 4])) + glm::unpackHalf1x16(halves[p * 4 + 1]) +
               glm::unpackHalf1x16(halves[p * 4 + 2]);
        ++n;
    }
    return n ? sum / double(n) : 0.0;
}

} // namespace

ReflectionRunResult runReflections(gpu::Context& ctx, scene::Scene& scene, const ReflectionRunOptions& requested) {
    const bool reference = requested.reference.enabled;
    const ReflectionRunOptions options = reference ? referenceSettings(requested) : requested;
    if (options.frames == 0) throw std::invalid_argument("--frames must be at least 1");
    rg::Executor executor(ctx, options.renderer.framesInFlight);
    executor.setCarrySkippedBarriers(options.carrySkippedBarriers);
    const bool cpuDevice = ctx.caps().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    executor.setPassTimer(options.passTimer.value_or(cpuDevice ? rg::PassTimer::HostSerial
                                                               : rg::PassTimer::GpuTimestamps));
    passes::ReflectionRenderer renderer(ctx, scene, options.renderer);
    if (reference && !renderer.tracesRays()) {
        throw std::runtime_error("reference mode traces rays, and device '" + ctx.caps().deviceName +
                                 "' has no ray tracing (or it was disabled)");
    }

    ReflectionRunResult result;
    result.backend = renderer.backend();
    result.mode = renderer.tracesRays() ? options.frame.mode : passes::ReflectionMode::Ssr;
    result.passTimer = executor.passTimer();
    const uint32_t w = options.width, h = options.height;
    const rg::HostReadback image(ctx, VkDeviceSize(w) * h * 4, "readback.output");
    const rg::HostReadback counts(ctx, shader::kReflectionCountWords * 4u, "readback.counts");
    const rg::HostReadback occlusion(ctx, shader::kOcclusionStatWords * 4u, "readback.occlusion");
    bool occlusionRead = false;
    std::optional<rg::HostReadback> resolved, roughness;
    const bool captures = !options.captureFrames.empty();
    if (reference || options.readResolved || captures) {
        resolved.emplace(ctx, VkDeviceSize(w) * h * 8, "readback.resolved");
    }
    if (options.readResolved || captures) roughness.emplace(ctx, VkDeviceSize(w) * h * 4, "readback.roughness");
    for (size_t k = 0; k < options.captureFrames.size(); ++k) {
        const bool increasing = k == 0 || options.captureFrames[k] > options.captureFrames[k - 1];
        if (options.captureFrames[k] >= options.frames || !increasing) {
            throw std::invalid_argument("captureFrames: expected increasing frame indices below " +
                                        std::to_string(options.frames));
        }
    }
    size_t nextCapture = 0;
    std::optional<double> previousMean;
    const uint64_t frameBase = reference ? uint64_t(options.reference.seed) << 20 : 0;

    scene::Camera camera;
    camera.resolution = {w, h};
    camera.lens = scene.lens;
    camera.jitter = options.jitter && options.frames > 1;

    std::map<std::string, std::vector<double>> passTimes, passCpuTimes;
    std::map<std::string, rg::Queue> passQueues;
    std::vector<std::string> passOrder;
    std::vector<double> reflectionTimes, totalTimes, reflectionCpuTimes, spanTimes;
    std::optional<uint64_t> lastTimed;
    std::vector<double> wallTimes;
    const auto collectTimings = [&] {
        if (const std::optional<double> span = executor.spanTiming()) spanTimes.push_back(*span);
        const std::vector<rg::PassTiming> timings = executor.timings();
        if (timings.empty() || (lastTimed && timings.front().frame == *lastTimed)) return;
        lastTimed = timings.front().frame;
        double reflection = 0.0, total = 0.0;
        bool any = false;
        // Passes that share a name (the pyramid's levels) count as one.
        std::map<std::string, double> frameTimes, frameCpuTimes;
        double reflectionCpu = 0.0;
        for (const rg::PassTiming& t : timings) {
            if (!t.milliseconds) continue;
            any = true;
            if (!passTimes.count(t.name) && !frameTimes.count(t.name)) passOrder.push_back(t.name);
            frameTimes[t.name] += *t.milliseconds;
            if (t.cpuMilliseconds) {
                frameCpuTimes[t.name] += *t.cpuMilliseconds;
                if (passes::isReflectionPass(t.name)) reflectionCpu += *t.cpuMilliseconds;
            }
            passQueues[t.name] = t.queue;
            total += *t.milliseconds;
            if (passes::isReflectionPass(t.name)) reflection += *t.milliseconds;
        }
        for (const auto& [name, ms] : frameTimes) passTimes[name].push_back(ms);
        for (const auto& [name, ms] : frameCpuTimes) passCpuTimes[name].push_back(ms);
        if (!frameCpuTimes.empty()) reflectionCpuTimes.push_back(reflectionCpu);
        if (any) {
            reflectionTimes.push_back(reflection);
            totalTimes.push_back(total);
        }
    };

    const auto start = std::chrono::steady_clock::now();
    auto lastReport = start;
    uint64_t blockingAfterFirst = 0;
    // Frames of one shape (most of them: the first frame, the readback
    // frames and the reference's checks differ) reuse one compiled plan.
    rg::PlanCache planCache;
    for (uint32_t i = 0; i < options.frames; ++i) {
        // The reference stands still: one pose, one scene time; only the
        // frame index (the noise) moves.
        const scene::CameraPose pose =
            options.stillPose ? *options.stillPose : cameraPoseAt(scene, options, reference ? 0 : i);
        if (i == 0) {
            camera.reset(pose, frameBase);
        } else {
            camera.advance(pose, frameBase + i);
        }
        scene::advanceScene(scene, options.startSeconds + (options.freezeTime ? 0.0f : float(i) * options.frameSeconds),
                            &camera);
        const bool capture = nextCapture < options.captureFrames.size() && options.captureFrames[nextCapture] == i;

        const bool check = reference && (i + 1) % options.reference.checkEvery == 0;
        const bool last = i + 1 == options.frames || check;
        passes::ReflectionFrameSettings settings = options.frame;
        settings.resetHistory = i == 0 || std::ranges::find(options.cutFrames, i) != options.cutFrames.end();
        settings.countRays = last;
        rg::Graph graph(executor.queueCaps());
        const passes::ReflectionFrame frame = renderer.addFrame(graph, camera, settings);
        rg::FrameResources resources;
        renderer.bind(resources, frame);
        result.screenSpaceIdleFrames += frame.screenSpaceIdle ? 1u : 0u;
        result.lastScreenSpaceIdle = frame.screenSpaceIdle;
        result.lastSslrProbeSpacing = frame.sslrProbeSpacing;
        if (last) {
            image.copy(graph, resources, frame.output.color);
            counts.copy(graph, resources, frame.counts);
            occlusionRead = frame.gbuffer.occlusionStats.valid();
            if (occlusionRead) occlusion.copy(graph, resources, frame.gbuffer.occlusionStats);
        }
        if (check || (last && options.readResolved) || capture) {
            resolved->copy(graph, resources, frame.temporal.resolved);
        }
        if ((last && options.readResolved) || capture) {
            roughness->copy(graph, resources, frame.gbuffer.roughnessMetal);
        }
        // Timed frames alternate: per-pass times (odd frames), then the
        // reflection chain as one span without them (reflection_span_ms,
        // even frames after the first), so the timestamps
        // around every pass, and the queue drains they cost, do not decide
        // which mode looks faster.
        if (options.timeEveryFrame) {
            const bool perPass = i == 0 || i % 2 == 1;
            executor.setTimedSpan(perPass ? std::nullopt
                                          : std::optional<rg::TimedSpan>({"reflections", passes::isReflectionPass}),
                                  perPass);
        }
        const auto frameStart = std::chrono::steady_clock::now();
        const rg::Plan& plan = planCache.compile(graph, executor.compileOptions());
        // Under --validate the plan's own checker runs too: the validation
        // layer does not see hazards between dispatches' shader writes or
        // around acceleration-structure builds (graph/verify.h).
        if (ctx.validationEnabled()) {
            const rg::VerifyReport report = rg::verify(plan);
            if (!report.ok()) throw std::runtime_error("render graph plan of frame " + std::to_string(i) + ": " + report.text());
            // A frame that skips passes (the host's SSLR gate) runs with
            // their barriers carried on: that plan is checked too (a
            // carried barrier may serve only the pass that skipped, so
            // without the redundancy rule).
            if (rg::hasSkippedPasses(plan)) {
                rg::VerifyOptions carried;
                carried.checkRedundancy = false;
                const rg::VerifyReport skipped = rg::verify(rg::skipPasses(plan), carried);
                if (!skipped.ok())
                    throw std::runtime_error("render graph plan of frame " + std::to_string(i) +
                                             " with its skipped passes: " + skipped.text());
            }
        }
        executor.run(plan, resources);
        // Every frame's pass times: waiting here serialises frames on the
        // host but not the GPU work inside a frame (the async BVH build
        // still overlaps the G-buffer), and the times are GPU timestamps.
        // The first frame (history and transient set-up, first BLAS builds)
        // is not timed.
        if (options.timeEveryFrame) {
            executor.waitIdle();
            if (i > 0) {
                collectTimings();
            }
            // The wall time of frames with per-pass timing (host-serial: each
            // pass waited for), like-for-like from frame to frame.
            if (i % 2 == 1) {
                wallTimes.push_back(
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frameStart).count());
            }
        }
        if (frame.bvh) {
            result.blasBuilt += renderer.bvhGpuStats().blasBuilds;
            result.blasRebuilt += renderer.bvhGpuStats().blasRebuilds;
        }

        result.framesRun = i + 1;
        if (capture) {
            executor.waitIdle();
            FrameCapture c;
            c.frame = i;
            c.resolved = resolvedFloats(*resolved, size_t(w) * h);
            c.roughness = roughnessFloats(*roughness, c.resolved);
            result.captures.push_back(std::move(c));
            ++nextCapture;
        }
        if (i == 0) blockingAfterFirst = ctx.blockingSubmits();
        if (check) {
            executor.waitIdle();
            const double mean = meanReflection(*resolved, w * h);
            if (previousMean) {
                result.lastChange = std::abs(mean - *previousMean) / std::max(std::abs(mean), 1e-6);
                spdlog::debug("reference: {} frames, mean {:.6f}, change {:.2e}", i + 1, mean, result.lastChange);
                if (i + 1 >= options.reference.minFrames && result.lastChange < options.reference.tolerance) {
                    result.converged = true;
                    break;
                }
            }
            previousMean = mean;
        }

        const auto now = std::chrono::steady_clock::now();
        if (now - lastReport > std::chrono::seconds(2) && i + 1 != options.frames) {
            if (reference) {
                spdlog::info("reference: {} frames, last change {:.2e} (tolerance {:.1e})", i + 1, result.lastChange,
                             options.reference.tolerance);
            } else {
                spdlog::info("frame {}/{} ({:.1f} s)", i + 1, options.frames,
                             std::chrono::duration<double>(now - start).count());
            }
            lastReport = now;
        }
    }
    if (reference) {
        spdlog::info("reference: {} after {} frames (last change {:.2e}, tolerance {:.1e})",
                     result.converged ? "converged" : "stopped at the frame limit", result.framesRun,
                     result.lastChange, options.reference.tolerance);
    }
    executor.waitIdle();
    if (options.frames == 1 || !options.timeEveryFrame) collectTimings();
    result.blockingSubmits = ctx.blockingSubmits() - blockingAfterFirst;
    result.planCompiles = planCache.misses();
    result.planReuses = planCache.hits();
    spdlog::info("render graph: {} of {} frames reused a compiled plan, {} compiled", result.planReuses,
                 result.framesRun, result.planCompiles);

    for (const std::string& name : passOrder) {
        result.passes.push_back({name, passQueues[name], median(passTimes[name]), mean(passTimes[name]),
                                 passCpuTimes.count(name) ? std::optional(median(passCpuTimes[name])) : std::nullopt});
    }
    result.framesTimed = uint32_t(totalTimes.size());
    if (!wallTimes.empty()) result.frameWallMs = median(wallTimes);
    if (!spanTimes.empty()) {
        result.reflectionSpanMs = median(spanTimes);
        result.reflectionSpanMeanMs = mean(spanTimes);
    }
    if (!totalTimes.empty()) {
        result.reflectionMs = median(reflectionTimes);
        result.reflectionMeanMs = mean(reflectionTimes);
        if (!reflectionCpuTimes.empty()) result.reflectionCpuMs = median(reflectionCpuTimes);
        result.totalMs = median(totalTimes);
    }
    result.rgba.resize(size_t(w) * h * 4);
    std::memcpy(result.rgba.data(), image.bytes().data(), result.rgba.size());
    if (options.readResolved) {
        result.resolved = resolvedFloats(*resolved, size_t(w) * h);
        result.roughness = roughnessFloats(*roughness, result.resolved);
    }
    std::vector<uint32_t> words(shader::kReflectionCountWords);
    std::memcpy(words.data(), counts.bytes().data(), words.size() * 4);
    result.pixelClasses.assign(words.begin(), words.begin() + shader::kPixelClassCount);
    result.sslrRays = words[shader::kCountSslrRays];
    result.rtRays = words[shader::kCountRtRays];
    result.tlasInstances = result.mode == passes::ReflectionMode::Ssr ? 0 : renderer.bvhGpuStats().tlasInstances;
    result.gbuffer = renderer.gbufferStats();
    if (occlusionRead) {
        const auto cull = occlusion.as<uint32_t>();
        result.occlusion.assign(cull.begin(), cull.begin() + shader::kOcclusionStatWords);
    }
    return result;
}

std::string statsJson(const gpu::Context& ctx, const ReflectionRunOptions& options, const ReflectionRunResult& r) {
    using nlohmann::json;
    json j;
    j["device"] = ctx.caps().deviceName;
    j["driver"] = ctx.caps().driverName + " " + ctx.caps().driverInfo;
    j["mode"] = options.reference.enabled ? std::string("reference") : std::string(passes::modeName(r.mode));
    if (r.mode != options.frame.mode) j["requested_mode"] = std::string(passes::modeName(options.frame.mode));
    if (options.reference.enabled) {
        j["reference"] = {{"frames", r.framesRun},
                          {"converged", r.converged},
                          {"last_change", r.lastChange},
                          {"tolerance", options.reference.tolerance},
                          {"seed", options.reference.seed}};
    }
    j["backend"] = r.mode == passes::ReflectionMode::Ssr ? "none" : std::string(passes::backendName(r.backend));
    j["size"] = {options.width, options.height};
    j["frames"] = options.reference.enabled ? r.framesRun : options.frames;
    j["frames_timed"] = r.framesTimed;
    json passList = json::array();
    for (const PassTime& p : r.passes) {
        passList.push_back({{"name", p.name},
                            {"queue", p.queue == rg::Queue::AsyncCompute ? "async_compute" : "graphics"},
                            {"gpu_ms", p.milliseconds},
                            {"gpu_mean_ms", p.meanMilliseconds}});
        if (p.cpuMilliseconds) passList.back()["cpu_ms"] = *p.cpuMilliseconds;
    }
    j["passes"] = passList;
    // gpu_ms is a GPU timestamp difference, or with host_serial the host's
    // wall time of the pass submitted alone (CPU devices).
    j["pass_timer"] = r.passTimer == rg::PassTimer::HostSerial ? "host_serial" : "gpu_timestamps";
    j["reflection_ms"] = r.reflectionMs ? json(*r.reflectionMs) : json(nullptr);
    // The same chain timed as one span, in the other half of the frames,
    // with no per-pass timestamps.
    j["reflection_span_ms"] = r.reflectionSpanMs ? json(*r.reflectionSpanMs) : json(nullptr);
    // Means of both: work that runs on some frames only (the hybrid's SSLR
    // probe frames) counts here and not in the medians.
    j["reflection_mean_ms"] = r.reflectionMeanMs ? json(*r.reflectionMeanMs) : json(nullptr);
    j["reflection_span_mean_ms"] = r.reflectionSpanMeanMs ? json(*r.reflectionSpanMeanMs) : json(nullptr);
    if (r.reflectionCpuMs) j["reflection_cpu_ms"] = *r.reflectionCpuMs;
    j["total_ms"] = r.totalMs ? json(*r.totalMs) : json(nullptr);
    j["frame_wall_ms"] = r.frameWallMs ? json(*r.frameWallMs) : json(nullptr);
    j["rays"] = {{"sslr", r.sslrRays}, {"rt", r.rtRays}};
    // Hybrid frames rendered as rt because SSLR did not pay (FeedbackSettings::hostGate).
    j["screen_space_idle_frames"] = r.screenSpaceIdleFrames;
    // Host-blocking submissions after the first frame (uploads, one-off
    // work): a steady frame makes none.
    j["blocking_submits"] = r.blockingSubmits;
    const double pixels = double(options.width) * options.height;
    const auto share = [&](uint32_t c) { return c < r.pixelClasses.size() ? double(r.pixelClasses[c]) / pixels : 0.0; };
    j["pixel_classes"] = {{"ssr", share(shader::kPixelSslr)}, {"hybrid", share(shader::kPixelHybrid)},
                          {"rt", share(shader::kPixelRt)},    {"env", share(shader::kPixelEnv)},
                          {"sky", share(shader::kPixelSky)}};
    j["bvh"] = {{"blas_built", r.blasBuilt}, {"blas_rebuilt", r.blasRebuilt}, {"tlas_instances", r.tlasInstances}};
    // The last frame's raster work: what frustum culling left to draw, and
    // the triangles of the facets skipped for facing away.
    j["raster"] = {{"draws", r.gbuffer.draws},
                   {"runs", r.gbuffer.runs},
                   {"triangles", r.gbuffer.triangles},
                   {"facet_triangles_skipped", r.gbuffer.facetTrianglesSkipped},
                   {"instances_culled", r.gbuffer.instancesCulled},
                   {"shadow_draws", r.gbuffer.shadowDraws},
                   {"shadow_instances_culled", r.gbuffer.shadowInstancesCulled}};
    // With occlusion culling (GBufferSettings::occlusionCulling), what the
    // GPU drew of those draws: instances drawn early (visible last frame)
    // and late (newly visible), those in the frustum drawn in neither, and
    // the triangles drawn.
    if (!r.occlusion.empty()) {
        j["raster"]["occlusion"] = {{"instances_early", r.occlusion[shader::kOcclusionStatEarly]},
                                    {"instances_late", r.occlusion[shader::kOcclusionStatLate]},
                                    {"instances_occluded", r.occlusion[shader::kOcclusionStatOccluded]},
                                    {"triangles_drawn", r.occlusion[shader::kOcclusionStatTriangles]}};
    }
    return j.dump(2) + "\n";
}

} // namespace glint::app
