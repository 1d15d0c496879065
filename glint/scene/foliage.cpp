#include "glint/scene/foliage.h"

#include "glint/scene/mesh_tools.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace glint::scene {

namespace {

Texture blankTexture(const char* name, uint32_t size) {
    Texture t{name, size, size, TextureFormat::Rgba8, {}, {}};
    t.rgba8.assign(size_t(size) * size * 4, 0);
    return t;
}

void setTexel(Texture& t, uint32_t x, uint32_t y, glm::vec3 linear, bool opaque) {
    const size_t i = (size_t(y) * t.width + x) * 4;
    t.rgba8[i + 0] = toSrgbByte(linear.r);
    t.rgba8[i + 1] = toSrgbByte(linear.g);
    t.rgba8[i + 2] = toSrgbByte(linear.b);
    t.rgba8[i + 3] = opaque ? 255 : 0;
}

// A frond seen flat: u along the rib (0 at the trunk), v across it. The
// leaflets leave the rib at an angle, narrowing towards the tip; the gaps
// between them are what the alpha test cuts out.
Texture frondTexture(uint32_t size) {
    Texture t = blankTexture("palm_frond", size);
    constexpr float kLeaflets = 22.0f;
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            const float u = (float(x) + 0.5f) / float(size);
            const float v = (float(y) + 0.5f) / float(size);
            const float across = std::abs(v - 0.5f) * 2.0f;              // 0 at the rib, 1 at the edge
            const float reach = 0.95f * std::sin(glm::pi<float>() * std::min(u * 1.15f, 1.0f));  // leaflet length
            const bool rib = across < 0.05f && u < 0.97f;
            // Leaflets slant towards the tip: their phase advances with `across`.
            const float phase = u * kLeaflets - across * 1.6f;
            const bool leaflet = across < reach && phase - std::floor(phase) < 0.55f;
            const float shade = 0.75f + 0.25f * hash01(int32_t(phase), int32_t(v > 0.5f), 5u);
            setTexel(t, x, y, glm::vec3(0.07f, 0.28f, 0.05f) * shade * (rib ? 0.8f : 1.0f), rib || leaflet);
        }
    }
    return t;
}

// Blades of grass rising from the bottom edge (v = 1 at the root; glTF's v
// runs down the image), tapering to their tips at different heights.
Texture grassTexture(uint32_t size) {
    Texture t = blankTexture("grass_blades", size);
    constexpr int kBlades = 9;
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            const float u = (float(x) + 0.5f) / float(size);
            const float h = 1.0f - (float(y) + 0.5f) / float(size);  // 0 at the root, 1 at the top
            bool inside = false;
            float tint = 0.0f;
            for (int k = 0; k < kBlades && !inside; ++k) {
                const float root = (float(k) + 0.5f) / float(kBlades);
                const float tip = 0.55f + 0.45f * hash01(k, 0, 9u);
                const float lean = (hash01(k, 1, 9u) - 0.5f) * 0.25f;
                const float centre = root + lean * h * h;
                const float halfWidth = 0.035f * std::max(0.0f, 1.0f - h / tip);
                inside = h < tip && std::abs(u - centre) < halfWidth;
                tint = hash01(k, 2, 9u);
            }
            setTexel(t, x, y, glm::mix(glm::vec3(0.10f, 0.30f, 0.04f), glm::vec3(0.22f, 0.35f, 0.08f), tint) *
                                  (0.55f + 0.45f * h),
                     inside);
        }
    }
    return t;
}

// One cell of a chain-link fence: two diagonal wires crossing.
Texture fenceTexture(uint32_t size) {
    Texture t = blankTexture("chain_link", size);
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            const float u = (float(x) + 0.5f) / float(size);
            const float v = (float(y) + 0.5f) / float(size);
            // Distance to the diagonals u = v and u = 1 - v, wrapping.
            const auto wire = [](float d) { return std::min(d, 1.0f - d); };
            const float a = wire(std::abs(u - v)), b = wire(std::abs(u + v - 1.0f));
            setTexel(t, x, y, glm::vec3(0.55f, 0.56f, 0.58f), std::min(a, b) < 0.045f);
        }
    }
    return t;
}

uint32_t cutout(SceneBuilder& b, const char* name, Texture texture, glm::vec3 colour, float metallic,
                float roughness) {
    Material m = makeMaterial(name, colour, metallic, roughness);
    m.alphaMode = AlphaMode::Mask;
    m.alphaCutoff = 0.5f;
    m.doubleSided = true;
    m.baseColorTexture.texture = b.texture(std::move(texture));
    return b.material(std::move(m));
}

