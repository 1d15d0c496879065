// The harness of glint_integrate_gpu_tests (integrate_test.cpp,
// feedback_test.cpp): integrate and the feedback pass on a real device
// behind the real G-buffer and ray generation passes, validation on. The
// traces are hand-made: known SSLR radiance, confidence and hit uvs and
// known RT radiance and hit distances are uploaded into the frame, so every
// pixel's source (sky, environment, SSLR, RT, fallback) is known from its
// class, its ray (a follower reads its quad leader's traces) and those
// values (expect(), checkFrame(), checkCounters()).
#pragma once

#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/feedback.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/integrate.h"
#include "glint/passes/lighting.h"
#include "glint/passes/ray_generation.h"
#include "glint/passes/sslr.h"
#include "glint/scene/animation.h"

#include "glint/feedback_shared.h"
#include "glint/integrate_shared.h"
#include "glint/ray_generation_shared.h"
#include "glint/sslr_shared.h"

#include <glm/gtc/packing.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <span>
#include <vector>

namespace glint::integrate_test {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr uint32_t kTiles = kSize / shader::kTileSize;
constexpr size_t kPixels = size_t(kSize) * kSize;
using test::square;
using test::testCamera;

constexpr rg::BoundaryState kHostWrite =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

inline size_t at(uint32_t x, uint32_t y) { return size_t(y) * kSize + x; }

inline bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool finite(glm::vec4 v) { return finite(glm::vec3(v)) && std::isfinite(v.w); }

// What a float becomes in a half-float texture.
inline float half(float v) { return glm::unpackHalf1x16(glm::packHalf1x16(v)); }

// ---------------------------------------------------------------------------
// Uploads and readbacks inside the graph, under the graph's own barriers
// ---------------------------------------------------------------------------

class Transfers {
public:
    explicit Transfers(gpu::Context& ctx) : ctx_(ctx) {}

