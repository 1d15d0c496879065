#pragma once
// Pass 6 of the reflection pipeline, its first half: the tile
// feedback. Far Cry 6 keeps one u32 per 8x8 tile with the SSLR hit and miss
// counts of two frames (layout: glint/feedback_shared.h)
// and uses it to send each tile's hybrid pixels to SSLR only, to SSLR with
// the ray tracer behind it, or straight to the ray tracer. At the start of a
// frame, after the G-buffer, one compute pass
//   - carries last frame's counters (the history buffer
//     "reflections.feedback") to this frame's tiles along the motion of one
//     pseudo-random pixel per tile, new every frame ("reprojected"; content
//     from off screen gets 0);
//   - decides each tile's mode from the two frames of counts it carried
//     ("tileModes": kTileMode*, read by ray generation);
//   - but first whether SSLR pays at all this frame: where last frame's
//     SSLR hits, summed over the frame, fall short of sslrMinHitShare of the
//     pixels, every tile sends its hybrid pixels straight to RT
//     (kTileModeRtOnly, no pixel kept hybrid), so that SSLR's passes run no
//     groups, except on one probe frame in sslrProbeInterval, which tries
//     SSLR everywhere again. The SSLR pass costs a floor (its longest
//     march, the pyramid) at any ray count; on a scene where it resolves a
//     few rays, the rays it saves cost less than that floor.
// Integrate (passes/integrate.h) writes this frame's counts into the
// history's `current` half, rotating the reprojected counter's counts into
// the previous half, and adds the frame's hits to the sum after the tiles.
//
//   passes::FeedbackPipelines feedbackPipelines(ctx);   // once
//   each frame, after the G-buffer:
//     const auto feedback = passes::addFeedbackPass(graph, feedbackPipelines, {gbuf, frame}, {});
//     ... ray generation reads feedback.tileModes ...
//     ... integrate reads feedback.reprojected and writes feedback.counters.current ...

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/gbuffer.h"

#include <cstdint>

