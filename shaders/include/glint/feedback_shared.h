// The 8x8-tile feedback counters of the hybrid reflections (Far Cry 6 talk,
// constants and packing shared by GLSL and C++
// (passes/integrate.cpp writes them, passes/feedback.cpp reprojects them
// and decides each tile's mode, shaders/ray_generation/classify.comp reads
// the modes).
//
// One u32 per 8x8 tile (glint/ray_generation_shared.h's kTileSize), 8 bits
// per count, saturating at 255:
//   bits  0- 7  SSLR hits of this frame   (traced SSLR/hybrid rays at or
//                                          above the confidence threshold)
//   bits  8-15  SSLR misses of this frame (below it)
//   bits 16-23  SSLR hits of the previous frame
//   bits 24-31  SSLR misses of the previous frame
// Integrate writes this frame's counts in the low half and moves the
// reprojected counter's low half (last frame's counts) into the high half.
//
// The counters buffer holds one word more, after the tiles: 1 + the
// frame's SSLR hits summed over every tile (the feedback pass sets it to 1
// at the start of the frame; integrate adds each tile's hits until the sum
// reaches FeedbackConstants::minFrameHits). 0 says no frame wrote it (a new
// pair): no evidence. Next frame's feedback pass reads it to decide whether
// SSLR pays at all (sslrPays).
#ifndef GLINT_FEEDBACK_SHARED_H
#define GLINT_FEEDBACK_SHARED_H

#include "glint/shared.h"
#include "glint/packing.h"  // GLINT_FUNC, min in C++
#include "glint/ray_generation_shared.h"  // kTileSize
#include "glint/sampling.glsl"            // pcgHash

GLINT_BEGIN

// Tile modes, one u32 per tile, decided by the feedback pass from the
// reprojected counters and read by ray generation for its hybrid pixels:
// SSLR only, SSLR then RT for low confidence, or straight to RT.
GLINT_CONST uint kTileModeSslr = 0u;
GLINT_CONST uint kTileModeHybrid = 1u;
GLINT_CONST uint kTileModeRt = 2u;
// Straight to RT with no pixel kept hybrid: the whole frame's SSLR hits
// were too few for the SSLR pass to pay for itself, and this frame is not
// a probe frame (feedbackProbeFrame).
GLINT_CONST uint kTileModeRtOnly = 3u;

GLINT_CONST uint kFeedbackCountMax = 255u;

GLINT_FUNC uint packFeedback(uint hits, uint misses, uint previousHits, uint previousMisses) {
    return min(hits, kFeedbackCountMax) | (min(misses, kFeedbackCountMax) << 8u) |
           (min(previousHits, kFeedbackCountMax) << 16u) | (min(previousMisses, kFeedbackCountMax) << 24u);
}

GLINT_FUNC uint feedbackHits(uint counter) { return counter & 0xFFu; }
GLINT_FUNC uint feedbackMisses(uint counter) { return (counter >> 8u) & 0xFFu; }
GLINT_FUNC uint feedbackPreviousHits(uint counter) { return (counter >> 16u) & 0xFFu; }
GLINT_FUNC uint feedbackPreviousMisses(uint counter) { return (counter >> 24u) & 0xFFu; }

// The next frame's counter: this frame's counts, and the (reprojected)
// counter's current counts moved into the previous half.
GLINT_FUNC uint rotateFeedback(uint reprojected, uint hits, uint misses) {
    return packFeedback(hits, misses, feedbackHits(reprojected), feedbackMisses(reprojected));
}

// ---------------------------------------------------------------------------
// The feedback pass (passes/feedback.cpp, shaders/feedback/reproject.comp)
// ---------------------------------------------------------------------------