    // A transient kSize^2 texture of `format` holding `bytes`, tightly packed rows.
    rg::Texture uploadTexture(rg::Graph& graph, rg::FrameResources& resources, const std::string& name,
                              VkFormat format, const void* bytes, size_t size) {
        const rg::Buffer staging = stage(graph, resources, name, bytes, size);
        struct Data {
            rg::Buffer src;
            rg::Texture dst;
        };
        const Data& data = graph.addPass<Data>(
            "upload." + name, rg::Queue::Graphics,
            [&](rg::Builder& b, Data& d) {
                d.src = b.read(staging, rg::Access::TransferSrc);
                d.dst = b.write(b.createTexture(name, {.width = kSize, .height = kSize, .format = format}),
                                rg::Access::TransferDst);
            },
            [](const Data& d, rg::PassContext& pc) {
                VkBufferImageCopy region{};
                region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                region.imageExtent = {kSize, kSize, 1};
                vkCmdCopyBufferToImage(pc.cmd(), pc.buffer(d.src).handle(), pc.image(d.dst).handle(),
                                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
            });
        return data.dst;
    }

    // Writes `words` into `target` (e.g. a history's current half).
    rg::Buffer uploadBuffer(rg::Graph& graph, rg::FrameResources& resources, const std::string& name,
                            rg::Buffer target, const std::vector<uint32_t>& words) {
        const rg::Buffer staging = stage(graph, resources, name, words.data(), words.size() * 4);
        struct Data {
            rg::Buffer src, dst;
        };
        const Data& data = graph.addPass<Data>(
            "upload." + name, rg::Queue::Graphics,
            [&](rg::Builder& b, Data& d) {
                d.src = b.read(staging, rg::Access::TransferSrc);
                d.dst = b.write(target, rg::Access::TransferDst);
            },
            [](const Data& d, rg::PassContext& pc) {
                const gpu::Buffer& src = pc.buffer(d.src);
                const VkBufferCopy region{0, 0, src.size()};
                vkCmdCopyBuffer(pc.cmd(), src.handle(), pc.buffer(d.dst).handle(), 1, &region);
            });
        return data.dst;
    }

    // Copies a texture (texelBytes per texel) or buffer into host memory at
    // the end of the frame; read it with get() after the frame finished.
    size_t readTexture(rg::Graph& graph, rg::FrameResources& resources, rg::Texture texture, uint32_t texelBytes) {
        return read(graph, resources, texture, {}, kPixels * texelBytes);
    }
    size_t readBuffer(rg::Graph& graph, rg::FrameResources& resources, rg::Buffer buffer, uint64_t bytes) {
        return read(graph, resources, {}, buffer, bytes);
    }

    template <class T> std::vector<T> get(size_t index) const {
        const std::span<const T> values = readbacks_.at(index)->template as<T>();
        return {values.begin(), values.end()};
    }

private:
    rg::Buffer stage(rg::Graph& graph, rg::FrameResources& resources, const std::string& name, const void* bytes,
                     size_t size) {
        staging_.push_back(std::make_unique<gpu::Buffer>(
            ctx_, gpu::BufferDesc{size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryUsage::Upload,
                                  "integrate_test.stage." + name}));
        std::memcpy(staging_.back()->mapped(), bytes, size);
        const rg::Buffer staging = graph.importBuffer(
            "stage." + name, {{size}, kHostWrite, rg::BoundaryState::of(rg::Access::TransferSrc)});
        resources.bind(staging, *staging_.back());
        return staging;
    }

    size_t read(rg::Graph& graph, rg::FrameResources& resources, rg::Texture texture, rg::Buffer buffer,
                uint64_t bytes) {
        const size_t index = readbacks_.size();
        readbacks_.push_back(
            std::make_unique<rg::HostReadback>(ctx_, bytes, "integrate_test.readback" + std::to_string(index)));
        if (texture.valid()) readbacks_.back()->copy(graph, resources, texture);
        if (buffer.valid()) readbacks_.back()->copy(graph, resources, buffer);
        return index;
    }

    gpu::Context& ctx_;
    // Kept for the harness's life: a buffer freed and its memory given to
    // the next frame's buffers reads to synchronization validation as a
    // hazard against the finished frame's copies.
    std::vector<std::unique_ptr<gpu::Buffer>> staging_;
    std::vector<std::unique_ptr<rg::HostReadback>> readbacks_;
};

// ---------------------------------------------------------------------------
// Scenes
// ---------------------------------------------------------------------------

// A square stretched to halfU x halfV along its axes.
inline scene::Geometry rectangle(glm::vec3 center, glm::vec3 u, glm::vec3 v, float halfU, float halfV,
                                 uint32_t material) {
    scene::Geometry g = square(center, u, v, 1.0f, material);
    for (glm::vec3& p : g.positions) {
        const glm::vec3 d = p - center;
        p = center + u * (glm::dot(d, u) * halfU) + v * (glm::dot(d, v) * halfV);
    }
    return g;
}

// Roughness of the floor's three strips.
constexpr float kSharedRoughness = 0.2f;  // >= reuseRoughness: quads share rays
constexpr float kMirrorRoughness = 0.0f;   // every pixel its own ray
constexpr float kEnvRoughness = 0.5f;      // above the cutoff: environment only

// A floor at y = -1 under the test camera (lower half of the image; the
// upper half is sky): x < -2 shares quad rays, -2 < x < 0 is a mirror, and
// x > 0 is too rough to trace. With ray generation's distances set by
// floorRaySettings() it holds RT (near), hybrid and SSLR (far) pixels.
inline scene::Scene floorScene() {
    scene::Scene s;
    s.name = "integrate-test-floor";
    for (const float roughness : {kSharedRoughness, kMirrorRoughness, kEnvRoughness}) {
        scene::Material m;
        m.roughnessFactor = roughness;
        m.metallicFactor = 1.0f;
        s.materials.push_back(m);
    }
    scene::Mesh mesh;
    mesh.name = "floor";
    const glm::vec3 x(1, 0, 0), z(0, 0, -1);
    mesh.lods.push_back({{rectangle({-501, -1, -500}, x, z, 499.0f, 500.0f, 0),
                          rectangle({-1, -1, -500}, x, z, 1.0f, 500.0f, 1),
                          rectangle({500, -1, -500}, x, z, 500.0f, 500.0f, 2)}});
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "floor";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}

inline passes::RayGenerationSettings floorRaySettings() {
    passes::RayGenerationSettings s;
    s.rtMaxDistance = 2.5f;  // rows below ~47
    return s;
}
// The SSLR-only distance of the floor scene's runs: rows above ~36.
constexpr float kFloorSslrMinDistance = 8.0f;

// A wall at z = -kWallDistance facing the camera and filling the image.
constexpr float kWallDistance = 4.0f;

inline scene::Scene wallScene() {
    scene::Scene s;
    s.name = "integrate-test-wall";
    scene::Material m;
    m.roughnessFactor = 0.5f;
    s.materials.push_back(m);
    scene::Mesh mesh;
    mesh.name = "wall";
    mesh.lods.push_back({{square({0, 0, -kWallDistance}, {1, 0, 0}, {0, 1, 0}, 200.0f)}});
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "wall";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}

// The SSLR test's scene (tests/gpu/sslr_test.cpp): a mirror floor at y = -1
// and a rough red wall at z = -kMirrorWallDistance from the floor to y = 1.
constexpr float kMirrorWallDistance = 6.0f;

inline scene::Scene mirrorWallScene() {
    scene::Scene s;
    s.name = "integrate-test-mirror-wall";
    scene::Material mirror;
    mirror.roughnessFactor = 0.0f;
    mirror.metallicFactor = 1.0f;
    scene::Material wall;
    wall.baseColorFactor = {0.8f, 0.1f, 0.1f, 1.0f};
    wall.roughnessFactor = 1.0f;
    wall.metallicFactor = 0.0f;
    s.materials = {mirror, wall};
    scene::Mesh mesh;
    mesh.name = "floor-and-wall";
    mesh.lods.push_back({{square({0, -1, -500}, {1, 0, 0}, {0, 0, -1}, 500.0f, 0),
                          rectangle({0, 0, -kMirrorWallDistance}, {1, 0, 0}, {0, 1, 0}, 40.0f, 1.0f, 1)}});
    s.meshes.push_back(std::move(mesh));
    scene::Instance inst;
    inst.name = "floor-and-wall";
    s.instances.push_back(inst);
    scene::prepareScene(s);
    return s;
}

// ---------------------------------------------------------------------------
// Hand-made traces
// ---------------------------------------------------------------------------

// What the SSLR and RT passes "wrote", per pixel, as the textures hold it
// (half floats already rounded). Every pixel has values, so a follower
// that read its own instead of its leader's would be caught.
struct Traces {
    std::vector<glm::vec4> sslrRadiance;  // a: 0, or the hit's kind (kSslrHitRay, kSslrHitCone)
    std::vector<float> sslrConfidence;
    std::vector<glm::vec2> sslrHit;       // uv of the hit texel's centre (float32)
    std::vector<glm::vec4> rtRadiance;    // a = traced
    std::vector<float> rtHitDistance;
};

// The row an SSLR hit of column x points at: floor rows (a surface at a
// known distance), and every ninth pixel the sky (no surface: kMiss).
inline uint32_t hitRow(uint32_t x, uint32_t y) { return y % 9 == 0 ? 10u : 40u + (x + y) % 8; }

inline Traces makeTraces(uint32_t seed, bool poison) {
    Traces t;
    t.sslrRadiance.resize(kPixels);
    t.sslrConfidence.resize(kPixels);
    t.sslrHit.resize(kPixels);
    t.rtRadiance.resize(kPixels);
    t.rtHitDistance.resize(kPixels);
    // Full (>= 0.9, also 0.95), mid and zero confidence.
    const std::array<float, 5> confidences = {1.0f, 0.5f, 0.0f, 0.95f, 0.3f};
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const size_t i = at(x, y);
            const float c = confidences[(x * 3 + y * 5 + seed) % confidences.size()];
            // A zero-confidence result is a miss or a rejected hit (a back
            // face): both occur. Every fifth hit is a cone trace's.
            const float hit = c > 0.0f || x % 2 == 1
                                  ? ((x + 2 * y) % 5 == 0 ? shader::kSslrHitCone : shader::kSslrHitRay)
                                  : 0.0f;
            t.sslrRadiance[i] = glm::vec4(float(x) / 64.0f + 0.01f, float(y) / 64.0f + 0.02f, 0.25f, hit);
            t.sslrConfidence[i] = c;
            const glm::vec2 uv = shader::sslrHitUv({x, hitRow(x, y)}, glm::uvec2(kSize));
            t.sslrHit[i] = uv;
            const bool traced = (x + 2 * y + seed) % 3 != 0;
            t.rtRadiance[i] = glm::vec4(0.75f, float(x) / 64.0f, float(y) / 64.0f, traced ? 1.0f : 0.0f);
            t.rtHitDistance[i] = 1.0f + 0.5f * float(x) + 0.01f * float(y);
            if (poison) {
                if ((x + y) % 7 == 0) t.sslrRadiance[i].r = kNaN;
                if ((x + y) % 7 == 3) t.sslrConfidence[i] = kNaN;
                if ((x * y) % 11 == 1) t.rtRadiance[i].g = kInf;
                if ((x + 3 * y) % 13 == 0) t.rtHitDistance[i] = kNaN;
                if ((x + 3 * y) % 13 == 5) t.rtHitDistance[i] = -kInf;
                if ((x + 5 * y) % 17 == 2) t.sslrHit[i].x = kNaN;
            }
            for (int c4 = 0; c4 < 4; ++c4) {
                t.sslrRadiance[i][c4] = half(t.sslrRadiance[i][c4]);
                t.rtRadiance[i][c4] = half(t.rtRadiance[i][c4]);
            }
            t.sslrConfidence[i] = half(t.sslrConfidence[i]);
        }
    }
    return t;
}

