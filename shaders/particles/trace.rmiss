#version 460
// Empty on purpose (passes/particles.h): the payload's list already holds
// every hit when the ray leaves the particle TLAS.
#extension GL_EXT_ray_tracing : require

void main() {
}
