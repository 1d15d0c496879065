#version 460
// The particles in the direct view (passes/particles.h): premultiplied
// colour and coverage, blended over the lit colour (ONE, ONE_MINUS_SRC_ALPHA)
// with glint/particles_shared.h's coverage, the trace's.
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "glint/particles_shared.h"

layout(location = 0) in vec2 quadPosition;
layout(location = 1) flat in vec4 color;
layout(location = 0) out vec4 outColor;

void main() {
    const float a = particleCoverage(color.a, dot(quadPosition, quadPosition));
    if (a <= 0.0) {
        discard;
    }
    outColor = vec4(max(color.rgb, vec3(0.0)) * a, a);
}
