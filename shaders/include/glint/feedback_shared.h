// The 8x8-tile feedback counters of the hybrid reflections (Far Cry 6 talk,
// DESIGN.md section 3): constants and packing shared by GLSL and C++
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
#ifndef GLINT_FEEDBACK_SHARED_H
#define GLINT_FEEDBACK_SHARED_H

#include "glint/shared.h"
#include "glint/packing.h"  // GLINT_FUNC, min in C++

GLINT_BEGIN

// Tile modes, one u32 per tile, decided by the feedback pass from the
// reprojected counters and read by ray generation for its hybrid pixels:
// SSLR only, SSLR then RT for low confidence, or straight to RT.
GLINT_CONST uint kTileModeSslr = 0u;
GLINT_CONST uint kTileModeHybrid = 1u;
GLINT_CONST uint kTileModeRt = 2u;

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

GLINT_END

#endif