// A quad from `origin` spanned by `u` and `v` (counter-clockwise seen from
// u x v), texture coordinates (0, 1) at the origin to (uScale, 0).
void appendQuad(Geometry& g, glm::vec3 origin, glm::vec3 u, glm::vec3 v, float uScale) {
    const uint32_t base = uint32_t(g.positions.size());
    const glm::vec3 n = glm::normalize(glm::cross(u, v));
    const glm::vec3 corners[4] = {origin, origin + u, origin + u + v, origin + v};
    const glm::vec2 uvs[4] = {{0.0f, 1.0f}, {uScale, 1.0f}, {uScale, 0.0f}, {0.0f, 0.0f}};
    for (int k = 0; k < 4; ++k) {
        g.positions.push_back(corners[k]);
        g.normals.push_back(n);
        g.texcoords0.push_back(uvs[k]);
    }
    g.indices.insert(g.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

} // namespace

FoliageMaterials foliageMaterials(SceneBuilder& b, uint32_t size) {
    FoliageMaterials m;
    // White base colours: the textures carry the colour.
    m.frond = cutout(b, "palm frond", frondTexture(size), glm::vec3(1.0f), 0.0f, 0.6f);
    m.grass = cutout(b, "grass", grassTexture(size), glm::vec3(1.0f), 0.0f, 0.8f);
    m.fence = cutout(b, "chain-link fence", fenceTexture(size), glm::vec3(1.0f), 1.0f, 0.35f);
    return m;
}

Geometry makeFrond(float length, float width, float droop, uint32_t segments, uint32_t material) {
    Geometry g;
    g.material = material;
    segments = std::max(segments, 1u);
    for (uint32_t s = 0; s <= segments; ++s) {
        const float t = float(s) / float(segments);
        // The rib arcs down: height falls with the square of the distance.
        const glm::vec3 centre(length * t, -droop * t * t, 0.0f);
        const glm::vec3 tangent = glm::normalize(glm::vec3(length, -2.0f * droop * t, 0.0f));
        const glm::vec3 side(0.0f, 0.0f, 0.5f * width);
        const glm::vec3 n = glm::normalize(glm::cross(tangent, glm::vec3(0.0f, 0.0f, -1.0f)));
        for (const float sign : {-1.0f, 1.0f}) {
            g.positions.push_back(centre + sign * side);
            g.normals.push_back(n);
            g.texcoords0.push_back({t, sign < 0.0f ? 0.0f : 1.0f});
        }
    }
    for (uint32_t s = 0; s < segments; ++s) {
        const uint32_t a = 2 * s;
        // Counter-clockwise seen from above (the normal's side).
        g.indices.insert(g.indices.end(), {a, a + 1, a + 3, a, a + 3, a + 2});
    }
    return g;
}

Geometry makeGrassTuft(float height, float width, uint32_t material) {
    Geometry g;
    g.material = material;
    for (int k = 0; k < 3; ++k) {
        const float a = glm::pi<float>() * float(k) / 3.0f;
        const glm::vec3 across(std::cos(a) * width, 0.0f, std::sin(a) * width);
        appendQuad(g, -0.5f * across, across, glm::vec3(0.0f, height, 0.0f), 1.0f);
    }
    return g;
}

Geometry makeGrassPatch(uint32_t tufts, float inner, float outer, uint32_t seed, uint32_t material) {
    Geometry patch;
    patch.material = material;
    for (uint32_t k = 0; k < tufts; ++k) {
        const float angle = glm::two_pi<float>() * (float(k) + hash01(int32_t(k), 0, seed)) / float(tufts);
        const float radius = inner + (outer - inner) * hash01(int32_t(k), 1, seed);
        const float height = 0.35f + 0.3f * hash01(int32_t(k), 2, seed);
        const glm::mat4 place = glm::rotate(translation({radius * std::cos(angle), 0.0f, radius * std::sin(angle)}),
                                            glm::two_pi<float>() * hash01(int32_t(k), 3, seed), {0, 1, 0});
        appendGeometry(patch, transformed(makeGrassTuft(height, 0.6f * height, material), place));
    }
    return patch;
}

Geometry makeFencePanel(float length, float height, uint32_t material) {
    Geometry g;
    g.material = material;
    appendQuad(g, glm::vec3(0.0f), glm::vec3(length, 0.0f, 0.0f), glm::vec3(0.0f, height, 0.0f), length);
    // One texture period per metre upwards too: v from `height` at the foot to 0.
    for (glm::vec2& uv : g.texcoords0) uv.y *= height;
    return g;
}

} // namespace glint::scene
