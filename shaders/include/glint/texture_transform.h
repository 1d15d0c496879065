// KHR_texture_transform as one affine map of texture coordinates, shared by
// the G-buffer's fragment shader (normal maps, per pixel) and the CPU
// sampling at vertices (scene::surfaceAtVertex, which fills the G-buffer's
// vertex colours and the BVH's packed primitives), so both apply the same
// maths. The extension defines uv' = T * R * S * uv with
//
//   T = | 1 0 offset.x |   R = |  cos r  sin r  0 |   S = | scale.x 0       0 |
//       | 0 1 offset.y |       | -sin r  cos r  0 |       | 0       scale.y 0 |
//       | 0 0 1        |       |  0      0      1 |       | 0       0       1 |
//
// (KHR_texture_transform README, "Transformation"). The map is affine, so
// it commutes with barycentric interpolation: transforming at vertices or
// per pixel gives the same coordinates.
#ifndef GLINT_TEXTURE_TRANSFORM_H
#define GLINT_TEXTURE_TRANSFORM_H

#include "glint/shared.h"

#ifdef __cplusplus
#include <cmath>
namespace glint::shader {
using std::cos;
using std::sin;
} // namespace glint::shader
#ifndef GLINT_FUNC
#define GLINT_FUNC inline
#endif
#else
#ifndef GLINT_FUNC
#define GLINT_FUNC
#endif
#endif

GLINT_BEGIN

// uv' = column0 * uv.x + column1 * uv.y + offset (24 bytes, scalar layout).
struct UvTransform {
    vec2 column0;
    vec2 column1;
    vec2 offset;
};

GLINT_FUNC UvTransform makeUvTransform(vec2 offset, float rotation, vec2 scale) {
    const float c = cos(rotation);
    const float s = sin(rotation);
    UvTransform t;
    // Columns of R * S.
    t.column0 = vec2(c * scale.x, -s * scale.x);
    t.column1 = vec2(s * scale.y, c * scale.y);
    t.offset = offset;
    return t;
}

GLINT_FUNC UvTransform identityUvTransform() {
    return makeUvTransform(vec2(0.0f, 0.0f), 0.0f, vec2(1.0f, 1.0f));
}

GLINT_FUNC vec2 applyUvTransform(UvTransform t, vec2 uv) {
    return t.column0 * uv.x + t.column1 * uv.y + t.offset;
}

GLINT_END

#ifdef __cplusplus
static_assert(sizeof(glint::shader::UvTransform) == 24);
#endif

#endif
