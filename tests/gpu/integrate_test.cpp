// Integrate and feedback (passes/integrate.h, passes/feedback.h) on a real
// device behind the real G-buffer and ray generation passes, validation on.
// The traces are hand-made: known SSLR radiance, confidence and hit uvs and
// known RT radiance and hit distances are uploaded into the frame, so every
// pixel's source (sky, environment, SSLR, RT, fallback) is known from its
// class, its ray (a follower reads its quad leader's traces) and those
// values; radiance, hit distance, the debug colour and the tile counters
// are checked against that, including with NaN and Inf in the traces and
// with each trace absent. Feedback: counters carried by a known camera
// motion land in the expected tiles, off-screen content carries nothing,
// tile modes follow the counts, and two frames rotate through the history.
// The counter packing and the mode decision run on the CPU too (the
// shaders' own header, glint/feedback_shared.h).
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

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr uint32_t kTiles = kSize / shader::kTileSize;
constexpr size_t kPixels = size_t(kSize) * kSize;
using test::square;
using test::testCamera;

constexpr rg::BoundaryState kHostWrite =
    rg::BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

size_t at(uint32_t x, uint32_t y) { return size_t(y) * kSize + x; }

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(glm::vec4 v) { return finite(glm::vec3(v)) && std::isfinite(v.w); }

// What a float becomes in a half-float texture.
float half(float v) { return glm::unpackHalf1x16(glm::packHalf1x16(v)); }

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
scene::Geometry rectangle(glm::vec3 center, glm::vec3 u, glm::vec3 v, float halfU, float halfV, uint32_t material) {
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
scene::Scene floorScene() {
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

passes::RayGenerationSettings floorRaySettings() {
    passes::RayGenerationSettings s;
    s.rtMaxDistance = 2.5f;  // rows below ~47
    return s;
}
// The SSLR-only distance of the floor scene's runs: rows above ~36.
constexpr float kFloorSslrMinDistance = 8.0f;

// A wall at z = -kWallDistance facing the camera and filling the image.
constexpr float kWallDistance = 4.0f;

scene::Scene wallScene() {
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

scene::Scene mirrorWallScene() {
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
    std::vector<glm::vec4> sslrRadiance;  // a = hit
    std::vector<float> sslrConfidence;
    std::vector<glm::vec4> sslrHit;       // uv, confidence, hit
    std::vector<glm::vec4> rtRadiance;    // a = traced
    std::vector<float> rtHitDistance;
};

// The row an SSLR hit of column x points at: floor rows (a surface at a
// known distance), and every ninth pixel the sky (no surface: kMiss).
uint32_t hitRow(uint32_t x, uint32_t y) { return y % 9 == 0 ? 10u : 40u + (x + y) % 8; }

Traces makeTraces(uint32_t seed, bool poison) {
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
            // face): both occur.
            const float hit = c > 0.0f || x % 2 == 1 ? 1.0f : 0.0f;
            t.sslrRadiance[i] = glm::vec4(float(x) / 64.0f + 0.01f, float(y) / 64.0f + 0.02f, 0.25f, hit);
            t.sslrConfidence[i] = c;
            const glm::vec2 uv((float(x) + 0.5f) / float(kSize), (float(hitRow(x, y)) + 0.5f) / float(kSize));
            t.sslrHit[i] = glm::vec4(uv, c, hit);
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
                t.sslrHit[i][c4] = half(t.sslrHit[i][c4]);
                t.rtRadiance[i][c4] = half(t.rtRadiance[i][c4]);
            }
            t.sslrConfidence[i] = half(t.sslrConfidence[i]);
        }
    }
    return t;
}

std::vector<uint16_t> halves(const std::vector<glm::vec4>& v) {
    std::vector<uint16_t> out;
    for (const glm::vec4& p : v) {
        for (int c = 0; c < 4; ++c) out.push_back(glm::packHalf1x16(p[c]));
    }
    return out;
}

std::vector<uint16_t> halves(const std::vector<float>& v) {
    std::vector<uint16_t> out;
    for (const float f : v) out.push_back(glm::packHalf1x16(f));
    return out;
}

// ---------------------------------------------------------------------------
// The oracle: what integrate should have written
// ---------------------------------------------------------------------------