inline std::vector<uint16_t> halves(const std::vector<glm::vec4>& v) {
    std::vector<uint16_t> out;
    for (const glm::vec4& p : v) {
        for (int c = 0; c < 4; ++c) out.push_back(glm::packHalf1x16(p[c]));
    }
    return out;
}

inline std::vector<uint16_t> halves(const std::vector<float>& v) {
    std::vector<uint16_t> out;
    for (const float f : v) out.push_back(glm::packHalf1x16(f));
    return out;
}

// ---------------------------------------------------------------------------
// The oracle: what integrate should have written
// ---------------------------------------------------------------------------

// glint/brdf.glsl's environmentRadiance, in C++.
inline glm::vec3 environmentRadiance(const shader::SceneLighting& l, glm::vec3 dir, float roughness) {
    const glm::vec3 zenith(l.skyZenith), horizon(l.skyHorizon), ground(l.skyGround);
    const float y = glm::clamp(dir.y, -1.0f, 1.0f);
    const glm::vec3 sky = y < 0.0f ? glm::mix(horizon, ground, glm::clamp(-y * 10.0f, 0.0f, 1.0f))
                                   : glm::mix(horizon, zenith, std::sqrt(y));
    const float pi = 3.14159265358979f;
    const glm::vec3 up = pi * glm::mix(horizon, zenith, 0.5f);
    const glm::vec3 down = pi * ground;
    const glm::vec3 irradiance = glm::mix(down, up, 0.5f + 0.5f * y);
    const float alpha = glm::clamp(roughness * roughness, 0.0f, 1.0f);
    return glm::mix(sky, irradiance / pi, alpha);
}

