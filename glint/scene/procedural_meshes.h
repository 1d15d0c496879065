#pragma once
// Procedural geometry for the built-in scenes. Every maker returns an
// indexed triangle list with normals, tangents and texcoords0, in metres,
// counter-clockwise front faces (glTF's convention).

#include "glint/scene/scene.h"

namespace glint::scene {

// Box of `size`, centred on the origin; UVs in metres times `uvPerMetre`.
Geometry makeBox(const glm::vec3& size, uint32_t material, float uvPerMetre = 1.0f);

// The same box with each face divided into `divisions` x `divisions`
// quads: finely tessellated flat walls, as the city's buildings have.
Geometry makeDividedBox(const glm::vec3& size, uint32_t divisions, uint32_t material, float uvPerMetre = 1.0f);

// Grid in the XZ plane facing +Y, centred on the origin, `cells` quads.
// `height` (optional) displaces each vertex along Y from its (x, z).
Geometry makeGrid(const glm::vec2& size, const glm::uvec2& cells, uint32_t material, float uvPerMetre = 1.0f,
                  float (*height)(float x, float z) = nullptr);

Geometry makeSphere(float radius, uint32_t segments, uint32_t rings, uint32_t material);

// Along +Y from y = 0 to `height`.
Geometry makeCylinder(float radius, float height, uint32_t segments, uint32_t material, bool caps = true);
Geometry makeCone(float radius, float height, uint32_t segments, uint32_t material);

// In the XZ plane around +Y.
Geometry makeTorus(float majorRadius, float minorRadius, uint32_t segments, uint32_t sides, uint32_t material);

// Sector of an annulus in the XZ plane between two radii and two angles
// (radians from +X towards +Z), facing +Y, heights from `height`.
Geometry makeRingSector(float innerRadius, float outerRadius, float angle0, float angle1, uint32_t segments,
                        uint32_t rings, uint32_t material, float (*height)(float x, float z) = nullptr);

// A tube along +Y from 0 to `height`, skinned to `bones` joints at
// y = k * height / bones, each vertex blended between its two nearest joints.
Geometry makeSkinnedTube(float radius, float height, uint32_t segments, uint32_t rings, uint32_t bones,
                         uint32_t material);

// A sheet in the XY plane from x = 0 to size.x, y = 0 to size.y, facing +Z,
// skinned along X to `bones` joints at x = k * size.x / bones (a flag).
Geometry makeSkinnedSheet(const glm::vec2& size, const glm::uvec2& cells, uint32_t bones, uint32_t material);

// Gives a rigid (unskinned) geometry joint 0 with weight 1, so it can join
// a skinned mesh and follow that joint.
void bindToJoint(Geometry& geometry, uint16_t joint);

} // namespace glint::scene
