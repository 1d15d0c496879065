#version 460
// Empty on purpose (passes/rt_trace.h): the ray generation shader starts
// every payload as a miss, so a miss has nothing to add.
#extension GL_EXT_ray_tracing : require

void main() {
}