// The floor point a pixel sees (the test camera at the origin).
inline glm::vec3 floorPoint(uint32_t x, uint32_t y) {
    const glm::vec2 ndc = test::pixelNdc(x, y);
    return glm::vec3(ndc.x, -ndc.y, -1.0f) / ndc.y;
}

struct Expected {
    glm::vec3 radiance{0.0f};
    float reflects = 0.0f;
    float hitDistance = shader::kMissHitDistance;
    uint32_t source = shader::kSourceSky;
    bool hasSslrHit = false;  // SSLR chosen: hit distance from the depth at the hit
    // How far the rasterised depth may move the hit: rasterisers snap
    // vertices to a sub-pixel grid (8 bits on NVIDIA), which near the
    // horizon of a floor moves the surface a long way per pixel.
    float hitDistanceSlack = 0.0f;
};

struct Presence {
    bool sslr = true;
    bool rt = true;
    bool feedback = true;
    // IntegrateInputs::sslrCountsOnly: SSLR handed every hybrid ray on;
    // its hits are counted, the ray tracer's results used.
    bool sslrCountsOnly = false;
};

// Everything one frame read back.
struct Frame {
    std::vector<uint32_t> classes;
    std::vector<shader::PackedRay> rays;
    std::vector<glm::u8vec4> roughnessMetal;
    std::vector<glm::vec4> radiance;
    std::vector<float> hitDistance;
    std::vector<glm::u8vec4> source;
    std::vector<uint32_t> counters;     // integrate's new counters, one per tile
    uint32_t frameHitsWord = 0;         // the counters' word after the tiles (glint/feedback_shared.h)
    std::vector<uint32_t> reprojected;  // the feedback pass's
    std::vector<uint32_t> tileModes;
    Traces sslr;  // the SSLR inputs integrate read (its sslr* fields)
};