// The tile's mode from its two frames of counts (a reprojected counter):
//   fewer than minRays traced rays in both frames  -> hybrid (no evidence)
//   misses at most sslrMissFraction of the rays     -> SSLR (only hits)
//   hits at most rtHitFraction of the rays          -> RT (only misses)
//   otherwise                                       -> hybrid (mixed)
// With both fractions 0 a tile needs every ray to agree before it leaves
// hybrid, the Far Cry 6 talk's rule; passes/feedback.h
// documents the knobs.
GLINT_FUNC uint decideTileMode(uint counter, uint minRays, float sslrMissFraction, float rtHitFraction) {
    const uint hits = feedbackHits(counter) + feedbackPreviousHits(counter);
    const uint misses = feedbackMisses(counter) + feedbackPreviousMisses(counter);
    const uint total = hits + misses;
    if (total == 0u || total < minRays) {
        return kTileModeHybrid;
    }
    if (float(misses) <= sslrMissFraction * float(total)) {
        return kTileModeSslr;
    }
    if (float(hits) <= rtHitFraction * float(total)) {
        return kTileModeRt;
    }
    return kTileModeHybrid;
}

// Whether SSLR is tried this frame whatever last frame's hits: one frame in
// each block of `interval` frames, at a pseudo-random place in the block,
// so that the probes do not fall on one parity or one quad-leader corner
// of the frame index (ray generation rotates the leader every frame; the
// samples' timing alternates frame by frame). At most 2 * interval - 1
// frames apart. Interval 0 or 1: every frame.
GLINT_FUNC bool feedbackProbeFrame(uint frame, uint interval) {
    if (interval <= 1u) {
        return true;
    }
    return frame % interval == pcgHash(frame / interval) % interval;
}

// The counters' word after the tiles at the start of a frame, before
// integrate adds the frame's hits.
GLINT_CONST uint kFeedbackFrameHitsStart = 1u;

// Whether SSLR pays this frame: last frame's SSLR hits (`lastFrameWord`,
// the counters' word after the tiles) reached minFrameHits, or this is a
// probe frame, or there is no evidence (a new pair, a reset). Otherwise
// every tile's hybrid pixels go straight to RT (kTileModeRtOnly), the SSLR
// list stays empty and SSLR's passes run no groups.
GLINT_FUNC bool sslrPays(uint lastFrameWord, uint minFrameHits, bool probeFrame, bool reset) {
    const bool noEvidence = reset || lastFrameWord < kFeedbackFrameHitsStart;
    return noEvidence || probeFrame || lastFrameWord - kFeedbackFrameHitsStart >= minFrameHits;
}

// The pixel of `tile` whose motion carries the tile's counter this frame:
// a new pseudo-random one every frame (the talk's "random motion vector of
// the tile"), so over frames the whole tile votes, not one corner. Inside
// the image for the partial tiles at the right and bottom edges.
GLINT_FUNC uvec2 feedbackProbePixel(uvec2 tile, uint frame, uvec2 size) {
    const uint h = pcgHash(tile.x + pcgHash(tile.y + pcgHash(frame)));
    const uint x0 = tile.x * kTileSize;
    const uint y0 = tile.y * kTileSize;
    const uint w = min(kTileSize, size.x - x0);
    const uint hgt = min(kTileSize, size.y - y0);
    return uvec2(x0 + (h & 0xFFFFu) % w, y0 + (h >> 16u) % hgt);
}

// Push constants of reproject.comp (48 bytes).
struct FeedbackConstants {
    uvec2 size;   // pixels
    uvec2 tiles;  // tiles in x and y
    uint frame;
    uint minRays;
    float sslrMissFraction;
    float rtHitFraction;
    uint adaptive;      // 0: every tile hybrid
    uint resetHistory;  // 1: carry nothing (a camera cut): every tile starts without evidence
    uint minFrameHits;  // SSLR hits of last frame below which SSLR does not pay (sslrPays); 0: it always does
    uint probeInterval; // feedbackProbeFrame's interval
    uint report;        // kFeedbackReport*: last frame's SSLR hits into the host's report
};

// FeedbackConstants::report: none; the word of last frame's hits copied
// into the report (the host's gate, passes/reflection_frame.h) by the
// first invocation; only that (a frame the host renders as rt: one group).
GLINT_CONST uint kFeedbackReportNone = 0u;
GLINT_CONST uint kFeedbackReport = 1u;
GLINT_CONST uint kFeedbackReportOnly = 2u;

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::FeedbackConstants) == 52);
#endif

#endif
