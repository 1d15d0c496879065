// The occlusion cull of the G-buffer's draws (glint/occlusion_shared.h,
// passes/gbuffer_occlusion.cpp), the body of occlusion_early.comp and
// occlusion_late.comp. One invocation per command slot decides whether its
// draw is drawn; its workgroup (one chunk) writes the drawn commands to the
// chunk's first slots, in slot order, and their count. The late phase also
// runs one invocation per scene instance, which writes next frame's
// visibility and the counts.
//
// GLINT_OCCLUSION_LATE: 0, the early phase: a draw is drawn where its
// instance was visible last frame (the history), and invocation 0 zeroes
// the counts. 1, the late phase: an instance is visible where its bounds
// reach in front of the farthest depth the Hi-Z holds over their screen
// rectangle; a draw is drawn where it is visible now and was not drawn
// early.
#extension GL_EXT_scalar_block_layout : require

#include "glint/occlusion_shared.h"

layout(local_size_x = kOcclusionGroupSize) in;

layout(set = 0, binding = 0, scalar) readonly buffer Draws { OcclusionDraw draws[]; };
layout(set = 0, binding = 1, scalar) readonly buffer Previous { uint previous[]; };
// VkDrawIndexedIndirectCommand per slot (indexCount, instanceCount,
// firstIndex, vertexOffset, firstInstance), then a count per chunk.
layout(set = 0, binding = 2, scalar) writeonly buffer Args { uint args[]; };
layout(set = 0, binding = 3, scalar) buffer Stats { uint stats[]; };
#if GLINT_OCCLUSION_LATE
layout(set = 0, binding = 4, scalar) readonly buffer Instances { OcclusionInstance instances[]; };
layout(set = 0, binding = 5, scalar) writeonly buffer Current { uint current[]; };
layout(set = 0, binding = 6) uniform sampler2D hiz;
#endif

layout(push_constant, scalar) uniform Constants { OcclusionConstants pc; };

// A new history pair is zeroed; its length still bounds the index.
bool drawnEarly(uint instance) {
    return instance < uint(previous.length()) && previous[instance] != 0u;
}

shared uint scan[kOcclusionGroupSize];

// Compacts the chunk: every invocation of the workgroup calls this (it
// holds barriers), `drawn` or not. The drawn commands go to the chunk's
// first slots in slot order (an inclusive scan of the flags), so the
// G-buffer draws them in the order the CPU sorted them.
void writeChunk(OcclusionDraw d, bool drawn) {
    const uint l = gl_LocalInvocationID.x;
    scan[l] = drawn ? 1u : 0u;
    barrier();
    for (uint offset = 1u; offset < kOcclusionGroupSize; offset <<= 1u) {
        const uint add = l >= offset ? scan[l - offset] : 0u;
        barrier();
        scan[l] += add;
        barrier();
    }
    const uint chunk = gl_WorkGroupID.x;
    if (drawn) {
        const uint at = (chunk * kOcclusionGroupSize + scan[l] - 1u) * 5u;
        args[at + 0u] = d.indexCount;
        args[at + 1u] = 1u;
        args[at + 2u] = d.firstIndex;
        args[at + 3u] = uint(d.vertexOffset);
        args[at + 4u] = d.instance;  // firstInstance: gbuffer.vert's instance
    }
    if (l == kOcclusionGroupSize - 1u) args[pc.countsAt + chunk] = scan[l];
}

#if GLINT_OCCLUSION_LATE
// Whether anything of the box may cover a pixel in front of what the early
// phase drew there. Conservative: a box that reaches behind the camera's
// plane or past the near plane, is wider than the Hi-Z's coarsest texels,
// or has non-finite bounds is visible.
bool visible(OcclusionInstance inst) {
    if (inst.boundsMin.w == 0.0) return false;  // outside the frustum: no draws
    vec2 lo = vec2(3.0e38), hi = vec2(-3.0e38);
    float nearest = 0.0;
    for (uint c = 0u; c < 8u; ++c) {
        const vec3 p = vec3((c & 1u) != 0u ? inst.boundsMax.x : inst.boundsMin.x,
                            (c & 2u) != 0u ? inst.boundsMax.y : inst.boundsMin.y,
                            (c & 4u) != 0u ? inst.boundsMax.z : inst.boundsMin.z);
        const vec4 clip = pc.viewProjection * vec4(p, 1.0);
        if (!(clip.w > 0.0)) return true;
        const vec3 ndc = clip.xyz / clip.w;
        lo = min(lo, ndc.xy);
        hi = max(hi, ndc.xy);
        nearest = max(nearest, ndc.z);
    }
    if (!(nearest < 1.0)) return true;  // reaches the near plane (reversed Z), or NaN
    const vec2 size = vec2(pc.screenSize);
    const vec2 pixelLo = (lo * 0.5 + 0.5) * size;
    const vec2 pixelHi = (hi * 0.5 + 0.5) * size;
    // Wholly beside the screen (a pixel of margin): it covers no pixel centre.
    if (pixelHi.x < -1.0 || pixelHi.y < -1.0 || pixelLo.x > size.x + 1.0 || pixelLo.y > size.y + 1.0) return false;
    // The pixels whose centres the rectangle holds, and half a pixel more
    // on each side: the rasterizer snaps vertices to its own sub-pixel
    // grid, and a pixel the test did not look at could show the box.
    const uvec2 first = uvec2(clamp(floor(pixelLo - 0.5), vec2(0.0), size - 1.0));
    const uvec2 last = uvec2(clamp(floor(pixelHi + 0.5), vec2(0.0), size - 1.0));
    const uint level = hizTestLevel(first, last, pc.hizMips);
    if (level >= pc.hizMips) return true;
    const uint shift = level + 1u;
    const ivec2 a = ivec2(first >> shift), b = ivec2(last >> shift);
    const int l = int(level);
    const float farthest = min(min(texelFetch(hiz, a, l).r, texelFetch(hiz, ivec2(b.x, a.y), l).r),
                               min(texelFetch(hiz, ivec2(a.x, b.y), l).r, texelFetch(hiz, b, l).r));
    return !(nearest < farthest);
}
#endif

void main() {
    const uint t = gl_GlobalInvocationID.x;
#if !GLINT_OCCLUSION_LATE
    if (t == 0u) {
        for (uint w = 0u; w < kOcclusionStatWords; ++w) stats[w] = 0u;
    }
    // The dispatch covers the slots (whole chunks).
    OcclusionDraw d = OcclusionDraw(0u, 0u, 0u, 0);
    if (t < pc.drawCount) d = draws[t];
    writeChunk(d, d.indexCount != 0u && drawnEarly(d.instance));
#else
    // Slots come in whole chunks: a workgroup holds slots or instances.
    if (t < pc.drawCount) {
        const OcclusionDraw d = draws[t];
        const bool early = d.indexCount != 0u && drawnEarly(d.instance);
        const bool now = d.indexCount != 0u && d.instance < pc.instanceCount && visible(instances[d.instance]);
        writeChunk(d, now && !early);
        if (now || early) atomicAdd(stats[kOcclusionStatTriangles], d.indexCount / 3u);
        return;
    }
    const uint i = t - pc.drawCount;
    if (i >= pc.instanceCount) return;
    const OcclusionInstance inst = instances[i];
    const bool now = visible(inst);
    current[i] = now ? 1u : 0u;
    if (inst.boundsMin.w != 0.0) {
        const bool early = drawnEarly(i);
        atomicAdd(stats[early ? kOcclusionStatEarly : (now ? kOcclusionStatLate : kOcclusionStatOccluded)], 1u);
    }
#endif
}