inline Expected expect(const Frame& f, const Traces& t, const Presence& present,
                       const shader::SceneLighting& lighting, float threshold, uint32_t x, uint32_t y) {
    Expected e;
    const size_t i = at(x, y);
    const uint32_t cls = f.classes[i];
    if (cls == shader::kPixelSky) {
        return e;
    }
    e.reflects = shader::kReflects;
    const glm::vec3 d = glm::normalize(floorPoint(x, y));
    const glm::vec3 mirror(d.x, -d.y, d.z);  // reflect about the floor's normal (0, 1, 0)
    e.radiance = environmentRadiance(lighting, mirror, shader::decodeUnorm8(f.roughnessMetal[i].r));
    e.source = cls == shader::kPixelEnv ? shader::kSourceEnvironment : shader::kSourceFallback;
    if (cls == shader::kPixelEnv) {
        return e;
    }
    const shader::PackedRay& ray = f.rays[i];
    const bool traced = ray.pixelFlags != shader::kNoRay;
    const glm::uvec2 leader = traced ? shader::unpackRayPixel(ray.pixelFlags) : glm::uvec2(x, y);
    const size_t li = at(leader.x, leader.y);
    // Compared as SSLR compares (the nearest half float).
    threshold = passes::sslrStoredThreshold(threshold);
    float confidence = 0.0f;
    // The RT outputs are read only where SSLR handed the ray on: nothing
    // clears them in the frame (the stored confidence is a half already).
    bool handedToRt = cls == shader::kPixelHybrid || cls == shader::kPixelRt;
    if (present.sslr && traced && (cls == shader::kPixelSslr || cls == shader::kPixelHybrid)) {
        const glm::vec4 r = t.sslrRadiance[li];
        const float c = t.sslrConfidence[li];
        handedToRt = cls == shader::kPixelHybrid && (present.sslrCountsOnly || !(c >= threshold));
        if (r.a > 0.5f && finite(glm::vec3(r)) && std::isfinite(c) && std::isfinite(t.sslrHit[li].x) &&
            std::isfinite(t.sslrHit[li].y) && !(present.sslrCountsOnly && cls == shader::kPixelHybrid)) {
            confidence = glm::clamp(c, 0.0f, 1.0f);
        }
    }
    const bool rtTraced = present.rt && traced && handedToRt && t.rtRadiance[li].a > 0.5f &&
                          finite(glm::vec3(t.rtRadiance[li]));
    bool useSslr = false;
    if (confidence >= threshold) {
        useSslr = true;
    } else if (rtTraced) {
        e.radiance = glm::vec3(t.rtRadiance[li]);
        const float hd = t.rtHitDistance[li];
        e.hitDistance = std::isfinite(hd) ? glm::clamp(hd, 0.0f, shader::kMissHitDistance) : shader::kMissHitDistance;
        e.source = shader::kSourceRt;
    } else if (confidence > 0.0f) {
        useSslr = true;
    }
    if (useSslr) {
        e.radiance = glm::vec3(t.sslrRadiance[li]);
        e.source = shader::kSourceSslr;
        // A cone trace's hit carries no ray's noise.
        if (shader::sslrHitIsCone(t.sslrRadiance[li].a)) {
            e.reflects = shader::kReflectsNoiseFree;
        }
        const glm::vec2 uv(t.sslrHit[li]);
        const glm::uvec2 texel = shader::sslrHitTexel(uv, glm::uvec2(kSize));
        // Floor rows have a surface; the sky row has none.
        if (f.classes[at(texel.x, texel.y)] != shader::kPixelSky) {
            e.hitDistance = glm::length(floorPoint(texel.x, texel.y) - floorPoint(x, y));
            e.hasSslrHit = true;
            // The floor's distance changes by (distance^2 * d ndc.y) per row;
            // 1/256 pixel of snapping is 2/(256 kSize) in NDC, at the hit
            // and at the reflecting pixel itself (the horizon rows are
            // ~80 units away: 0.4 units per 1/256 pixel there).
            const float hitDepth = glm::length(floorPoint(texel.x, texel.y));
            const float ownDepth = glm::length(floorPoint(x, y));
            e.hitDistanceSlack = (hitDepth * hitDepth + ownDepth * ownDepth) * 2.0f / (256.0f * float(kSize));
        }
    }
    return e;
}

// This frame's SSLR hit and miss counts of a tile, as integrate counts them.
inline glm::uvec2 tileCounts(const Frame& f, const Traces& t, float threshold, uint32_t tx, uint32_t ty) {
    glm::uvec2 counts(0);
    for (uint32_t y = ty * shader::kTileSize; y < (ty + 1) * shader::kTileSize; ++y) {
        for (uint32_t x = tx * shader::kTileSize; x < (tx + 1) * shader::kTileSize; ++x) {
            const size_t i = at(x, y);
            const shader::PackedRay& ray = f.rays[i];
            const bool own = ray.pixelFlags != shader::kNoRay && (ray.pixelFlags & shader::kRayReused) == 0u;
            if (!own || (f.classes[i] != shader::kPixelSslr && f.classes[i] != shader::kPixelHybrid)) continue;
            const glm::vec4 r = t.sslrRadiance[i];
            const float c = t.sslrConfidence[i];
            const bool valid = r.a > 0.5f && finite(glm::vec3(r)) && std::isfinite(c) &&
                               std::isfinite(t.sslrHit[i].x) && std::isfinite(t.sslrHit[i].y);
            const bool hit = valid && glm::clamp(c, 0.0f, 1.0f) >= passes::sslrStoredThreshold(threshold);
            ++counts[hit ? 0 : 1];
        }
    }
    return counts;
}

inline glm::u8vec4 sourceColour(uint32_t source) {
    const glm::vec4 c = shader::integrateSourceColour(source);
    return {shader::encodeUnorm8(c.x), shader::encodeUnorm8(c.y), shader::encodeUnorm8(c.z),
            shader::encodeUnorm8(c.w)};
}

// ---------------------------------------------------------------------------
// Running frames
// ---------------------------------------------------------------------------