// glint/brdf.glsl's environmentRadiance, in C++.
glm::vec3 environmentRadiance(const shader::SceneLighting& l, glm::vec3 dir, float roughness) {
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
glm::vec3 floorPoint(uint32_t x, uint32_t y) {
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

Expected expect(const Frame& f, const Traces& t, const Presence& present, const shader::SceneLighting& lighting,
                float threshold, uint32_t x, uint32_t y) {
    Expected e;
    const size_t i = at(x, y);
    const uint32_t cls = f.classes[i];
    if (cls == shader::kPixelSky) {
        return e;
    }
    e.reflects = 1.0f;
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
        handedToRt = cls == shader::kPixelHybrid && !(c >= threshold);
        if (r.a > 0.5f && finite(glm::vec3(r)) && std::isfinite(c) && std::isfinite(t.sslrHit[li].x) &&
            std::isfinite(t.sslrHit[li].y)) {
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
        const glm::vec2 uv(t.sslrHit[li]);
        const glm::uvec2 texel = glm::uvec2(glm::floor(uv * float(kSize)));
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
glm::uvec2 tileCounts(const Frame& f, const Traces& t, float threshold, uint32_t tx, uint32_t ty) {
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

glm::u8vec4 sourceColour(uint32_t source) {
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
            const auto r = halves(traces.sslrRadiance), c = halves(traces.sslrConfidence), h = halves(traces.sslrHit);
            sslr.radiance = transfers_.uploadTexture(graph, resources, "sslr_radiance", passes::kSslrRadianceFormat,
                                                     r.data(), r.size() * 2);
            sslr.confidence = transfers_.uploadTexture(graph, resources, "sslr_confidence",
                                                       passes::kSslrConfidenceFormat, c.data(), c.size() * 2);
            sslr.hitDebug = transfers_.uploadTexture(graph, resources, "sslr_hits", passes::kSslrHitDebugFormat,
                                                     h.data(), h.size() * 2);
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
        const passes::IntegrateOutputs out =
            passes::addIntegratePass(graph, integratePipelines_, in, options.integrate);
        REQUIRE(out.counters.valid() == present.feedback);

        const size_t classes = transfers_.readBuffer(graph, resources, rays.classes, kPixels * 4);
        const size_t rayList = transfers_.readBuffer(graph, resources, rays.rays, kPixels * sizeof(shader::PackedRay));
        const size_t roughness = transfers_.readTexture(graph, resources, gbuf.roughnessMetal, 4);
        const size_t radiance = transfers_.readTexture(graph, resources, out.radiance, 8);
        const size_t hitDistance = transfers_.readTexture(graph, resources, out.hitDistance, 4);
        const size_t source = transfers_.readTexture(graph, resources, out.sourceDebug, 4);
        size_t counters = 0, reprojected = 0, modes = 0, sslrRadiance = 0, sslrConfidence = 0, sslrHit = 0;
        if (in.sslr) {
            sslrRadiance = transfers_.readTexture(graph, resources, in.sslr->radiance, 8);
            sslrConfidence = transfers_.readTexture(graph, resources, in.sslr->confidence, 2);
            sslrHit = transfers_.readTexture(graph, resources, in.sslr->hitDebug, 8);
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
            const auto h = transfers_.get<uint16_t>(sslrHit);
            f.sslr.sslrRadiance.resize(kPixels);
            f.sslr.sslrConfidence.resize(kPixels);
            f.sslr.sslrHit.resize(kPixels);
            for (size_t i = 0; i < kPixels; ++i) {
                for (int k = 0; k < 4; ++k) {
                    f.sslr.sslrRadiance[i][k] = glm::unpackHalf1x16(r[i * 4 + k]);
                    f.sslr.sslrHit[i][k] = glm::unpackHalf1x16(h[i * 4 + k]);
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
        f.source = transfers_.get<glm::u8vec4>(source);
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
    uint32_t count(uint32_t cls, uint32_t source) const {
        const auto it = classSource.find({cls, source});
        return it == classSource.end() ? 0u : it->second;
    }
};

Coverage checkFrame(const Frame& f, const Traces& t, const Presence& present, const shader::SceneLighting& lighting,
                    float threshold = 0.9f) {
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

void checkCounters(const Frame& f, const Traces& t, const std::vector<uint32_t>& carried, float threshold = 0.9f) {
    for (uint32_t ty = 0; ty < kTiles; ++ty) {
        for (uint32_t tx = 0; tx < kTiles; ++tx) {
            INFO("tile " << tx << ", " << ty);
            const glm::uvec2 counts = tileCounts(f, t, threshold, tx, ty);
            const uint32_t tile = ty * kTiles + tx;
            CHECK(f.counters[tile] == shader::rotateFeedback(carried[tile], counts.x, counts.y));
        }
    }
}

} // namespace

// ---------------------------------------------------------------------------
// CPU: the shared header
// ---------------------------------------------------------------------------

TEST_CASE("feedback counters pack four 8-bit counts and saturate at 255") {
    const uint32_t c = shader::packFeedback(1, 2, 3, 4);
    CHECK(c == 0x04030201u);
    CHECK(shader::feedbackHits(c) == 1u);
    CHECK(shader::feedbackMisses(c) == 2u);
    CHECK(shader::feedbackPreviousHits(c) == 3u);
    CHECK(shader::feedbackPreviousMisses(c) == 4u);
    const uint32_t s = shader::packFeedback(300, 255, 1000, 64);
    CHECK(shader::feedbackHits(s) == 255u);
    CHECK(shader::feedbackMisses(s) == 255u);
    CHECK(shader::feedbackPreviousHits(s) == 255u);
    CHECK(shader::feedbackPreviousMisses(s) == 64u);
    // A tile of 8x8 pixels never saturates in one frame.
    CHECK(shader::kTileSize * shader::kTileSize <= shader::kFeedbackCountMax);
}

TEST_CASE("rotating a counter moves this frame's counts behind the new ones and drops the oldest") {
    const uint32_t lastFrame = shader::packFeedback(10, 20, 30, 40);
    const uint32_t next = shader::rotateFeedback(lastFrame, 5, 6);
    CHECK(next == shader::packFeedback(5, 6, 10, 20));
    // Two rotations forget the first frame entirely.
    CHECK(shader::rotateFeedback(next, 0, 0) == shader::packFeedback(0, 0, 5, 6));
}

TEST_CASE("tile modes: no evidence is hybrid, only hits SSLR, only misses RT, mixed hybrid") {
    using shader::decideTileMode;
    using shader::packFeedback;
    CHECK(decideTileMode(0u, 1, 0.0f, 0.0f) == shader::kTileModeHybrid);
    CHECK(decideTileMode(packFeedback(5, 0, 0, 0), 1, 0.0f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(0, 0, 7, 0), 1, 0.0f, 0.0f) == shader::kTileModeSslr);  // last frame only
    CHECK(decideTileMode(packFeedback(3, 0, 4, 0), 1, 0.0f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(0, 6, 0, 2), 1, 0.0f, 0.0f) == shader::kTileModeRt);
    CHECK(decideTileMode(packFeedback(0, 0, 0, 1), 1, 0.0f, 0.0f) == shader::kTileModeRt);
    CHECK(decideTileMode(packFeedback(4, 1, 0, 0), 1, 0.0f, 0.0f) == shader::kTileModeHybrid);
    // Mixed across the two frames is mixed.
    CHECK(decideTileMode(packFeedback(3, 0, 0, 2), 1, 0.0f, 0.0f) == shader::kTileModeHybrid);
    // The knobs: too few rays is no evidence; a tolerated stray ray.
    CHECK(decideTileMode(packFeedback(2, 0, 1, 0), 4, 0.0f, 0.0f) == shader::kTileModeHybrid);
    CHECK(decideTileMode(packFeedback(2, 0, 2, 0), 4, 0.0f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(19, 1, 0, 0), 1, 0.05f, 0.0f) == shader::kTileModeSslr);
    CHECK(decideTileMode(packFeedback(18, 2, 0, 0), 1, 0.05f, 0.0f) == shader::kTileModeHybrid);
    CHECK(decideTileMode(packFeedback(1, 19, 0, 0), 1, 0.0f, 0.05f) == shader::kTileModeRt);
}

TEST_CASE("the feedback probe pixel lies in its tile and the image, and moves from frame to frame") {
    const glm::uvec2 size(61, 37);  // partial tiles at the right and bottom
    const glm::uvec2 tiles((size + shader::kTileSize - 1u) / shader::kTileSize);
    for (uint32_t ty = 0; ty < tiles.y; ++ty) {
        for (uint32_t tx = 0; tx < tiles.x; ++tx) {
            std::map<uint32_t, int> seen;
            for (uint32_t frame = 0; frame < 64; ++frame) {
                const glm::uvec2 p = shader::feedbackProbePixel({tx, ty}, frame, size);
                REQUIRE(p.x / shader::kTileSize == tx);
                REQUIRE(p.y / shader::kTileSize == ty);
                REQUIRE(p.x < size.x);
                REQUIRE(p.y < size.y);
                ++seen[p.y * size.x + p.x];
            }
            CHECK(seen.size() > 1);
        }
    }
}

// ---------------------------------------------------------------------------
// GPU: integrate
// ---------------------------------------------------------------------------

TEST_CASE("integrate takes each pixel's reflection from the source its class and confidences call for") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(0, false);
    const Presence all;
    const Frame f = harness.run(testCamera(), 0, traces, all);
    const Coverage cov = checkFrame(f, traces, all, harness.lighting());
    // The first frame carries nothing: the counters hold this frame's counts.
    checkCounters(f, traces, std::vector<uint32_t>(kTiles * kTiles, 0u));
    CHECK(f.reprojected == std::vector<uint32_t>(kTiles * kTiles, 0u));

    // The scene exercised every rule.
    using namespace shader;
    CHECK(cov.count(kPixelSky, kSourceSky) > 0);
    CHECK(cov.count(kPixelEnv, kSourceEnvironment) > 0);
    CHECK(cov.count(kPixelSslr, kSourceSslr) > 0);
    CHECK(cov.count(kPixelSslr, kSourceFallback) > 0);
    CHECK(cov.count(kPixelSslr, kSourceRt) == 0);  // beyond the BVH: RT never answers
    CHECK(cov.count(kPixelHybrid, kSourceSslr) > 0);
    CHECK(cov.count(kPixelHybrid, kSourceRt) > 0);
    CHECK(cov.count(kPixelHybrid, kSourceFallback) > 0);
    CHECK(cov.count(kPixelRt, kSourceRt) > 0);
    CHECK(cov.count(kPixelRt, kSourceFallback) > 0);
    CHECK(cov.count(kPixelRt, kSourceSslr) == 0);
    CHECK(cov.followers > 50);
    CHECK(cov.followerSslr > 0);
    CHECK(cov.followerRt > 0);
    CHECK(cov.sslrHitDistances > 50);
}

TEST_CASE("integrate lets no NaN or Inf from the traces through; poisoned traces count as misses") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(1, true);
    const Presence all;
    const Frame f = harness.run(testCamera(), 1, traces, all);
    checkFrame(f, traces, all, harness.lighting());
    checkCounters(f, traces, std::vector<uint32_t>(kTiles * kTiles, 0u));
}

TEST_CASE("integrate without RT, without SSLR, without either and without feedback binds only what exists") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(2, false);
    uint64_t frame = 0;
    for (const Presence present : {Presence{true, false, true}, Presence{false, true, true},
                                   Presence{false, false, true}, Presence{true, true, false},
                                   Presence{false, true, false}}) {
        INFO("sslr " << present.sslr << " rt " << present.rt << " feedback " << present.feedback);
        const Frame f = harness.run(testCamera(), frame++, traces, present);
        const Coverage cov = checkFrame(f, traces, present, harness.lighting());
        if (!present.rt) CHECK(cov.count(shader::kPixelRt, shader::kSourceRt) == 0);
        if (!present.sslr) CHECK(cov.count(shader::kPixelHybrid, shader::kSourceSslr) == 0);
        if (present.feedback && !present.sslr) {
            // No SSLR, no counts; the carried counts still rotate.
            for (uint32_t tile = 0; tile < kTiles * kTiles; ++tile) {
                CHECK(f.counters[tile] == shader::rotateFeedback(f.reprojected[tile], 0, 0));
            }
        }
    }
}

TEST_CASE("a lower confidence threshold trusts SSLR alone more often") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Traces traces = makeTraces(0, false);
    const Presence noFeedback{true, true, false};
    // The same frame index twice: the same classes and rays.
    const Frame strict = harness.run(testCamera(), 0, traces, noFeedback);
    const Coverage strictCov = checkFrame(strict, traces, noFeedback, harness.lighting());
    const Presence all;
    const Frame lax = harness.run(testCamera(), 0, traces, all, {.confidenceThreshold = 0.4f});
    REQUIRE(lax.classes == strict.classes);
    const Coverage laxCov = checkFrame(lax, traces, all, harness.lighting(), 0.4f);
    // The counters count a hit at the same threshold (the first feedback
    // frame: nothing carried).
    checkCounters(lax, traces, std::vector<uint32_t>(kTiles * kTiles, 0u), 0.4f);
    // Hybrid pixels at confidence 0.5 now keep SSLR instead of going to RT.
    CHECK(laxCov.count(shader::kPixelHybrid, shader::kSourceSslr) >
          strictCov.count(shader::kPixelHybrid, shader::kSourceSslr));
    CHECK(laxCov.count(shader::kPixelHybrid, shader::kSourceRt) <
          strictCov.count(shader::kPixelHybrid, shader::kSourceRt));
}

TEST_CASE("behind the real SSLR pass, confident wall hits are SSLR with the wall's distance from the floor") {
    test::GpuTest gpu;
    Harness harness(gpu, mirrorWallScene());
    passes::SslrPipelines sslrPipelines(gpu.ctx());
    RunOptions options;
    options.realSslr = &sslrPipelines;
    options.rays.rtMaxDistance = 0.0f;  // every floor pixel hybrid
    options.sslrMinDistance = 1e9f;
    const Traces none = makeTraces(0, false);  // RT absent: only the SSLR fields matter, and those are replaced
    const Presence ssr{true, false, true};
    const Frame f = harness.run(testCamera(), 4, none, ssr, options);
    uint32_t checked = 0;
    for (uint32_t y = kSize / 2; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const size_t i = at(x, y);
            if (f.classes[i] != shader::kPixelHybrid) continue;
            INFO("pixel " << x << ", " << y);
            const shader::PackedRay& ray = f.rays[i];
            const glm::uvec2 leader = shader::unpackRayPixel(ray.pixelFlags);
            const size_t li = at(leader.x, leader.y);
            const float confidence = f.sslr.sslrConfidence[li];
            REQUIRE(finite(f.radiance[i]));
            REQUIRE(std::isfinite(f.hitDistance[i]));
            if (confidence < 0.9f) continue;
            REQUIRE(f.source[i] == sourceColour(shader::kSourceSslr));
            REQUIRE(glm::vec3(f.radiance[i]) == glm::vec3(f.sslr.sslrRadiance[li]));
            // The wall point at the hit texel's centre (the wall is the
            // plane z = -6), measured from this pixel's floor point...
            const glm::vec2 uv(f.sslr.sslrHit[li]);
            const glm::vec2 texel = glm::floor(uv * float(kSize)) + 0.5f;
            const glm::vec2 ndc = texel / float(kSize) * 2.0f - 1.0f;
            const glm::vec3 wall(ndc.x * kMirrorWallDistance, -ndc.y * kMirrorWallDistance, -kMirrorWallDistance);
            const float expected = glm::length(wall - floorPoint(x, y));
            REQUIRE(std::abs(f.hitDistance[i] - expected) <= 1e-3f * expected);
            // ... which is the mirror path's length to within the texel's
            // footprint on the wall (6 / 32 units).
            const glm::vec3 p = floorPoint(x, y);
            const glm::vec3 d = glm::normalize(p);
            const glm::vec3 mirrored(d.x, -d.y, d.z);
            const float analytic = (-kMirrorWallDistance - p.z) / mirrored.z;
            const float footprint = 2.0f * kMirrorWallDistance / float(kSize);
            REQUIRE(std::abs(f.hitDistance[i] - analytic) <= footprint + 0.02f * analytic);
            ++checked;
        }
    }
    CHECK(checked > 200);
    checkCounters(f, f.sslr, f.reprojected);
    uint32_t hits = 0;
    for (const uint32_t c : f.counters) hits += shader::feedbackHits(c);
    CHECK(hits > 50);
}

// ---------------------------------------------------------------------------
// GPU: feedback
// ---------------------------------------------------------------------------

TEST_CASE("two frames rotate the counters through the history: last frame's counts move behind this frame's") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Presence all;
    const scene::Camera camera = testCamera();  // still: every tile carries its own counter
    const Traces first = makeTraces(0, false);
    const Frame f0 = harness.run(camera, 0, first, all, {.followTileModes = true});
    checkCounters(f0, first, std::vector<uint32_t>(kTiles * kTiles, 0u));
    const Traces second = makeTraces(3, false);
    const Frame f1 = harness.run(camera, 1, second, all, {.followTileModes = true});
    CHECK(f1.reprojected == f0.counters);
    checkCounters(f1, second, f0.counters);
    checkFrame(f1, second, all, harness.lighting());
    // And the modes of frame 1 follow frame 0's two frames of counts.
    uint32_t previousHalves = 0;
    for (uint32_t tile = 0; tile < kTiles * kTiles; ++tile) {
        CHECK(f1.tileModes[tile] == shader::decideTileMode(f0.counters[tile], 1, 0.0f, 0.0f));
        const uint32_t c = f1.counters[tile];
        previousHalves += shader::feedbackPreviousHits(c) + shader::feedbackPreviousMisses(c);
    }
    CHECK(previousHalves > 0);
}

TEST_CASE("a known camera motion carries each tile's counter from where its content was; off screen gives 0") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    std::vector<uint32_t> counters(kTiles * kTiles);
    for (uint32_t tile = 0; tile < counters.size(); ++tile) {
        counters[tile] = shader::packFeedback(tile % kTiles, tile / kTiles, 7, tile + 1);
    }
    scene::Camera camera = testCamera();
    harness.runFeedback(camera, 0, counters);
    // Up 1 and right 2: at the wall's distance 4 a world unit is 8 pixels,
    // one tile, so last frame the content of tile (tx, ty) was in tile
    // (tx + 2, ty - 1) whichever pixel of the tile is probed.
    const glm::vec3 moved(2.0f, 1.0f, 0.0f);
    camera.advance({moved, moved + glm::vec3(0, 0, -1), {0, 1, 0}}, 1);
    const auto f = harness.runFeedback(camera, 1, counters);
    for (uint32_t y = 0; y < kSize; y += 5) {
        for (uint32_t x = 0; x < kSize; x += 3) {
            INFO("pixel " << x << ", " << y);
            REQUIRE(std::abs(f.motion[at(x, y)].x - 16.0f) < 1e-2f);
            REQUIRE(std::abs(f.motion[at(x, y)].y + 8.0f) < 1e-2f);
        }
    }
    for (uint32_t ty = 0; ty < kTiles; ++ty) {
        for (uint32_t tx = 0; tx < kTiles; ++tx) {
            INFO("tile " << tx << ", " << ty);
            const bool onScreen = tx + 2 < kTiles && ty >= 1;
            const uint32_t expected = onScreen ? counters[(ty - 1) * kTiles + tx + 2] : 0u;
            CHECK(f.reprojected[ty * kTiles + tx] == expected);
            CHECK(f.tileModes[ty * kTiles + tx] == shader::decideTileMode(expected, 1, 0.0f, 0.0f));
        }
    }
    // The camera stays where it moved: no motion, every tile keeps its own.
    camera.advance({moved, moved + glm::vec3(0, 0, -1), {0, 1, 0}}, 2);
    CHECK(harness.runFeedback(camera, 2, counters).reprojected == counters);
    // A reset (a camera cut) carries nothing: every tile without evidence,
    // hybrid.
    camera.advance({moved, moved + glm::vec3(0, 0, -1), {0, 1, 0}}, 3);
    const auto cut = harness.runFeedback(camera, 3, counters, {}, true);
    CHECK(cut.reprojected == std::vector<uint32_t>(counters.size(), 0u));
    CHECK(cut.tileModes == std::vector<uint32_t>(counters.size(), shader::kTileModeHybrid));
}

TEST_CASE("tile modes follow the carried counts and the feedback settings") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    using shader::packFeedback;
    const std::array<uint32_t, 9> cases = {0u,
                                           packFeedback(5, 0, 0, 0),
                                           packFeedback(3, 0, 4, 0),
                                           packFeedback(0, 6, 0, 2),
                                           packFeedback(4, 1, 0, 0),
                                           packFeedback(3, 0, 0, 2),
                                           packFeedback(0, 0, 7, 0),
                                           packFeedback(19, 1, 0, 0),
                                           packFeedback(1, 19, 0, 0)};
    std::vector<uint32_t> counters(kTiles * kTiles);
    for (uint32_t tile = 0; tile < counters.size(); ++tile) counters[tile] = cases[(tile * 5) % cases.size()];
    const scene::Camera camera = testCamera();
    harness.runFeedback(camera, 0, counters);
    passes::FeedbackSettings strict;
    passes::FeedbackSettings tolerant;
    tolerant.minRays = 6;
    tolerant.sslrMissFraction = 0.05f;
    tolerant.rtHitFraction = 0.05f;
    passes::FeedbackSettings off;
    off.adaptive = false;
    uint64_t frame = 1;
    for (const passes::FeedbackSettings& settings : {strict, tolerant, off}) {
        const auto f = harness.runFeedback(camera, frame++, counters, settings);
        CHECK(f.reprojected == counters);
        std::map<uint32_t, int> modes;
        for (uint32_t tile = 0; tile < counters.size(); ++tile) {
            INFO("tile " << tile << " counter " << counters[tile] << " minRays " << settings.minRays);
            const uint32_t expected =
                settings.adaptive ? shader::decideTileMode(counters[tile], settings.minRays,
                                                           settings.sslrMissFraction, settings.rtHitFraction)
                                  : shader::kTileModeHybrid;
            CHECK(f.tileModes[tile] == expected);
            ++modes[f.tileModes[tile]];
        }
        if (settings.adaptive) {
            CHECK(modes.size() == 3);  // every mode occurs
        } else {
            CHECK(modes.size() == 1);
        }
    }
}

