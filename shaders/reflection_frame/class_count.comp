#version 460
// Counts the frame's pixel classes and traced rays for stats
// (passes/reflection_frame.cpp, glint/reflection_frame_shared.h): one
// workgroup per 8x8 tile reduces in shared memory, then one atomic per
// counter per tile.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "glint/reflection_frame_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, scalar) readonly buffer Classes { uint classes[]; };
layout(set = 0, binding = 1, scalar) readonly buffer Rays { PackedRay rays[]; };
layout(set = 0, binding = 2, scalar) readonly buffer RtArgs { uint rtArgs[]; };
layout(set = 0, binding = 3, scalar) buffer Counts { uint counts[]; };

layout(push_constant, scalar) uniform Constants { ClassCountConstants pc; };

shared uint sharedCounts[kReflectionCountWords];

void main() {
    const uint lane = gl_LocalInvocationIndex;
    if (lane < kReflectionCountWords) {
        sharedCounts[lane] = 0u;
    }
    barrier();
    const uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x < pc.size.x && pixel.y < pc.size.y) {
        const uint index = pixel.y * pc.size.x + pixel.x;
        const uint pixelClass = min(classes[index], kPixelClassCount - 1u);
        atomicAdd(sharedCounts[pixelClass], 1u);
        const PackedRay ray = rays[index];
        const bool leader = ray.pixelFlags != kNoRay && (ray.pixelFlags & kRayReused) == 0u;
        if (leader && (pixelClass == kPixelSslr || pixelClass == kPixelHybrid)) {
            atomicAdd(sharedCounts[kCountSslrRays], 1u);
        }
    }
    barrier();
    if (lane < kPixelClassCount + 1u && sharedCounts[lane] != 0u) {
        atomicAdd(counts[lane], sharedCounts[lane]);
    }
    if (lane == 0u && gl_WorkGroupID.xy == uvec2(0u) && pc.rtListCounted != 0u) {
        counts[kCountRtRays] = rtArgs[kRayListCountOffset];
    }
}