struct RunOptions {
    passes::IntegrateSettings integrate;
    // SSLR's, integrate's (and so the counters') confidence threshold.
    float confidenceThreshold = passes::kDefaultConfidenceThreshold;
    passes::RayGenerationSettings rays = floorRaySettings();
    float sslrMinDistance = kFloorSslrMinDistance;
    // Ray generation follows the feedback's tile modes.
    bool followTileModes = false;
    // Runs the real SSLR pass instead of uploading traces.sslr*.
    passes::SslrPipelines* realSslr = nullptr;
    passes::FeedbackSettings feedback;
    // IntegrateInputs::debugOutputs: off, the source colours are not read back.
    bool debugOutputs = true;
};

// One scene, one executor (the history persists across frames), the real
// G-buffer and ray generation, hand-made traces, the feedback pass and
// integrate.
class Harness {
public:
    Harness(test::GpuTest& gpu, scene::Scene scene)
        : ctx_(gpu.ctx()),
          scene_(std::move(scene)),
          executor_(ctx_),
          renderer_(ctx_, scene_),
          rayPipelines_(ctx_),
          feedbackPipelines_(ctx_),
          integratePipelines_(ctx_),
          transfers_(ctx_),
          lighting_(passes::sceneLighting(scene_)) {}

    const shader::SceneLighting& lighting() const { return lighting_; }

    Frame run(const scene::Camera& camera, uint64_t frameIndex, const Traces& traces, const Presence& present,
              const RunOptions& options = {}) {
        rg::Graph graph(executor_.queueCaps());
        rg::FrameResources resources;
        Frame f;
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer_, {camera});
        std::optional<passes::FeedbackOutputs> feedback;
        if (present.feedback) {
            feedback = passes::addFeedbackPass(graph, feedbackPipelines_, {gbuf, frameIndex}, options.feedback);
        }
        passes::RayGenerationInputs rayInputs{gbuf, frameIndex, camera};
        rayInputs.sslrMinDistance = options.sslrMinDistance;
        if (options.followTileModes && feedback) rayInputs.tileModes = feedback->tileModes;
        const passes::RayGenerationOutputs rays =
            passes::addRayGenerationPass(graph, rayPipelines_, rayInputs, options.rays);

        passes::IntegrateInputs in;
        in.gbuffer = gbuf;
        in.rays = rays;
        if (present.sslr && options.realSslr) {
            in.sslr = passes::addSslrPass(graph, *options.realSslr,
                                          {gbuf, rays, frameIndex, camera.view, camera.projection,
                                           options.confidenceThreshold});
        } else if (present.sslr) {
            passes::SslrOutputs sslr;
            sslr.width = kSize;
            sslr.height = kSize;
            const auto r = halves(traces.sslrRadiance), c = halves(traces.sslrConfidence);
            sslr.radiance = transfers_.uploadTexture(graph, resources, "sslr_radiance", passes::kSslrRadianceFormat,
                                                     r.data(), r.size() * 2);
            sslr.confidence = transfers_.uploadTexture(graph, resources, "sslr_confidence",
                                                       passes::kSslrConfidenceFormat, c.data(), c.size() * 2);
            sslr.hit = transfers_.uploadTexture(graph, resources, "sslr_hits", passes::kSslrHitFormat,
                                                traces.sslrHit.data(), kPixels * sizeof(glm::vec2));
            in.sslr = sslr;
        }
        if (present.rt) {
            const auto r = halves(traces.rtRadiance);
            in.rtRadiance = transfers_.uploadTexture(graph, resources, "rt_radiance", VK_FORMAT_R16G16B16A16_SFLOAT,
                                                     r.data(), r.size() * 2);
            in.rtHitDistance = transfers_.uploadTexture(graph, resources, "rt_hit_distance", VK_FORMAT_R32_SFLOAT,
                                                        traces.rtHitDistance.data(), kPixels * 4);
        }
        if (feedback) in.feedback = *feedback;
        in.lighting = lighting_;
        in.camera = camera;
        in.confidenceThreshold = options.confidenceThreshold;
        in.debugOutputs = options.debugOutputs;
        in.sslrCountsOnly = present.sslrCountsOnly;
        const passes::IntegrateOutputs out =
            passes::addIntegratePass(graph, integratePipelines_, in, options.integrate);
        REQUIRE(out.counters.valid() == present.feedback);