TEST_CASE("SSLR probe frames: one per block of the interval, on both parities, at most 2 x interval - 1 apart") {
    for (const uint32_t interval : {2u, 8u, 13u}) {
        INFO("interval " << interval);
        std::optional<uint32_t> last;
        std::array<uint32_t, 2> parity{};
        std::set<uint32_t> offsets;
        for (uint32_t block = 0; block < 200; ++block) {
            uint32_t probes = 0;
            for (uint32_t k = 0; k < interval; ++k) {
                const uint32_t frame = block * interval + k;
                if (!shader::feedbackProbeFrame(frame, interval)) continue;
                ++probes;
                ++parity[frame % 2];
                offsets.insert(k);
                if (last) CHECK(frame - *last <= 2 * interval - 1);
                last = frame;
            }
            CHECK(probes == 1);
        }
        // Not tied to the frame's parity (the samples time alternate
        // frames) nor to one place in the block.
        CHECK(parity[0] > 20);
        CHECK(parity[1] > 20);
        CHECK(offsets.size() == interval);
    }
    for (uint32_t frame = 0; frame < 16; ++frame) CHECK(shader::feedbackProbeFrame(frame, 1));
}

TEST_CASE("SSLR pays with enough of last frame's hits, on probe frames, and without evidence") {
    const uint32_t start = shader::kFeedbackFrameHitsStart;
    CHECK(shader::sslrPays(0u, 100u, false, false));  // a new pair: no frame wrote the word
    CHECK(!shader::sslrPays(start + 99u, 100u, false, false));
    CHECK(shader::sslrPays(start + 100u, 100u, false, false));
    CHECK(shader::sslrPays(start, 100u, true, false));   // a probe frame
    CHECK(shader::sslrPays(start, 100u, false, true));   // a reset
    CHECK(shader::sslrPays(start, 0u, false, false));    // the gate off
}

