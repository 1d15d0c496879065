#include "glint/scene/alpha_test.h"

#include "glint/texture_transform.h"

#include <glm/gtc/packing.hpp>
#include <stb_image_resize.h>

#include <algorithm>
#include <cmath>

namespace glint::scene {

namespace {

// The whole periods of `wrap` to take off a coordinate: repeats of 1,
// mirrored repeats of 2 (a mirrored period is two copies); none when
// clamped.
float period(Wrap wrap) {
    switch (wrap) {
        case Wrap::Repeat:
            return 1.0f;
        case Wrap::MirroredRepeat:
            return 2.0f;
        case Wrap::ClampToEdge:
            break;
    }
    return 0.0f;
}

float shifted(float u, float shift, Wrap wrap) {
    // Clamped: anything past [0, 1] reads the edge, so [-1, 2] is as good
    // as any larger range and keeps the halves precise.
    return wrap == Wrap::ClampToEdge ? std::clamp(u, -1.0f, 2.0f) : u - shift;
}

uint32_t wrapBits(Wrap wrap) {
    switch (wrap) {
        case Wrap::Repeat:
            return shader::kAlphaWrapRepeat;
        case Wrap::ClampToEdge:
            return shader::kAlphaWrapClamp;
        case Wrap::MirroredRepeat:
            return shader::kAlphaWrapMirror;
    }
    return shader::kAlphaWrapRepeat;
}

} // namespace

bool alphaTested(const Material& material) { return material.alphaMode == AlphaMode::Mask; }

std::vector<shader::AlphaTriangle> alphaTriangles(const Scene& scene, const Geometry& g) {
    const Material& m = scene.materials.at(g.material);
    const TextureRef& ref = m.baseColorTexture;
    const std::vector<glm::vec2>& uvs = ref.texCoord == 0 ? g.texcoords0 : g.texcoords1;
    const shader::UvTransform transform = ref.uvTransform();
    const glm::vec2 periods(period(ref.wrapS), period(ref.wrapT));
    std::vector<shader::AlphaTriangle> out(g.triangleCount());
    for (uint32_t t = 0; t < g.triangleCount(); ++t) {
        glm::vec2 uv[3];
        shader::AlphaTriangle& a = out[t];
        a.alpha = 0;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t v = g.indices[3 * t + k];
            uv[k] = shader::applyUvTransform(transform, v < uvs.size() ? uvs[v] : glm::vec2(0.0f));
            const float alpha = m.baseColorFactor.a * (v < g.colors.size() ? g.colors[v].a : 1.0f);
            a.alpha |= uint32_t(std::lround(std::clamp(alpha, 0.0f, 1.0f) * 255.0f)) << (8 * k);
        }
        // The same shift for the three vertices keeps the triangle whole.
        glm::vec2 shift(0.0f);
        for (int axis = 0; axis < 2; ++axis) {
            if (periods[axis] > 0.0f) shift[axis] = std::floor(uv[0][axis] / periods[axis]) * periods[axis];
        }
        for (uint32_t k = 0; k < 3; ++k) {
            a.uv[int(k)] = glm::packHalf2x16(
                glm::vec2(shifted(uv[k].x, shift.x, ref.wrapS), shifted(uv[k].y, shift.y, ref.wrapT)));
        }
    }
    return out;
}

std::vector<uint8_t> alphaMaskTexels(const Texture& texture, uint32_t size) {
    const size_t texels = size_t(texture.width) * texture.height;
    std::vector<uint8_t> alpha(texels);
    for (uint32_t y = 0; y < texture.height; ++y) {
        for (uint32_t x = 0; x < texture.width; ++x) {
            alpha[size_t(y) * texture.width + x] =
                uint8_t(std::lround(std::clamp(texture.texel(x, y).a, 0.0f, 1.0f) * 255.0f));
        }
    }
    if (texture.width == size && texture.height == size) {
        return alpha;
    }
    std::vector<uint8_t> out(size_t(size) * size);
    // Alpha is linear: no colour space, one channel, wrapping edges (most
    // cut-outs tile or sit inside their texture).
    stbir_resize_uint8_generic(alpha.data(), int(texture.width), int(texture.height), 0, out.data(), int(size),
                               int(size), 0, 1, STBIR_ALPHA_CHANNEL_NONE, 0, STBIR_EDGE_WRAP, STBIR_FILTER_DEFAULT,
                               STBIR_COLORSPACE_LINEAR, nullptr);
    return out;
}

uint32_t alphaMaskWord(const Material& material, uint32_t layer) {
    const TextureRef& ref = material.baseColorTexture;
    return (layer & shader::kAlphaLayerBits) | wrapBits(ref.wrapS) << shader::kAlphaWrapShiftU |
           wrapBits(ref.wrapT) << shader::kAlphaWrapShiftV;
}

} // namespace glint::scene
