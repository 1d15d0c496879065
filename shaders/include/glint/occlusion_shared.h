// Occlusion culling of the G-buffer (passes/gbuffer_occlusion.cpp,
// shaders/gbuffer/hiz.comp and occlusion_cull.comp): constants, buffers and
// push constants shared by GLSL and C++. Buffers use scalar layout.
//
// Two phases a frame, so nothing visible is ever missing (the two-pass
// scheme of Haar and Aaltonen, "GPU-Driven Rendering Pipelines",
// SIGGRAPH 2015):
//   1. early: the draws of the instances that were visible last frame (the
//      visibility history) are drawn into the G-buffer;
//   2. a depth pyramid (Hi-Z) of what they left is built; every instance in
//      the frustum is tested against it, the result becomes next frame's
//      history, and the visible instances not drawn early are drawn late,
//      over the early ones.
// The G-buffer's draws are sorted into runs that bind the same (passes/
// gbuffer_internal.h, SurfaceDraw). Each run takes whole chunks of
// kOcclusionGroupSize command slots; a cull workgroup handles one chunk: it
// writes the chunk's drawn commands to its first slots, in order, and their
// count after all the slots. The raster passes draw each chunk with one
// vkCmdDrawIndexedIndirectCount, so a draw the cull rejects issues no command.
//
// The Hi-Z is a min-depth pyramid (reversed Z: the farthest depth of each
// footprint). Its level 0 is bit_ceil(screen) / 2 texels a side, so every
// level halves exactly: texel t of level k covers the screen pixels
// [t 2^(k+1), (t + 1) 2^(k+1)). Pixels beyond the screen count as the
// nearest depth (1), which leaves the minimum of the pixels on screen.
#ifndef GLINT_OCCLUSION_SHARED_H
#define GLINT_OCCLUSION_SHARED_H

#include "glint/packing.h"
#include "glint/shared.h"

GLINT_BEGIN

// Command slots per chunk, and the cull's workgroup size.
GLINT_CONST uint kOcclusionGroupSize = 256u;

// hiz.comp: a 16 x 16 workgroup per 32 x 32 texels of its source reduces
// each 2 x 2 (the minimum) and then four more levels in shared memory.
GLINT_CONST uint kHizGroupTexels = 32u;
GLINT_CONST uint kHizLevelsPerPass = 5u;
// Two passes: level 9's texels are 1,024 pixels wide. A box wider than
// that on screen is taken as visible.
GLINT_CONST uint kHizMaxMips = 10u;

// One scene instance: its world bounds, grown by a margin (passes/
// gbuffer_occlusion.cpp says why). boundsMin.w is 1 where the instance is
// in the view frustum and has draws this frame, else 0.
struct OcclusionInstance {
    vec4 boundsMin;
    vec4 boundsMax;
};

// One command slot of the G-buffer's draws (the same index range in both
// phases): the cull pass writes its VkDrawIndexedIndirectCommand where the
// draw is drawn. indexCount 0: a slot that pads its run to whole chunks.
struct OcclusionDraw {
    uint instance;
    uint indexCount;
    uint firstIndex;
    int vertexOffset;
};

// Push constants of occlusion_early.comp and occlusion_late.comp (88
// bytes; the early phase reads only the counts).
struct OcclusionConstants {
    mat4 viewProjection;  // the jittered one the G-buffer draws with
    uvec2 screenSize;
    uint hizMips;
    uint drawCount;      // command slots, a multiple of kOcclusionGroupSize
    uint instanceCount;
    uint countsAt;       // the args buffer's word where the chunks' counts begin
};

// Push constants of hiz_base.comp and hiz_down.comp (56 bytes).
struct HizConstants {
    // Texels of the source (the depth, or level 4) that the screen
    // reaches; the rest read as 1.
    uvec2 sourceValid;
    uvec2 outputSize[5];
    uint outputs;       // levels written (the rest of the bindings are stand-ins)
    uint pad;
};

// The cull pass's counts of this frame (u32 words; the early phase zeroes
// them, the late phase adds).
GLINT_CONST uint kOcclusionStatEarly = 0u;     // instances drawn early (visible last frame)
GLINT_CONST uint kOcclusionStatLate = 1u;      // instances drawn late (newly visible)
GLINT_CONST uint kOcclusionStatOccluded = 2u;  // in the frustum, drawn in neither phase
GLINT_CONST uint kOcclusionStatTriangles = 3u; // triangles drawn in both phases
GLINT_CONST uint kOcclusionStatWords = 4u;

// Level 0 of the Hi-Z for a screen of `size` pixels: half its power-of-two
// ceiling per axis.
GLINT_FUNC uvec2 hizBaseSize(uvec2 size) {
    uvec2 p = uvec2(1u, 1u);
    while (p.x < size.x) p.x *= 2u;
    while (p.y < size.y) p.y *= 2u;
    return uvec2(p.x > 1u ? p.x / 2u : 1u, p.y > 1u ? p.y / 2u : 1u);
}

GLINT_FUNC uvec2 hizLevelSize(uvec2 base, uint level) {
    return uvec2(base.x >> level > 0u ? base.x >> level : 1u, base.y >> level > 0u ? base.y >> level : 1u);
}

// The texels of level `level` that screen pixels [0, size) reach: the
// rest of the level lies beyond the screen.
GLINT_FUNC uvec2 hizValidSize(uvec2 size, uint level) {
    const uint shift = level + 1u;
    return uvec2((size.x + (1u << shift) - 1u) >> shift, (size.y + (1u << shift) - 1u) >> shift);
}

// The finest level at which the pixel rectangle [lo, hi] (inclusive) spans
// at most 2 x 2 texels; `mips` when none does.
GLINT_FUNC uint hizTestLevel(uvec2 lo, uvec2 hi, uint mips) {
    for (uint level = 0u; level < mips; ++level) {
        const uint shift = level + 1u;
        if ((hi.x >> shift) - (lo.x >> shift) <= 1u && (hi.y >> shift) - (lo.y >> shift) <= 1u) return level;
    }
    return mips;
}

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::OcclusionInstance) == 32);
static_assert(sizeof(glint::shader::OcclusionDraw) == 16);
static_assert(sizeof(glint::shader::OcclusionConstants) == 88);
static_assert(sizeof(glint::shader::HizConstants) == 56);
#endif

#endif
