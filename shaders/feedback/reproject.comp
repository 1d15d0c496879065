#version 460
// Feedback (passes/feedback.h): one invocation per 8x8 tile. Carries last
// frame's feedback counter to where the tile's content was last frame,
// following the motion of one pseudo-random pixel of the tile (the Far Cry
// 6 talk's "random motion vector of the tile"; a new pixel every frame), and
// decides the tile's mode (SSLR, hybrid, RT) from the two frames of counts
// the carried counter holds (glint/feedback_shared.h), unless last frame's
// SSLR hits, summed over the frame, say that SSLR does not pay: then every
// tile goes to RT with no pixel kept hybrid (kTileModeRtOnly), except on
// probe frames. Starts this frame's sum for integrate to add to, and hands
// last frame's sum to the host's report (a storage write: a copy command
// between the dispatches cost the pass about 5 us).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/feedback_shared.h"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0) uniform sampler2D motionTexture;
layout(set = 0, binding = 1, scalar) readonly buffer Previous { uint previous[]; };
layout(set = 0, binding = 2, scalar) writeonly buffer Reprojected { uint reprojected[]; };
layout(set = 0, binding = 3, scalar) writeonly buffer TileModes { uint tileModes[]; };
// This frame's counters (integrate writes the tiles): only the total word
// after the tiles is written here.
layout(set = 0, binding = 4, scalar) writeonly buffer Current { uint current[]; };
// The host's report of last frame's hits (pc.report; bound to something
// else when there is none, and then not written).
layout(set = 0, binding = 5, scalar) writeonly buffer Report { uint report[]; };

layout(push_constant, scalar) uniform Constants { FeedbackConstants pc; };

// By the bits: implementations may fold isnan/isinf away (integrate.glsl).
bool isFinite(vec2 v) {
    return (floatBitsToUint(v.x) & 0x7F800000u) != 0x7F800000u && (floatBitsToUint(v.y) & 0x7F800000u) != 0x7F800000u;
}

void main() {
    const uint tileIndex = gl_GlobalInvocationID.x;
    const uint tiles = pc.tiles.x * pc.tiles.y;
    if (tileIndex == 0u && pc.report != kFeedbackReportNone) {
        report[0] = tiles < uint(previous.length()) ? previous[tiles] : 0u;
    }
    if (pc.report == kFeedbackReportOnly) {
        return;
    }
    if (tileIndex == 0u && tiles < uint(current.length())) {
        current[tiles] = kFeedbackFrameHitsStart;
    }
    if (tileIndex >= tiles) {
        return;
    }
    // The frame's gate: one word every invocation reads (length(): the
    // buffers are bound whole).
    const uint lastFrameWord = tiles < uint(previous.length()) ? previous[tiles] : 0u;
    const bool pays = sslrPays(lastFrameWord, pc.minFrameHits, feedbackProbeFrame(pc.frame, pc.probeInterval),
                               pc.resetHistory != 0u);
    const uvec2 tile = uvec2(tileIndex % pc.tiles.x, tileIndex / pc.tiles.x);
    const uvec2 probe = feedbackProbePixel(tile, pc.frame, pc.size);
    // glint/gbuffer_shared.h: history lookup = pixel + motion.
    const vec2 motion = texelFetch(motionTexture, ivec2(probe), 0).xy;
    const vec2 last = vec2(probe) + 0.5 + motion;
    uint counter = 0u;
    // Content that came from off screen has no history, nor has anything
    // after a reset: no evidence.
    if (pc.resetHistory == 0u && isFinite(motion) && all(greaterThanEqual(last, vec2(0.0))) &&
        all(lessThan(last, vec2(pc.size)))) {
        const uvec2 lastTile = uvec2(last) / kTileSize;
        const uint lastIndex = lastTile.y * pc.tiles.x + lastTile.x;
        // length(): the buffers are bound whole.
        counter = lastIndex < uint(previous.length()) ? previous[lastIndex] : 0u;
    }
    reprojected[tileIndex] = counter;
    tileModes[tileIndex] = pc.adaptive == 0u ? kTileModeHybrid
                           : !pays          ? kTileModeRtOnly
                                            : decideTileMode(counter, pc.minRays, pc.sslrMissFraction, pc.rtHitFraction);
}
