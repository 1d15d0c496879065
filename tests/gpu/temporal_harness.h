// What glint_temporal_gpu_tests' temporal and composite cases share
// (temporal_rig.h, composite_test.cpp): kSize x kSize textures uploaded
// into and read back from the graph through host buffers that outlive the
// frames using them (Staging), and the scenes: materials, one instance per
// geometry, a wall filling the image.
#pragma once

#include "support/pass_test_scene.h"

#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/scene/animation.h"

#include <glm/gtc/packing.hpp>

#include <cstring>
#include <deque>
#include <string>
#include <vector>

namespace glint::temporal_test {

inline constexpr uint32_t kSize = test::kPassTestSize;
inline constexpr size_t kPixels = size_t(kSize) * kSize;
using test::square;
using test::testCamera;

inline constexpr rg::BoundaryState kHostWrite =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

inline size_t at(uint32_t x, uint32_t y) { return size_t(y) * kSize + x; }

// Host buffers that outlive the frames using them (one per use: frames in
// flight never share one).
class Staging {
public:
    explicit Staging(gpu::Context& ctx) : ctx_(ctx) {}

    const gpu::Buffer& upload(const void* data, size_t bytes) {
        buffers_.emplace_back(ctx_, gpu::BufferDesc{bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                                    "temporal_test.upload"});
        std::memcpy(buffers_.back().mapped(), data, bytes);
        return buffers_.back();
    }
    const rg::HostReadback& readback(size_t bytes, const std::string& name) {
        return readbacks_.emplace_back(ctx_, bytes, "readback." + name);
    }

private:
    gpu::Context& ctx_;
    std::deque<gpu::Buffer> buffers_;
    std::deque<rg::HostReadback> readbacks_;
};

// A side x side texture (kSize x kSize unless told) of `format` filled from
// `texels` by a copy inside the graph.
inline rg::Texture uploadTexture(rg::Graph& graph, rg::FrameResources& resources, Staging& staging,
                                 const std::string& name, VkFormat format, const void* texels,
                                 uint32_t side = kSize) {
    const gpu::Buffer& source = staging.upload(texels, size_t(side) * side * gpu::bytesPerTexel(format));
    const rg::Buffer imported = graph.importBuffer(
        name + ".staging", {{source.size()}, kHostWrite, rg::BoundaryState::of(rg::Access::TransferSrc)});
    resources.bind(imported, source);
    struct Data {
        rg::Buffer source;
        rg::Texture texture;
    };
    const Data& d = graph.addPass<Data>(
        "upload." + name, rg::Queue::Graphics,
        [&](rg::Builder& b, Data& data) {
            data.source = b.read(imported, rg::Access::TransferSrc);
            data.texture = b.write(b.createTexture(name, {.width = side, .height = side, .format = format}),
                                   rg::Access::TransferDst);
        },
        [side](const Data& data, rg::PassContext& pc) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {side, side, 1};
            vkCmdCopyBufferToImage(pc.cmd(), pc.buffer(data.source).handle(), pc.image(data.texture).handle(),
                                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        });
    return d.texture;
}

// Copies a kSize x kSize texture into a new host buffer inside the graph.
inline const gpu::Buffer& readTexture(rg::Graph& graph, rg::FrameResources& resources, Staging& staging,
                                      rg::Texture texture, VkFormat format, const std::string& name) {
    const rg::HostReadback& target = staging.readback(kPixels * gpu::bytesPerTexel(format), name);
    target.copy(graph, resources, texture);
    return target.buffer();
}

inline std::vector<glm::vec4> halves(const gpu::Buffer& b, int components) {
    std::vector<glm::vec4> out(kPixels, glm::vec4(0.0f));
    const uint16_t* h = reinterpret_cast<const uint16_t*>(b.mapped());
    for (size_t i = 0; i < kPixels; ++i) {
        for (int c = 0; c < components; ++c) out[i][c] = glm::unpackHalf1x16(h[i * components + c]);
    }
    return out;
}

// ---------------------------------------------------------------- scenes

inline scene::Material material(float roughness, float metallic, glm::vec3 albedo = glm::vec3(0.8f)) {
    scene::Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    m.roughnessFactor = roughness;
    m.metallicFactor = metallic;
    return m;
}

// One instance per geometry, so a test can move each.
inline scene::Scene makeScene(std::vector<scene::Geometry> geometries, std::vector<scene::Material> materials) {
    scene::Scene s;
    s.name = "temporal-test";
    s.materials = std::move(materials);
    for (size_t i = 0; i < geometries.size(); ++i) {
        scene::Mesh mesh;
        mesh.name = "object" + std::to_string(i);
        mesh.lods.push_back({{std::move(geometries[i])}});
        scene::Instance inst;
        inst.name = mesh.name;
        s.meshes.push_back(std::move(mesh));
        inst.mesh = uint32_t(i);
        s.instances.push_back(inst);
    }
    scene::prepareScene(s);
    return s;
}

inline constexpr float kWallDistance = 5.0f;

// A wall filling the image at z = -kWallDistance, facing the camera.
inline scene::Scene wallScene(const scene::Material& m) {
    return makeScene({square({0, 0, -kWallDistance}, {1, 0, 0}, {0, 1, 0}, 50.0f, 0)}, {m});
}

} // namespace glint::temporal_test
