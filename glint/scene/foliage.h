#pragma once
// Alpha-tested vegetation and fences for the built-in scenes (the plaza):
// what a tropical reflection mostly shows, and what tests the alpha test in
// raster, SSLR and both ray backends. Each cut-out is a texture whose alpha
// draws the shape (glTF alphaMode MASK, double-sided) on a few quads.
// Internal to glint/scene.

#include "glint/scene/scene.h"
#include "glint/scene/scene_builder.h"

#include <cstdint>

namespace glint::scene {

struct FoliageMaterials {
    uint32_t frond = 0;  // palm fronds: leaflets along a rib
    uint32_t grass = 0;  // tufts of blades
    uint32_t fence = 0;  // galvanised chain-link
};

// Generates the three textures (size x size texels) and their alpha-tested
// materials in `b`.
FoliageMaterials foliageMaterials(SceneBuilder& b, uint32_t size);

// A palm frond: a strip of `segments` quads from the origin along +x, `length`
// long and `width` wide (in z), drooping in an arc to `droop` below its
// start; u runs along the rib, v across it.
Geometry makeFrond(float length, float width, float droop, uint32_t segments, uint32_t material);

// A tuft of grass: three vertical quads `height` tall and `width` wide,
// crossed at 60 degrees around the origin.
Geometry makeGrassTuft(float height, float width, uint32_t material);

// A patch of `tufts` tufts scattered (deterministically from `seed`) in a
// ring of radii [inner, outer] around the origin.
Geometry makeGrassPatch(uint32_t tufts, float inner, float outer, uint32_t seed, uint32_t material);

// A fence panel from (0, 0, 0) along +x, `length` by `height`, its texture
// repeating once per metre.
Geometry makeFencePanel(float length, float height, uint32_t material);

} // namespace glint::scene
