// Composite and debug views (passes/composite.cpp, shaders/composite/*):
// push constants and enumerations shared by GLSL and C++.
//
// Output: RGBA8_UNORM storage images whose bytes are sRGB-encoded
// (IEC 61966-2-1, glint/packing.h's linearToSrgb), alpha 255, ready to be
// written to a PNG as they are.
#ifndef GLINT_COMPOSITE_SHARED_H
#define GLINT_COMPOSITE_SHARED_H

#include "glint/shared.h"

GLINT_BEGIN

GLINT_CONST uint kCompositeGroupSize = 8u;

// Tonemap operators (passes/composite.h's Tonemap documents each).
GLINT_CONST uint kTonemapKhronosPbrNeutral = 0u;
GLINT_CONST uint kTonemapAcesFitted = 1u;
GLINT_CONST uint kTonemapClamp = 2u;

// Debug view kinds (passes/composite.h's DebugViewKind).
GLINT_CONST uint kDebugViewColor = 0u;
GLINT_CONST uint kDebugViewScalar = 1u;
GLINT_CONST uint kDebugViewRaw = 2u;

// Push constants of composite.comp (112 bytes).
struct CompositeConstants {
    mat4 inverseViewProjection;  // unjittered
    vec4 cameraPosition;
    uvec2 size;
    float exposure;
    uint tonemap;
    uint hasReflections;   // 0: the lit colour alone
    uint hasTransparency;  // 0: no transparent layer
    uint pad1;
    uint pad2;
};

// Push constants of debug_view*.comp (32 bytes).
struct DebugViewConstants {
    uvec2 size;
    uint kind;
    uint tonemap;
    float minValue;
    float maxValue;
    float exposure;
    uint sourceShift;  // output pixel p shows source texel p >> sourceShift (1: a half-size source)
};

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::CompositeConstants) == 112);
static_assert(sizeof(glint::shader::DebugViewConstants) == 32);
#endif

#endif