namespace glint::passes {

// The history pair's name: one pair per executor, kept across frames.
inline constexpr const char* kFeedbackHistoryName = "reflections.feedback";

struct FeedbackInputs {
    GBufferOutputs gbuffer;  // motion (and the size)
    // Picks each tile's probe pixel; the same index, the same probes.
    uint64_t frameIndex = 0;
    // Carry no counters (a camera cut, a new scene: the temporal pass's
    // history is discarded with them): every tile starts hybrid, without
    // evidence, as on the first frame.
    bool resetHistory = false;
    // The host's side of the gate (ReflectionRenderer, FeedbackSettings::
    // hostGate). When valid (4 bytes), the pass's shader writes the
    // counters' word after the tiles of last frame (`previous`: its SSLR
    // hits) into it (a storage write), for the host to read once the frame
    // has finished.
    rg::Buffer report;
    // False: the report is declared but not written (last frame wrote no
    // counters, so there is nothing to report).
    bool reportLastFrame = true;
    // A hybrid frame the host renders as rt (ReflectionRenderer's SSLR
    // gate: ray generation reads no tile modes, integrate writes no
    // counters): the pass writes only the report, if any (one workgroup),
    // and is skipped without one (rg::Builder::skip: no barriers of its own).
    // Its declarations stay the same, so that the frame keeps its plan.
    bool screenSpaceIdle = false;
};

struct FeedbackSettings {
    // A tile whose two frames hold fewer traced SSLR rays than this has no
    // evidence and stays hybrid. 1: any ray is evidence, the talk's rule.
    // Glint's starting value; the bench may raise it for stability.
    uint32_t minRays = 1;
    // A tile goes SSLR-only when at most this fraction of its rays missed,
    // RT-only when at most this fraction hit. 0: only hits / only misses,
    // as the Far Cry 6 talk describes it; a small
    // fraction tolerates a stray ray (Glint's knob, tuned by the bench).
    float sslrMissFraction = 0.0f;
    float rtHitFraction = 0.0f;
    // SSLR is tried on hybrid pixels only while last frame's SSLR hits
    // (rays at or above the confidence threshold, over the whole frame)
    // reach this share of the pixels; below it the frame's hybrid pixels go
    // straight to RT. 0: SSLR is always tried. Glint's knob, not the talk's:
    // on the H200 at 1080p (docs/results/log/03-2026-12-03-04.md) the SSLR pass and its pyramid
    // cost 0.08 ms at any ray count, about what tracing 5% of the pixels
    // costs there; the scenes where SSLR helps resolve 12-21% of the pixels
    // (the plaza, the city) and those where it does not 0.1-0.4%
    // (DamagedHelmet, CornellBox-Vinc3r).
    float sslrMinHitShare = 0.02f;
    // While SSLR does not pay, one frame in this many (feedbackProbeFrame:
    // at a pseudo-random place in each block) tries it on every hybrid
    // pixel again, so that the frame comes back to SSLR when it starts to
    // hit. 1: every frame.
    uint32_t sslrProbeInterval = 8;
    // The same gate on the host (passes/reflection_frame.h): once the hits
    // of a frame that tried SSLR, read back a few frames later, fall short
    // of sslrMinHitShare, the frames that are not probe frames render as rt
    // (ray generation sends every traced pixel to RT, and the feedback, the
    // pyramid and the SSLR pass record nothing), until a probe frame's hits
    // reach the share again. Removes what the GPU gate still pays on such
    // frames: this pass, SSLR's empty dispatches, integrate's hybrid
    // variant. Off: only the GPU gate.
    bool hostGate = true;
    // While the host's gate holds SSLR back, its probe frames render as rt
    // too: SSLR traces every hybrid ray and its hits are counted for the
    // report, but it hands every ray on to RT and integrate takes the ray
    // tracer's result, so the frame's reflections are rt mode's exactly.
    // The probe then measures without adding SSLR's less accurate hits to
    // the history of a scene where it does not pay (it costs the RT rays
    // of what SSLR resolved: few, or the gate would be open). Off: a probe
    // uses what SSLR resolves, as a hybrid frame does.
    bool probesRenderAsRt = true;
    // The host's gate backs off: each probe whose report says SSLR still
    // does not pay halves how often the next ones come (only one probe
    // frame of feedbackProbeFrame's in 2, 4, ... is kept), until one in
    // this many frames; a report that says SSLR pays, or a cut, goes back
    // to sslrProbeInterval. A probe frame costs what the hybrid costs
    // without the gate (on the H200 at 1080p 0.085-0.11 ms more than rt
    // where SSLR resolves nothing, docs/results/log/05-2026-12-06-a.md); the frames between
    // render as rt, so backing off costs no accuracy, only the time SSLR
    // takes to come back where it starts to pay. At least sslrProbeInterval; equal: no
    // backing off.
    uint32_t sslrProbeIntervalMax = 32;
    // Off: every tile hybrid, as if there were no feedback (the bench's
    // baseline); the counters are still carried.
    bool adaptive = true;
};

struct FeedbackOutputs {
    // u32 per tile, then the frame's SSLR hits (glint/feedback_shared.h);
    // previous: last frame's; current: written by integrate.
    rg::HistoryBuffer counters;
    rg::Buffer reprojected;      // u32 per tile: last frame's counter carried to this tile
    rg::Buffer tileModes;        // u32 per tile, shader::kTileMode*
    uint32_t tilesX = 0;
    uint32_t tilesY = 0;
    // The frame's hits that make SSLR pay (sslrMinHitShare of the pixels,
    // rounded up; 0 when the share is 0): integrate stops adding to the sum
    // once it reaches them.
    uint32_t minFrameHits = 0;
};

// FeedbackOutputs::minFrameHits for a frame of width x height pixels.
uint32_t feedbackMinFrameHits(const FeedbackSettings& settings, uint32_t width, uint32_t height);

// Whether the host's gate keeps `frame` as a probe frame at backing-off
// `stride` (1, 2, 4, ..., FeedbackSettings::sslrProbeIntervalMax /
// sslrProbeInterval): feedbackProbeFrame's probe of every stride-th block
// of sslrProbeInterval frames.
bool hostProbeFrame(uint64_t frame, uint32_t probeInterval, uint32_t stride);

// The pipeline and the sampler the pass records with; created once.
class FeedbackPipelines {
public:
    explicit FeedbackPipelines(gpu::Context& ctx);

private:
    friend FeedbackOutputs addFeedbackPass(rg::Graph&, FeedbackPipelines&, const FeedbackInputs&,
                                           const FeedbackSettings&);
    gpu::Context& ctx_;
    gpu::Pipeline reproject_;
    gpu::Sampler nearest_;
};

// Declares the pass (see the top of this file) on the graphics queue. The
// history pair is created on the graph here; integrate must write its
// `current` half in the same frame (the executor swaps the pair only in
// frames that write it).
FeedbackOutputs addFeedbackPass(rg::Graph& graph, FeedbackPipelines& pipelines, const FeedbackInputs& inputs,
                                const FeedbackSettings& settings = {});

} // namespace glint::passes