        const size_t classes = transfers_.readBuffer(graph, resources, rays.classes, kPixels * 4);
        const size_t rayList = transfers_.readBuffer(graph, resources, rays.rays, kPixels * sizeof(shader::PackedRay));
        const size_t roughness = transfers_.readTexture(graph, resources, gbuf.roughnessMetal, 4);
        const size_t radiance = transfers_.readTexture(graph, resources, out.radiance, 8);
        const size_t hitDistance = transfers_.readTexture(graph, resources, out.hitDistance, 4);
        REQUIRE(out.sourceDebug.valid() == options.debugOutputs);
        const size_t source = options.debugOutputs ? transfers_.readTexture(graph, resources, out.sourceDebug, 4) : 0;
        size_t counters = 0, reprojected = 0, modes = 0, sslrRadiance = 0, sslrConfidence = 0, sslrHit = 0;
        if (in.sslr) {
            sslrRadiance = transfers_.readTexture(graph, resources, in.sslr->radiance, 8);
            sslrConfidence = transfers_.readTexture(graph, resources, in.sslr->confidence, 2);
            sslrHit = transfers_.readTexture(graph, resources, in.sslr->hit, 8);
        }
        if (feedback) {
            const uint64_t bytes = uint64_t(kTiles) * kTiles * 4;
            counters = transfers_.readBuffer(graph, resources, out.counters, bytes + 4);
            reprojected = transfers_.readBuffer(graph, resources, feedback->reprojected, bytes);
            modes = transfers_.readBuffer(graph, resources, feedback->tileModes, bytes);
        }
        execute(graph, resources);

        f.classes = transfers_.get<uint32_t>(classes);
        f.rays = transfers_.get<shader::PackedRay>(rayList);
        f.roughnessMetal = transfers_.get<glm::u8vec4>(roughness);
        if (in.sslr) {
            // What the SSLR pass (or the upload) left, as integrate read it.
            const auto r = transfers_.get<uint16_t>(sslrRadiance);
            const auto c = transfers_.get<uint16_t>(sslrConfidence);
            f.sslr.sslrHit = transfers_.get<glm::vec2>(sslrHit);
            f.sslr.sslrRadiance.resize(kPixels);
            f.sslr.sslrConfidence.resize(kPixels);
            for (size_t i = 0; i < kPixels; ++i) {
                for (int k = 0; k < 4; ++k) {
                    f.sslr.sslrRadiance[i][k] = glm::unpackHalf1x16(r[i * 4 + k]);
                }
                f.sslr.sslrConfidence[i] = glm::unpackHalf1x16(c[i]);
            }
        }
        const auto radianceHalves = transfers_.get<uint16_t>(radiance);
        f.radiance.resize(kPixels);
        for (size_t i = 0; i < kPixels; ++i) {
            for (int c = 0; c < 4; ++c) f.radiance[i][c] = glm::unpackHalf1x16(radianceHalves[i * 4 + c]);
        }
        f.hitDistance = transfers_.get<float>(hitDistance);
        if (options.debugOutputs) f.source = transfers_.get<glm::u8vec4>(source);
        if (feedback) {
            f.counters = transfers_.get<uint32_t>(counters);
            f.frameHitsWord = f.counters.back();
            f.counters.pop_back();
            f.reprojected = transfers_.get<uint32_t>(reprojected);
            f.tileModes = transfers_.get<uint32_t>(modes);
        }
        return f;
    }

    // A frame of the G-buffer and the feedback pass alone, whose counters'
    // current half is written with `counters` (standing in for integrate):
    // one per tile, then the frame's word of hits, which is 1 + the tiles'
    // hits where `counters` has none.
    struct FeedbackFrame {
        std::vector<uint32_t> reprojected;
        std::vector<uint32_t> tileModes;
        std::vector<glm::vec2> motion;
    };
    FeedbackFrame runFeedback(const scene::Camera& camera, uint64_t frameIndex, const std::vector<uint32_t>& counters,
                              const passes::FeedbackSettings& settings = {}, bool resetHistory = false) {
        rg::Graph graph(executor_.queueCaps());
        rg::FrameResources resources;
        const passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer_, {camera});
        const passes::FeedbackOutputs feedback =
            passes::addFeedbackPass(graph, feedbackPipelines_, {gbuf, frameIndex, resetHistory}, settings);
        REQUIRE(feedback.tilesX == kTiles);
        REQUIRE(feedback.tilesY == kTiles);
        std::vector<uint32_t> written = counters;
        if (written.size() == size_t(kTiles) * kTiles) {
            uint32_t hits = 0;
            for (const uint32_t c : counters) hits += shader::feedbackHits(c);
            written.push_back(shader::kFeedbackFrameHitsStart + hits);
        }
        transfers_.uploadBuffer(graph, resources, "counters", feedback.counters.current, written);
        const uint64_t bytes = uint64_t(kTiles) * kTiles * 4;
        const size_t reprojected = transfers_.readBuffer(graph, resources, feedback.reprojected, bytes);
        const size_t modes = transfers_.readBuffer(graph, resources, feedback.tileModes, bytes);
        const size_t motion = transfers_.readTexture(graph, resources, gbuf.motion, 4);
        execute(graph, resources);
        FeedbackFrame f;
        f.reprojected = transfers_.get<uint32_t>(reprojected);
        f.tileModes = transfers_.get<uint32_t>(modes);
        const auto motionHalves = transfers_.get<uint16_t>(motion);
        for (size_t i = 0; i < kPixels; ++i) {
            f.motion.push_back(
                {glm::unpackHalf1x16(motionHalves[2 * i]), glm::unpackHalf1x16(motionHalves[2 * i + 1])});
        }
        return f;
    }