TEST_CASE("a frame after one whose SSLR hits fell short sends every tile RT-only, except on probe frames") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    const scene::Camera camera = testCamera();  // still: every tile carries its own counter
    // Every tile's own counts say SSLR; only the frame's sum decides.
    const std::vector<uint32_t> tiles(kTiles * kTiles, shader::packFeedback(5, 0, 0, 0));
    const passes::FeedbackSettings settings;
    const uint32_t minHits = uint32_t(std::ceil(double(settings.sslrMinHitShare) * kSize * kSize));
    REQUIRE(minHits > 1);
    const auto withHits = [&](uint32_t hits) {
        std::vector<uint32_t> c = tiles;
        c.push_back(shader::kFeedbackFrameHitsStart + hits);
        return c;
    };
    std::vector<uint64_t> probes, others;
    for (uint64_t frame = 1; probes.size() < 2 || others.size() < 6; ++frame) {
        (shader::feedbackProbeFrame(uint32_t(frame), settings.sslrProbeInterval) ? probes : others).push_back(frame);
    }
    const auto all = [&](uint32_t mode) { return std::vector<uint32_t>(tiles.size(), mode); };
    // Each call's modes follow what the call before it left as last frame's counters.
    harness.runFeedback(camera, 0, withHits(minHits - 1), settings);
    CHECK(harness.runFeedback(camera, others[0], withHits(minHits), settings).tileModes ==
          all(shader::kTileModeRtOnly));
    CHECK(harness.runFeedback(camera, others[1], withHits(minHits - 1), settings).tileModes ==
          all(shader::kTileModeSslr));
    CHECK(harness.runFeedback(camera, probes[0], withHits(0), settings).tileModes == all(shader::kTileModeSslr));
    CHECK(harness.runFeedback(camera, others[2], withHits(minHits - 1), settings).tileModes ==
          all(shader::kTileModeRtOnly));
    // A reset carries no counters and no evidence: hybrid, not RT.
    CHECK(harness.runFeedback(camera, others[3], withHits(minHits - 1), settings, true).tileModes ==
          all(shader::kTileModeHybrid));
    // The gate off (share 0), and the feedback off.
    passes::FeedbackSettings always = settings;
    always.sslrMinHitShare = 0.0f;
    CHECK(harness.runFeedback(camera, others[4], withHits(minHits - 1), always).tileModes ==
          all(shader::kTileModeSslr));
    passes::FeedbackSettings off = settings;
    off.adaptive = false;
    CHECK(harness.runFeedback(camera, others[5], withHits(0), off).tileModes == all(shader::kTileModeHybrid));
}

