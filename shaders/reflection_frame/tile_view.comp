#version 460
// Debug view of a u32-per-8x8-tile buffer (passes/reflection_frame.cpp):
// the feedback counters or the tile modes, one colour per tile, with a dark
// grid line so tiles stay distinguishable.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/feedback_shared.h"
#include "glint/reflection_frame_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, scalar) readonly buffer Tiles { uint tiles[]; };
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D outImage;

layout(push_constant, scalar) uniform Constants { TileViewConstants pc; };

void main() {
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y) {
        return;
    }
    const uint value = tiles[(pixel.y / kTileSize) * pc.tilesX + pixel.x / kTileSize];
    vec3 colour;
    if (pc.what == kTileViewModes) {
        // Blue SSLR, purple hybrid, red RT, dark red RT-only (the frame's
        // SSLR does not pay: passes/feedback.h).
        colour = value == kTileModeSslr     ? vec3(0.1, 0.3, 1.0)
                 : value == kTileModeHybrid ? vec3(0.7, 0.2, 0.9)
                 : value == kTileModeRt     ? vec3(1.0, 0.15, 0.1)
                                            : vec3(0.45, 0.05, 0.05);
    } else {
        // A tile holds at most 64 pixels per frame: two frames' hits (green)
        // and misses (red) on a 0..128 scale.
        const float hits = float(feedbackHits(value) + feedbackPreviousHits(value));
        const float misses = float(feedbackMisses(value) + feedbackPreviousMisses(value));
        colour = vec3(misses, hits, 0.0) / 128.0;
    }
    const bool grid = (pixel.x % kTileSize) == 0u || (pixel.y % kTileSize) == 0u;
    imageStore(outImage, ivec2(pixel), vec4(grid ? colour * 0.6 : colour, 1.0));
}
