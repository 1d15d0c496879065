#version 460
// The shadow map writes depth only: the pipeline needs a fragment stage,
// and the rasterised depth is all it keeps.
void main() {}