TEST_CASE("integrate sums the frame's SSLR hits after the tiles' counters, up to what decides") {
    test::GpuTest gpu;
    Harness harness(gpu, floorScene());
    const Presence all;
    const scene::Camera camera = testCamera();
    const Traces traces = makeTraces(0, false);
    const auto hitsOf = [](const Frame& f) {
        uint32_t hits = 0;
        for (const uint32_t c : f.counters) hits += shader::feedbackHits(c);
        return hits;
    };
    // A share of 1 decides only at every pixel: the whole sum.
    RunOptions whole;
    whole.feedback.sslrMinHitShare = 1.0f;
    const Frame f = harness.run(camera, 0, traces, all, whole);
    const uint32_t hits = hitsOf(f);
    REQUIRE(hits > 50);
    CHECK(f.frameHitsWord == shader::kFeedbackFrameHitsStart + hits);
    // A small share: the tiles stop adding once the sum decides (the
    // atomics of tiles already past the test still land).
    RunOptions small;
    small.feedback.sslrMinHitShare = 10.0f / float(kSize * kSize);
    const Frame g = harness.run(camera, 1, traces, all, small);
    CHECK(g.frameHitsWord >= shader::kFeedbackFrameHitsStart + 10);
    CHECK(g.frameHitsWord <= shader::kFeedbackFrameHitsStart + hitsOf(g));
    // The gate off: the word stays where the feedback pass started it.
    RunOptions off;
    off.feedback.sslrMinHitShare = 0.0f;
    CHECK(harness.run(camera, 2, traces, all, off).frameHitsWord == shader::kFeedbackFrameHitsStart);
}

