#include "glint/scene/camera.h"
#include "glint/scene/frustum.h"

#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

using namespace glint::scene;

namespace {

Aabb boxAt(glm::vec3 centre, float half = 0.5f) {
    Aabb b;
    b.extend(centre - glm::vec3(half));
    b.extend(centre + glm::vec3(half));
    return b;
}

} // namespace

TEST_CASE("a reversed-Z infinite perspective keeps what is in front and inside the sides, however far") {
    // 90 degrees, square: at distance d the view spans [-d, d] in x and y.
    const glm::mat4 projection = perspectiveReversedZ(glm::radians(90.0f), 1.0f, 0.1f, kInfiniteFar);
    const glm::mat4 view = glm::lookAt(glm::vec3(0.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0));
    const Frustum f(projection * view);
    CHECK(f.intersects(boxAt({0, 0, -5})));
    CHECK(f.intersects(boxAt({0, 0, -1e6f}, 10.0f)));  // no far plane
    CHECK_FALSE(f.intersects(boxAt({0, 0, 5})));        // behind
    CHECK_FALSE(f.intersects(boxAt({0, 0, -0.01f}, 0.005f)));  // before the near plane
    CHECK_FALSE(f.intersects(boxAt({8, 0, -5})));       // right of the 45-degree side
    CHECK(f.intersects(boxAt({5.4f, 0, -5})));          // its corner crosses the side
    CHECK_FALSE(f.intersects(boxAt({0, -8, -5})));
    CHECK_FALSE(f.intersects(Aabb{}));                  // an empty box is nowhere
    CHECK(f.intersects(glm::vec3(6.0f, 0.0f, -5.0f), 1.0f));  // a sphere reaching over the side
    CHECK_FALSE(f.intersects(glm::vec3(6.0f, 0.0f, -5.0f), 0.5f));
}

TEST_CASE("an orthographic clip space culls by its box") {
    // x, y in [-10, 10], depth 0..1 over z in [-20, 0] (reversed: 1 nearest).
    glm::mat4 m(1.0f);
    m[0][0] = 0.1f;
    m[1][1] = 0.1f;
    m[2][2] = 1.0f / 20.0f;
    m[3][2] = 1.0f;
    const Frustum f(m);
    CHECK(f.intersects(boxAt({0, 0, -10})));
    CHECK(f.intersects(boxAt({9.9f, 0, -10})));
    CHECK_FALSE(f.intersects(boxAt({11, 0, -10})));
    CHECK_FALSE(f.intersects(boxAt({0, 0, -25})));
    CHECK_FALSE(f.intersects(boxAt({0, 0, 5})));
}
