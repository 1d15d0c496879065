#pragma once
// Per-frame scene update on the CPU: animation sampling (glTF 2.0 STEP,
// LINEAR with slerp for rotations, CUBICSPLINE), node world transforms,
// instance transforms with last frame's kept for motion vectors, and the
// joint matrices the GPU skinning pass consumes.

#include "glint/scene/scene.h"

#include <span>
#include <vector>

namespace glint::scene {

// Value of `sampler` at `seconds`, clamped to its first and last keys.
// Translation and scale come back in xyz; rotations as a unit quaternion in
// xyzw.
glm::vec4 sampleAnimation(const AnimationSampler& sampler, AnimationPath path, float seconds);

// Morph target weights of a Weights sampler at `seconds` into `out`
// (sampler.weightCount entries), clamped to the first and last keys.
void sampleMorphWeights(const AnimationSampler& sampler, float seconds, std::span<float> out);

// `base` with its morph targets applied (glTF 2.0 3.7.2.2): positions,
// normals and tangents plus the weighted sum of the targets' displacements,
// normals and tangents renormalised (the tangent keeps its sign). Weights
// past the geometry's targets are ignored; missing ones count as 0.
Geometry morphedGeometry(const Geometry& base, std::span<const float> weights);

// Writes the TRS (and morph weights) of every node `animation` targets,
// evaluated at `seconds`.
void applyAnimation(const Animation& animation, float seconds, std::span<Node> nodes);

// World transform of every node. Throws SceneError on a parent cycle.
std::vector<glm::mat4> worldTransforms(std::span<const Node> nodes);

// Object-space skinning matrices of an instance placed at `instanceWorld`:
// inverse(instanceWorld) * world[joint] * inverseBind, one per joint, so the
// instance transform stays the TLAS transform and skinned vertices stay in
// object space (glTF ignores the skinned node's own transform; multiplying
// back by instanceWorld gives exactly the glTF result).
void computeJointMatrices(const Skin& skin, std::span<const glm::mat4> world, const glm::mat4& instanceWorld,
                          std::span<glm::mat4> out);

// Once, after a scene is filled: validates it (validateScene), computes
// geometry and mesh bounds, lays out the joint palette, evaluates the scene
// at `seconds` and makes last frame equal to this one.
void prepareScene(Scene& scene, double seconds = 0.0);

// Every frame: keeps this frame's instance transforms and joint matrices as
// last frame's, places the camera node at `camera` (when both exist), plays
// the scene's animations at `seconds`, and bumps the deformVersion of every
// skinned instance whose joint matrices changed and of every instance whose
// morph weights changed.
void advanceScene(Scene& scene, double seconds, const Camera* camera = nullptr);

} // namespace glint::scene
