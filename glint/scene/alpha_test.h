#pragma once
// Alpha-tested geometry in the ray tracer, the CPU side: the per-triangle
// texture coordinates and vertex alpha (shader::AlphaTriangle) and the
// alpha mask layers that the any-hit test reads (glint/alpha_test.h says
// why the packed primitives cannot carry them). passes::BvhManager uploads
// what these return once, at start-up.

#include "glint/scene/scene.h"

#include "glint/alpha_test.h"

#include <cstdint>
#include <vector>

namespace glint::scene {

// Materials whose geometry the ray tracer alpha-tests (glTF alphaMode
// MASK); every other geometry is opaque to rays.
bool alphaTested(const Material& material);

// One AlphaTriangle per triangle of `geometry` (whose material is
// alpha-tested): the coordinates of the base colour texture's set through
// its KHR_texture_transform, moved per triangle by whole periods of the
// texture's wrap modes towards 0 (clamped ones clamped to [-1, 2]), so
// that half floats hold them to 1/1024 of a period or better wherever the
// triangle lies in texture space; and baseColorFactor.a x COLOR_0.a at
// each vertex.
std::vector<shader::AlphaTriangle> alphaTriangles(const Scene& scene, const Geometry& geometry);

// The alpha channel of `texture` resampled to size x size (stb's resize,
// a Mitchell filter when shrinking), row-major R8: one layer of the
// ray tracer's alpha mask array.
std::vector<uint8_t> alphaMaskTexels(const Texture& texture, uint32_t size);

// The alphaMask word of a material's row (glint/alpha_test.h): `layer`
// (kAlphaNoMask without a base colour texture) and the texture's wrap modes.
uint32_t alphaMaskWord(const Material& material, uint32_t layer);

} // namespace glint::scene