TEST_CASE("feedback refuses hit and miss fractions outside [0, 1]") {
    test::GpuTest gpu;
    Harness harness(gpu, wallScene());
    const std::vector<uint32_t> counters(kTiles * kTiles, 0u);
    passes::FeedbackSettings settings;
    settings.rtHitFraction = 1.5f;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("rtHitFraction must lie in [0, 1]"), gpu::GpuError);
    settings.rtHitFraction = 0.0f;
    settings.sslrMissFraction = -0.1f;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("(got -0.1"), gpu::GpuError);
    settings.sslrMissFraction = 0.0f;
    settings.sslrMinHitShare = 2.0f;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("sslrMinHitShare must lie in [0, 1]"), gpu::GpuError);
    settings.sslrMinHitShare = 0.02f;
    settings.sslrProbeInterval = 0;
    CHECK_THROWS_WITH_AS(harness.runFeedback(testCamera(), 0, counters, settings),
                         doctest::Contains("sslrProbeInterval be at least 1"), gpu::GpuError);
}

TEST_CASE("integrate refuses an RT radiance without its hit distance") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    passes::IntegratePipelines pipelines(ctx);
    rg::Graph graph;
    passes::IntegrateInputs in;
    in.gbuffer.width = in.gbuffer.height = kSize;
    in.rays.width = in.rays.height = kSize;
    in.rtRadiance =
        graph.createTexture("rt", {.width = kSize, .height = kSize, .format = VK_FORMAT_R16G16B16A16_SFLOAT});
    CHECK_THROWS_WITH_AS(passes::addIntegratePass(graph, pipelines, in), doctest::Contains("hit distance"),
                         gpu::GpuError);
}
