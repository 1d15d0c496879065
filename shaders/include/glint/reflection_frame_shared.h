// The frame module's own small passes (passes/reflection_frame.cpp,
// shaders/reflection_frame/*): constants shared by GLSL and C++.
//
// Counts (kReflectionCountWords uints):
//   [kPixel*]                     pixels of each class (glint/ray_generation_shared.h)
//   [kCountSslrRays]              SSLR rays traced: ray leaders of SSLR and hybrid pixels
//   [kCountRtRays]                RT rays traced: copied from the RT list's length
#ifndef GLINT_REFLECTION_FRAME_SHARED_H
#define GLINT_REFLECTION_FRAME_SHARED_H

#include "glint/ray_generation_shared.h"

GLINT_BEGIN

GLINT_CONST uint kCountSslrRays = kPixelClassCount;
GLINT_CONST uint kCountRtRays = kPixelClassCount + 1u;
GLINT_CONST uint kReflectionCountWords = kPixelClassCount + 2u;

// What tile_view.comp shows of a u32-per-tile buffer.
GLINT_CONST uint kTileViewCounters = 0u;  // feedback counters: hits green, misses red (this frame + last)
GLINT_CONST uint kTileViewModes = 1u;     // tile modes: SSLR blue, hybrid purple, RT red

struct TileViewConstants {
    uvec2 size;
    uint tilesX;
    uint what;
};

struct ClassCountConstants {
    uvec2 size;
    uint rtListCounted;  // 1: copy the RT list's length into kCountRtRays
    uint pad;
};

GLINT_END

#endif