private:
    void execute(rg::Graph& graph, rg::FrameResources& resources) {
        const rg::Plan plan = graph.compile(executor_.compileOptions());
        const auto report = rg::verify(plan);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor_.run(plan, resources);
        executor_.waitIdle();
    }

    gpu::Context& ctx_;
    scene::Scene scene_;
    rg::Executor executor_;
    passes::GBufferRenderer renderer_;
    passes::RayGenerationPipelines rayPipelines_;
    passes::FeedbackPipelines feedbackPipelines_;
    passes::IntegratePipelines integratePipelines_;
    Transfers transfers_;
    shader::SceneLighting lighting_;
};

// Compares one frame with the oracle; returns how often each (class,
// source) pair and each follower case occurred, so callers can insist the
// scene exercised them.
struct Coverage {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> classSource;
    uint32_t followers = 0;
    uint32_t followerSslr = 0;
    uint32_t followerRt = 0;
    uint32_t sslrHitDistances = 0;
    uint32_t noiseFree = 0;  // pixels marked kReflectsNoiseFree
    uint32_t count(uint32_t cls, uint32_t source) const {
        const auto it = classSource.find({cls, source});
        return it == classSource.end() ? 0u : it->second;
    }
};

inline Coverage checkFrame(const Frame& f, const Traces& t, const Presence& present,
                           const shader::SceneLighting& lighting, float threshold = 0.9f) {
    Coverage cov;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            INFO("pixel " << x << ", " << y << " class " << f.classes[at(x, y)]);
            const size_t i = at(x, y);
            const Expected e = expect(f, t, present, lighting, threshold, x, y);
            // Nothing non-finite leaves integrate.
            REQUIRE(finite(f.radiance[i]));
            REQUIRE(std::isfinite(f.hitDistance[i]));
            REQUIRE(f.hitDistance[i] >= 0.0f);
            REQUIRE(f.hitDistance[i] <= shader::kMissHitDistance);
            INFO("source " << e.source << " wrote " << int(f.source[i].r) << " " << int(f.source[i].g) << " "
                           << int(f.source[i].b) << "; radiance " << f.radiance[i].r << " " << f.radiance[i].g << " "
                           << f.radiance[i].b << " hit " << f.hitDistance[i]);
            REQUIRE(f.source[i] == sourceColour(e.source));
            REQUIRE(f.radiance[i].a == e.reflects);
            cov.noiseFree += e.reflects == shader::kReflectsNoiseFree ? 1u : 0u;
            const glm::vec3 got(f.radiance[i]);
            const glm::vec3 want(half(e.radiance.x), half(e.radiance.y), half(e.radiance.z));
            if (e.source == shader::kSourceSslr || e.source == shader::kSourceRt) {
                REQUIRE(got == want);  // copied, half to half
            } else {
                REQUIRE(glm::length(got - want) <= 2e-3f * glm::length(want) + 1e-4f);
            }
            if (e.hasSslrHit) {
                REQUIRE(std::abs(f.hitDistance[i] - e.hitDistance) <= 1e-3f * e.hitDistance + 1e-4f + e.hitDistanceSlack);
                ++cov.sslrHitDistances;
            } else {
                REQUIRE(f.hitDistance[i] == e.hitDistance);
            }
            ++cov.classSource[{f.classes[i], e.source}];
            const uint32_t flags = f.rays[i].pixelFlags;
            if (flags != shader::kNoRay && (flags & shader::kRayReused) != 0u) {
                ++cov.followers;
                cov.followerSslr += e.source == shader::kSourceSslr ? 1u : 0u;
                cov.followerRt += e.source == shader::kSourceRt ? 1u : 0u;
            }
        }
    }
    return cov;
}

inline void checkCounters(const Frame& f, const Traces& t, const std::vector<uint32_t>& carried,
                          float threshold = 0.9f) {
    for (uint32_t ty = 0; ty < kTiles; ++ty) {
        for (uint32_t tx = 0; tx < kTiles; ++tx) {
            INFO("tile " << tx << ", " << ty);
            const glm::uvec2 counts = tileCounts(f, t, threshold, tx, ty);
            const uint32_t tile = ty * kTiles + tx;
            CHECK(f.counters[tile] == shader::rotateFeedback(carried[tile], counts.x, counts.y));
        }
    }
}

} // namespace glint::integrate_test
