// Particles in the reflections (passes/particles.h, the particle TLAS of
// passes/bvh_update.h) on a real device, validation on, behind the real
// G-buffer, BVH update, ray generation, SSLR, ray tracer and integrate.
// The scene: a mirror floor at y = -1, a wall at z = -6 that the floor
// reflects, particle A floating in front of the wall (so the floor's
// reflection shows it) and particle B behind the wall (its reflection
// would show on the floor but the wall hides it). The camera looks down -Z
// from the origin. A CPU reference intersects each floor pixel's mirror ray
// with the quad of A that the ray sees (the one facing the camera axis the
// ray's direction is largest along) and evaluates the coverage the shaders
// evaluate (glint/particles_shared.h). A second scene looks down at a
// mirror floor at 42 degrees, so that the floor reflects rays at 84 degrees
// to the view: they meet a camera-facing quad nearly edge-on.
#include "support/gpu_test.h"
#include "support/pass_test_scene.h"

#include "glint/gpu/error.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/graph/transfer.h"
#include "glint/graph/verify.h"
#include "glint/passes/bvh_update.h"
#include "glint/passes/gbuffer.h"
#include "glint/passes/integrate.h"
#include "glint/passes/lighting.h"
#include "glint/passes/particles.h"
#include "glint/passes/ray_generation.h"
#include "glint/passes/rt_trace.h"
#include "glint/passes/sslr.h"
#include "glint/scene/animation.h"
#include "glint/scene/builtin_scenes.h"
#include "glint/scene/bvh_planner.h"

#include "glint/particles_shared.h"
#include "glint/ray_generation_shared.h"

#include <glm/gtc/packing.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

using namespace glint;

namespace {

constexpr uint32_t kSize = test::kPassTestSize;
constexpr size_t kPixels = size_t(kSize) * kSize;
using test::square;

constexpr float kFloorY = -1.0f;
constexpr float kWallZ = -6.0f;
// A: in front of the wall, reflected by the floor around pixel (32, 44).
const scene::Particle kParticleA{{0.0f, -0.4f, -4.0f}, 0.5f, {1.0f, 0.5f, 0.25f, 0.8f}};
// B: behind the wall; the floor around pixel (38, 42) would reflect it,
// but its reflected rays meet the wall mid-height first (on screen, so
// SSLR finds the wall too).
const scene::Particle kParticleB{{1.5f, 0.5f, -8.0f}, 0.5f, {0.2f, 0.4f, 1.0f, 0.9f}};

scene::Scene mirrorScene(bool withParticles) {
    scene::Scene s;
    s.name = "particles-test";
    scene::Material mirror;
    mirror.baseColorFactor = {0.9f, 0.9f, 0.9f, 1.0f};
    mirror.metallicFactor = 1.0f;
    mirror.roughnessFactor = 0.0f;
    scene::Material wall;
    wall.baseColorFactor = {0.5f, 0.5f, 0.5f, 1.0f};
    wall.metallicFactor = 0.0f;
    wall.roughnessFactor = 1.0f;  // rougher than the cutoff: no rays leave it
    s.materials = {mirror, wall};
    scene::Mesh floor;
    floor.name = "floor";
    floor.lods.push_back({{square({0, kFloorY, -8}, {1, 0, 0}, {0, 0, -1}, 8.0f, 0)}});
    scene::Mesh wallMesh;
    wallMesh.name = "wall";
    wallMesh.lods.push_back({{square({0, 3, kWallZ}, {1, 0, 0}, {0, 1, 0}, 4.0f, 1)}});
    s.meshes = {floor, wallMesh};
    scene::Instance a;
    a.name = "floor";
    a.mesh = 0;
    scene::Instance b;
    b.name = "wall";
    b.mesh = 1;
    s.instances = {a, b};
    if (withParticles) {
        s.particles = {kParticleA, kParticleB};
    }
    scene::prepareScene(s);
    return s;
}

// The edge-on scene: the camera 2 above the floor looks down at 42
// degrees, so the floor's mirror rays leave it at 84 degrees to the view
// direction; particle C floats on the mirror ray of the image's centre,
// 2 units from the floor.
constexpr float kEdgeOnPitch = glm::radians(44.0f);
const glm::vec3 kEdgeOnEye{0.0f, kFloorY + 2.0f, 0.0f};

scene::Camera edgeOnCamera() {
    scene::Camera camera = test::testCamera();
    const glm::vec3 forward(0.0f, -std::sin(kEdgeOnPitch), -std::cos(kEdgeOnPitch));
    camera.reset({kEdgeOnEye, kEdgeOnEye + forward, {0, 1, 0}}, 0);
    return camera;
}

scene::Particle edgeOnParticle() {
    const glm::vec3 forward(0.0f, -std::sin(kEdgeOnPitch), -std::cos(kEdgeOnPitch));
    const glm::vec3 floorPoint = kEdgeOnEye + ((kFloorY - kEdgeOnEye.y) / forward.y) * forward;
    const glm::vec3 mirror = glm::reflect(forward, glm::vec3(0, 1, 0));
    return {floorPoint + 2.0f * mirror, 0.65f, {0.3f, 1.0f, 0.4f, 0.9f}};
}

scene::Scene edgeOnScene() {
    scene::Scene s = mirrorScene(false);
    s.instances.resize(1);  // the floor alone
    s.particles = {edgeOnParticle()};
    scene::prepareScene(s);
    return s;
}

size_t pixelIndex(uint32_t x, uint32_t y) { return size_t(y) * kSize + x; }

// The floor point seen at pixel (x, y) and the CPU's expected particle
// coverage and radiance along its mirror ray (A only: B is behind the wall).
struct Expected {
    bool floor = false;
    glm::vec4 particles{0.0f};
};

// Which of a particle's quads a ray meets (glint/particles_shared.h).
enum class Quads { ByRayAxis, BillboardOnly };

// Premultiplied colour and coverage of `particle` along the ray from `p`
// in direction `r`, through the quad `quads` picks: the plane through its
// centre facing that camera axis.
glm::vec4 particleAlong(const scene::Camera& camera, const scene::Particle& particle, glm::vec3 p, glm::vec3 r,
                        Quads quads) {
    const shader::ParticleBillboardParams basis = passes::particleBasis(camera.view);
    const glm::vec3 axes[shader::kParticleQuadAxes] = {basis.right, basis.up, basis.back};
    const uint32_t axis = quads == Quads::BillboardOnly
                              ? shader::kParticleAxisBack
                              : shader::particleQuadAxis(glm::vec3(glm::dot(r, basis.right), glm::dot(r, basis.up),
                                                                   glm::dot(r, basis.back)));
    const glm::vec3 normal = axes[axis];
    const float facing = glm::dot(r, normal);
    if (std::abs(facing) < 1e-6f) return glm::vec4(0.0f);
    const float t = glm::dot(particle.position - p, normal) / facing;
    if (t <= 0.0f) return glm::vec4(0.0f);
    const shader::ParticleData data{particle.position, particle.radius, particle.color};
    const float coverage = shader::particleCoverageAt(data, p + t * r);
    return glm::vec4(glm::vec3(particle.color) * coverage, coverage);
}

// The floor point (y = kFloorY, in front of `wallZ`) seen at pixel (x, y)
// and its mirror ray; false where the pixel sees no floor.
bool floorRay(const scene::Camera& camera, uint32_t x, uint32_t y, float wallZ, glm::vec3& p, glm::vec3& r) {
    const glm::mat4 inv = glm::inverse(camera.viewProjection());
    const glm::vec2 ndc = test::pixelNdc(x, y);
    const glm::vec4 a = inv * glm::vec4(ndc, 1.0f, 1.0f);
    const glm::vec4 b = inv * glm::vec4(ndc, 0.5f, 1.0f);
    const glm::vec3 origin = glm::vec3(a) / a.w;
    const glm::vec3 dir = glm::normalize(glm::vec3(b) / b.w - origin);
    if (dir.y >= -1e-4f) return false;
    const float s = (kFloorY - origin.y) / dir.y;
    p = origin + s * dir;
    if (p.z < wallZ || std::abs(p.x) > 8.0f) return false;
    r = glm::reflect(dir, glm::vec3(0, 1, 0));
    return true;
}

Expected expectedAt(const scene::Camera& camera, uint32_t x, uint32_t y) {
    Expected e;
    glm::vec3 p, r;
    if (!floorRay(camera, x, y, kWallZ, p, r)) return e;
    e.floor = true;
    e.particles = particleAlong(camera, kParticleA, p, r, Quads::ByRayAxis);
    return e;
}

// ---------------------------------------------------------------------------
// One frame of the reflection passes with the particle trace
// ---------------------------------------------------------------------------

struct Frame {
    std::vector<glm::vec4> particles;           // the trace's output
    std::vector<std::array<uint16_t, 4>> particleBits;
    std::vector<glm::vec4> untraced;            // the trace with no traces bound (every reflection a miss)
    std::vector<glm::vec4> reflection;          // integrate with particles
    std::vector<glm::vec4> reflectionAlone;     // integrate without
    std::vector<glm::vec4> litBefore, litAfter;  // around the forward pass
    passes::BvhGpuStats bvh;
    bool traced = false;
    uint32_t forwardDrawn = 0, forwardCulled = 0;  // by the forward pass
};

class Rig {
public:
    Rig(gpu::Context& ctx, scene::Scene s, scene::Camera camera = test::testCamera())
        : ctx_(ctx),
          scene_(std::move(s)),
          camera_(std::move(camera)),
          executor_(ctx),
          renderer_(ctx, scene_),
          bvh_(ctx, scene_),
          rays_(ctx),
          sslr_(ctx),
          rt_(ctx),
          integrate_(ctx),
          particles_(ctx) {
        for (uint32_t slot = 0; slot < kReadbacks; ++slot) {
            readbacks_.emplace_back(ctx, kPixels * 8, "particles_test.readback" + std::to_string(slot));
        }
    }

    const scene::Camera& camera() const { return camera_; }
    passes::ParticlePipelines& particles() { return particles_; }

    // sslrParticles: the forward pass draws the particles into the lit
    // colour before SSLR, and the trace skips what SSLR resolves (the Far
    // Cry 6 talk's SSLR particles, passes/particles.h). noiseFrame: the
    // frame the rays' noise is drawn for (0: this run's own), so that two
    // runs can trace the same rays.
    Frame run(passes::ReflectionMode mode, passes::RtBackend backend, bool sslrParticles = false,
              uint64_t noiseFrame = 0) {
        // A backend switch changes the trace's shader stages; the graph
        // orders frames as if they ran the same plan (passes/rt_trace.h).
        ctx_.waitIdle();
        rg::Graph graph(executor_.queueCaps());
        rg::FrameResources resources;
        const scene::BvhPlan plan = planner_.plan(scene_, camera_.position, frame_++);
        const uint64_t noise = noiseFrame != 0 ? noiseFrame : frame_;
        const passes::BvhUpdateOutputs bvh = passes::addBvhUpdatePass(graph, bvh_, plan, camera_);
        bvh_.bind(resources, bvh);
        passes::GBufferOutputs gbuf = passes::addGBufferPass(graph, renderer_, {camera_});
        if (sslrParticles) {
            gbuf.lit = passes::addParticleForwardPass(graph, particles_, {gbuf, scene_.particles, camera_}).lit;
        }
        const passes::RayGenerationOutputs rays =
            passes::addRayGenerationPass(graph, rays_, {gbuf, noise, camera_, {}, mode}, {});
        std::optional<passes::SslrOutputs> sslr;
        if (mode != passes::ReflectionMode::Rt) {
            sslr = passes::addSslrPass(graph, sslr_, {gbuf, rays, noise, camera_.view, camera_.projection});
        }
        std::optional<passes::RtTraceOutputs> rt;
        const shader::SceneLighting lighting = passes::sceneLighting(scene_);
        if (mode != passes::ReflectionMode::Ssr) {
            rt = passes::addRtTracePass(graph, rt_,
                                        {gbuf, sslr ? sslr->rtRayList : rays.rtRays, sslr ? sslr->rtArgs : rays.rtArgs,
                                         bvh, lighting, camera_, noise});
        }
        Frame f;
        f.traced = passes::particlesTraced(bvh);
        std::vector<std::pair<rg::Texture, std::vector<glm::vec4>*>> reads;
        passes::IntegrateInputs integrateInputs;
        integrateInputs.gbuffer = gbuf;
        integrateInputs.rays = rays;
        integrateInputs.sslr = sslr;
        if (rt) {
            integrateInputs.rtRadiance = rt->radiance;
            integrateInputs.rtHitDistance = rt->hitDistance;
        }
        integrateInputs.lighting = lighting;
        integrateInputs.camera = camera_;
        const passes::IntegrateOutputs alone = passes::addIntegratePass(graph, integrate_, integrateInputs);
        reads.push_back({alone.radiance, &f.reflectionAlone});
        rg::Texture particleRadiance;
        if (f.traced) {
            passes::ParticleTraceInputs in;
            in.gbuffer = gbuf;
            in.rays = rays;
            in.sslr = sslr;
            if (rt) {
                in.rtRadiance = rt->radiance;
                in.rtHitDistance = rt->hitDistance;
            }
            if (sslr) {
                in.rtRayList = sslr->rtRayList;
                in.rtArgs = sslr->rtArgs;
            }
            in.bvh = bvh;
            in.camera = camera_;
            passes::ParticleTraceSettings settings;
            settings.backend = backend;
            // The whole image is compared: texels no leader writes read 0.
            settings.clearUntraced = true;
            settings.sslrSeesParticles = sslrParticles && sslr.has_value();
            particleRadiance = passes::addParticleTracePass(graph, particles_, in, settings).radiance;
            reads.push_back({particleRadiance, &f.particles});
            // The same rays with no trace to end them: every reflection a
            // miss, so they reach past the wall.
            passes::ParticleTraceInputs unbounded = in;
            unbounded.sslr.reset();
            unbounded.rtRadiance = unbounded.rtHitDistance = rg::Texture{};
            const rg::Texture untraced = passes::addParticleTracePass(graph, particles_, unbounded, settings).radiance;
            reads.push_back({untraced, &f.untraced});
            integrateInputs.particles = particleRadiance;
            reads.push_back({passes::addIntegratePass(graph, integrate_, integrateInputs).radiance, &f.reflection});
        }
        // The lit colour before and after the forward pass.
        addReadback(graph, gbuf.lit, 0, resources);
        const passes::ParticleForwardOutputs forward =
            passes::addParticleForwardPass(graph, particles_, {gbuf, scene_.particles, camera_});
        addReadback(graph, forward.lit, 1, resources);
        f.forwardDrawn = forward.particles;
        f.forwardCulled = forward.culled;
        uint32_t slot = 2;
        for (const auto& [texture, target] : reads) addReadback(graph, texture, slot++, resources);

        const rg::Plan compiled = graph.compile(executor_.compileOptions());
        const auto report = rg::verify(compiled);
        REQUIRE_MESSAGE(report.ok(), report.text());
        executor_.run(compiled, resources);
        executor_.waitIdle();
        ctx_.waitIdle();

        f.litBefore = unpack(0);
        f.litAfter = unpack(1);
        slot = 2;
        for (const auto& [texture, target] : reads) {
            if (texture == particleRadiance) {
                f.particleBits.resize(kPixels);
                std::memcpy(f.particleBits.data(), readbacks_[slot].bytes().data(), kPixels * 8);
            }
            *target = unpack(slot++);
        }
        f.bvh = bvh_.stats();
        return f;
    }

private:
    std::vector<glm::vec4> unpack(uint32_t slot) const {
        std::vector<glm::vec4> out(kPixels);
        const auto* bits = reinterpret_cast<const uint16_t*>(readbacks_[slot].bytes().data());
        for (size_t i = 0; i < kPixels; ++i) {
            for (int c = 0; c < 4; ++c) out[i][c] = glm::unpackHalf1x16(bits[4 * i + c]);
        }
        return out;
    }

    // Copies an RGBA16F texture into readback slot `slot` inside the graph.
    void addReadback(rg::Graph& graph, rg::Texture texture, uint32_t slot, rg::FrameResources& resources) {
        REQUIRE(slot < readbacks_.size());
        readbacks_[slot].copy(graph, resources, texture);
    }

    gpu::Context& ctx_;
    scene::Scene scene_;
    scene::Camera camera_;
    rg::Executor executor_;
    passes::GBufferRenderer renderer_;
    passes::BvhManager bvh_;
    scene::BvhPlanner planner_;
    passes::RayGenerationPipelines rays_;
    passes::SslrPipelines sslr_;
    passes::RtTracePipelines rt_;
    passes::IntegratePipelines integrate_;
    passes::ParticlePipelines particles_;
    static constexpr uint32_t kReadbacks = 8;
    std::vector<rg::HostReadback> readbacks_;
    uint64_t frame_ = 1;
};

std::vector<passes::RtBackend> availableBackends(const gpu::Context& ctx) {
    std::vector<passes::RtBackend> out;
    for (const passes::RtBackend b : {passes::RtBackend::RayQuery, passes::RtBackend::Pipeline}) {
        if (passes::ParticlePipelines::supported(ctx, b)) out.push_back(b);
    }
    return out;
}

std::string text(glm::vec4 v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ", " +
           std::to_string(v.w) + ")";
}

bool near(glm::vec4 a, glm::vec4 b, float tolerance) {
    return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::vec4(tolerance)));
}

// B's mirror image seen on the floor: the pixel whose reflected ray passes
// nearest B's centre (the mirror camera at (0, -2, 0) through B).
glm::uvec2 mirrorPixelOf(const scene::Camera& camera, glm::vec3 particle) {
    const glm::vec3 mirrorEye(0.0f, 2.0f * kFloorY, 0.0f);
    const float s = (kFloorY - mirrorEye.y) / (particle.y - mirrorEye.y);
    const glm::vec3 floorPoint = mirrorEye + s * (particle - mirrorEye);
    const glm::vec4 clip = camera.viewProjection() * glm::vec4(floorPoint, 1.0f);
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    return glm::uvec2((ndc * 0.5f + 0.5f) * float(kSize));
}

} // namespace

TEST_CASE("a particle in front of a mirror tints exactly the reflected rays through it, with its colour and coverage") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto backends = availableBackends(ctx);
    REQUIRE_FALSE(backends.empty());
    Rig rig(ctx, mirrorScene(true));
    for (const passes::RtBackend backend : backends) {
        const std::string backendName = passes::rtBackendName(backend);
        CAPTURE(backendName);
        const Frame f = rig.run(passes::ReflectionMode::Rt, backend);
        REQUIRE(f.traced);
        uint32_t floorPixels = 0, covered = 0, uncovered = 0, wrong = 0;
        float peak = 0.0f;
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const size_t i = pixelIndex(x, y);
                const Expected e = expectedAt(rig.camera(), x, y);
                const glm::vec4 got = f.particles[i];
                if (!e.floor) {
                    // The wall and the sky trace no rays: no particles.
                    if (got != glm::vec4(0.0f) && wrong++ < 5) {
                        MESSAGE("off-floor pixel " << x << "," << y << ": " << text(got));
                    }
                    continue;
                }
                ++floorPixels;
                // Half-float output; the GPU reconstructs from depth and
                // packs the ray's direction (16-bit octahedral).
                if (!near(got, e.particles, 0.02f) && wrong++ < 5) {
                    MESSAGE("pixel " << x << "," << y << ": " << text(got) << " vs " << text(e.particles));
                }
                if (e.particles.a == 0.0f) {
                    ++uncovered;
                    if (got != glm::vec4(0.0f) && wrong++ < 5) {
                        MESSAGE("miss pixel " << x << "," << y << ": " << text(got));
                    }
                } else {
                    ++covered;
                }
                peak = std::max(peak, got.a);
                // Premultiplied: rgb = colour * coverage.
                CHECK(near(glm::vec4(glm::vec3(got), 0.0f),
                           glm::vec4(glm::vec3(kParticleA.color) * got.a, 0.0f), 2e-3f + 2e-3f * got.a));
            }
        }
        MESSAGE(floorPixels << " floor pixels, " << covered << " see A, " << uncovered << " see no particle");
        CHECK(wrong == 0);
        CHECK(covered > 10);
        CHECK(uncovered > 200);
        // The ray nearest A's centre sees nearly its full alpha.
        CHECK(peak > 0.95f * kParticleA.color.a);
        CHECK(peak <= kParticleA.color.a + 1e-3f);

        // Integrate composites it over the reflection: p.rgb + (1 - p.a) * reflection.
        uint32_t compositeErrors = 0;
        for (size_t i = 0; i < kPixels; ++i) {
            const glm::vec4 p = f.particles[i];
            const glm::vec3 expected = glm::vec3(p) + (1.0f - p.a) * glm::vec3(f.reflectionAlone[i]);
            const glm::vec3 got = glm::vec3(f.reflection[i]);
            const float tolerance = 2e-3f * std::max(1.0f, glm::length(expected));
            if (glm::any(glm::greaterThan(glm::abs(got - expected), glm::vec3(tolerance)))) {
                if (compositeErrors++ < 5) {
                    MESSAGE("composite at " << i << ": " << text(f.reflection[i]) << " vs "
                                            << text(glm::vec4(expected, 0.0f)));
                }
            }
            CHECK(f.reflection[i].a == f.reflectionAlone[i].a);
        }
        CHECK(compositeErrors == 0);
    }
}

TEST_CASE("a particle reflected at 80-89 degrees to its billboard keeps its coverage: each ray meets the quad facing "
          "its largest view axis, once") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    const auto backends = availableBackends(ctx);
    REQUIRE_FALSE(backends.empty());
    const scene::Camera camera = edgeOnCamera();
    const scene::Particle c = edgeOnParticle();
    const shader::ParticleBillboardParams basis = passes::particleBasis(camera.view);
    Rig rig(ctx, edgeOnScene(), camera);
    for (const passes::RtBackend backend : backends) {
        const std::string backendName = passes::rtBackendName(backend);
        CAPTURE(backendName);
        const Frame f = rig.run(passes::ReflectionMode::Rt, backend);
        REQUIRE(f.traced);
        CHECK(f.bvh.particles == 1u);
        CHECK(f.bvh.particleQuads == shader::kParticleQuadAxes);
        uint32_t covered = 0, wrong = 0;
        double sumGot = 0.0, sumExpected = 0.0, sumBillboard = 0.0;
        float peak = 0.0f, expectedPeak = 0.0f, nearestToNormal = 90.0f;
        for (uint32_t y = 0; y < kSize; ++y) {
            for (uint32_t x = 0; x < kSize; ++x) {
                const glm::vec4 got = f.particles[pixelIndex(x, y)];
                glm::vec3 p, r;
                if (!floorRay(camera, x, y, -1e9f, p, r)) {
                    CHECK(got == glm::vec4(0.0f));
                    continue;
                }
                const glm::vec4 expected = particleAlong(camera, c, p, r, Quads::ByRayAxis);
                if (!near(got, expected, 0.02f) && wrong++ < 5) {
                    MESSAGE("pixel " << x << "," << y << ": " << text(got) << " vs " << text(expected));
                }
                sumGot += got.a;
                sumExpected += expected.a;
                sumBillboard += particleAlong(camera, c, p, r, Quads::BillboardOnly).a;
                peak = std::max(peak, got.a);
                expectedPeak = std::max(expectedPeak, expected.a);
                if (expected.a > 0.0f) {
                    ++covered;
                    const float degrees = glm::degrees(std::acos(std::abs(glm::dot(r, basis.back))));
                    nearestToNormal = std::min(nearestToNormal, degrees);
                }
            }
        }
        MESSAGE(covered << " pixels see C; coverage summed " << sumGot << " (expected " << sumExpected
                        << ", through the billboard alone " << sumBillboard << "); rays at least " << nearestToNormal
                        << " degrees from the billboard's normal");
        // The rays that see C all meet its billboard between 80 and 90 degrees.
        CHECK(nearestToNormal >= 80.0f);
        CHECK(covered > 50);
        CHECK(wrong == 0);
        CHECK(std::abs(sumGot - sumExpected) <= 0.02 * sumExpected);
        // Through the camera-facing quad alone the reflection keeps a sliver.
        CHECK(sumBillboard < 0.2 * sumExpected);
        // Seen once: the ray nearest C's centre gets nearly its alpha, not more.
        CHECK(expectedPeak > 0.9f * c.color.a);
        CHECK(std::abs(peak - expectedPeak) <= 0.02f);
        CHECK(peak <= c.color.a + 1e-3f);
    }
}

TEST_CASE("a particle's quad axis follows the ray's largest view-space component, one mask per direction") {
    using namespace shader;
    CHECK(particleQuadAxis({0.0f, 0.0f, -1.0f}) == kParticleAxisBack);
    CHECK(particleQuadAxis({0.9f, 0.1f, 0.3f}) == kParticleAxisRight);
    CHECK(particleQuadAxis({-0.2f, -0.9f, 0.3f}) == kParticleAxisUp);
    // Ties: back before right before up, so a diagonal ray still sees one quad.
    CHECK(particleQuadAxis({0.5f, 0.5f, 0.5f}) == kParticleAxisBack);
    CHECK(particleQuadAxis({0.5f, 0.5f, 0.1f}) == kParticleAxisRight);
    // Distinct single-bit masks, none of them the main TLAS's "all".
    uint32_t masks = 0;
    for (uint32_t axis = 0; axis < kParticleQuadAxes; ++axis) {
        const uint32_t mask = particleAxisMask(axis);
        CHECK(std::popcount(mask) == 1);
        CHECK((masks & mask) == 0u);
        masks |= mask;
    }
    // Each quad spans the two axes it does not face.
    const glm::mat4 view = glm::lookAt(glm::vec3(1, 2, 3), glm::vec3(0, 0, 0), glm::vec3(0, 1, 0));
    const ParticleBillboardParams basis = passes::particleBasis(view);
    const glm::vec3 axes[kParticleQuadAxes] = {basis.right, basis.up, basis.back};
    for (uint32_t axis = 0; axis < kParticleQuadAxes; ++axis) {
        CAPTURE(axis);
        CHECK(std::abs(glm::dot(particleQuadSpanU(basis, axis), axes[axis])) < 1e-6f);
        CHECK(std::abs(glm::dot(particleQuadSpanV(basis, axis), axes[axis])) < 1e-6f);
        CHECK(std::abs(glm::dot(particleQuadSpanU(basis, axis), particleQuadSpanV(basis, axis))) < 1e-6f);
    }
    // The billboard the forward pass draws is the back axis's quad.
    CHECK(particleQuadSpanU(basis, kParticleAxisBack) == basis.right);
    CHECK(particleQuadSpanV(basis, kParticleAxisBack) == basis.up);
}

TEST_CASE("with SSLR particles, SSLR reflects the particles it sees in the lit colour and the trace only the rest: "
          "no reflection gets a particle twice") {
    test::GpuTest gpu;
    Rig rig(gpu.ctx(), mirrorScene(true));
    // The same rays twice: particles drawn after SSLR, then before it.
    constexpr uint64_t kNoiseFrame = 5;
    const Frame traced = rig.run(passes::ReflectionMode::Hybrid, passes::RtBackend::Auto, false, kNoiseFrame);
    const Frame seen = rig.run(passes::ReflectionMode::Hybrid, passes::RtBackend::Auto, true, kNoiseFrame);
    REQUIRE(seen.traced);
    uint32_t changedTraces = 0, skipped = 0, bySslr = 0, twice = 0;
    for (size_t i = 0; i < kPixels; ++i) {
        // The trace only drops rays: where it still runs, it finds what it found.
        if (seen.particles[i] != glm::vec4(0.0f) && seen.particles[i] != traced.particles[i]) ++changedTraces;
        if (traced.particles[i].a > 0.01f && seen.particles[i] == glm::vec4(0.0f)) ++skipped;
        // Without the trace's particles, the reflection differs only where
        // SSLR sampled a lit colour with a particle drawn in.
        const glm::vec4 delta = glm::abs(seen.reflectionAlone[i] - traced.reflectionAlone[i]);
        if (glm::any(glm::greaterThan(glm::vec3(delta), glm::vec3(1e-3f)))) {
            ++bySslr;
            if (seen.particles[i] != glm::vec4(0.0f) && twice++ < 5) {
                MESSAGE("pixel " << i << ": SSLR's reflection carries a particle and the trace adds "
                                 << text(seen.particles[i]));
            }
        }
    }
    MESSAGE(skipped << " particle rays left to SSLR, " << bySslr << " reflections with a particle from SSLR");
    CHECK(changedTraces == 0);
    CHECK(skipped >= 5);
    CHECK(bySslr > 10);
    CHECK(twice == 0);
}

TEST_CASE("particles behind the reflected surface are not composited; without a trace to end the ray they would be") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    Rig rig(ctx, mirrorScene(true));
    const glm::uvec2 b = mirrorPixelOf(rig.camera(), kParticleB.position);
    REQUIRE(expectedAt(rig.camera(), b.x, b.y).floor);
    // RT mode (the ray tracer's hit distance) and SSR mode (SSLR's): both
    // end the reflection at the wall.
    for (const passes::ReflectionMode mode : {passes::ReflectionMode::Rt, passes::ReflectionMode::Ssr,
                                              passes::ReflectionMode::Hybrid}) {
        CAPTURE(int(mode));
        const Frame f = rig.run(mode, passes::RtBackend::Auto);
        const size_t i = pixelIndex(b.x, b.y);
        MESSAGE("B's mirror pixel " << b.x << "," << b.y << ": " << text(f.particles[i]) << ", unbounded "
                                    << text(f.untraced[i]));
        CHECK(f.particles[i] == glm::vec4(0.0f));
        CHECK(f.untraced[i].a > 0.5f * kParticleB.color.a);
        // A, in front of the wall, is seen whichever trace resolved the floor.
        const glm::uvec2 a = mirrorPixelOf(rig.camera(), kParticleA.position);
        CHECK(f.particles[pixelIndex(a.x, a.y)].a > 0.9f * kParticleA.color.a);
    }
}

TEST_CASE("the ray query and the ray tracing pipeline particle traces are bit-identical") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    if (availableBackends(ctx).size() < 2) {
        MESSAGE("device '" << ctx.caps().deviceName << "' has one backend; nothing to compare");
        return;
    }
    Rig mirror(ctx, mirrorScene(true));
    Rig edgeOn(ctx, edgeOnScene(), edgeOnCamera());
    for (const auto& [rig, mode] : {std::pair{&mirror, passes::ReflectionMode::Rt},
                                    std::pair{&mirror, passes::ReflectionMode::Hybrid},
                                    std::pair{&edgeOn, passes::ReflectionMode::Rt}}) {
        const Frame query = rig->run(mode, passes::RtBackend::RayQuery);
        const Frame pipeline = rig->run(mode, passes::RtBackend::Pipeline);
        uint32_t differing = 0, covered = 0;
        for (size_t i = 0; i < kPixels; ++i) {
            if (query.particleBits[i] != pipeline.particleBits[i] && differing++ < 5) {
                MESSAGE("pixel " << i << ": " << text(query.particles[i]) << " vs " << text(pipeline.particles[i]));
            }
            if (query.particles[i].a > 0.0f) ++covered;
        }
        CHECK(differing == 0);
        CHECK(covered > 10);
    }
}

TEST_CASE("a scene without particles builds no particle TLAS, buffer or dispatch, and needs no particle trace") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    {
        Rig rig(ctx, mirrorScene(false));
        const Frame f = rig.run(passes::ReflectionMode::Hybrid, passes::RtBackend::Auto);
        CHECK_FALSE(f.traced);
        CHECK(f.bvh.particleTlasBuilds == 0);
        CHECK(f.bvh.particles == 0);
        CHECK(f.bvh.particleQuads == 0);
        CHECK(f.bvh.particleDispatches == 0);
        CHECK(f.bvh.particleBytes == 0);
        // Nothing drawn: the forward pass declared nothing, the lit colour is untouched.
        CHECK(f.litBefore == f.litAfter);
    }
    {
        Rig rig(ctx, mirrorScene(true));
        const Frame f = rig.run(passes::ReflectionMode::Hybrid, passes::RtBackend::Auto);
        CHECK(f.traced);
        CHECK(f.bvh.particleTlasBuilds == 1);
        CHECK(f.bvh.particles == 2);
        CHECK(f.bvh.particleQuads == 2 * shader::kParticleQuadAxes);
        CHECK(f.bvh.particleDispatches == 1);
        CHECK(f.bvh.particleBytes > 0);
    }
    // The trace refuses a BVH without a particle TLAS.
    rg::Graph graph;
    passes::ParticlePipelines pipelines(ctx);
    passes::ParticleTraceInputs in;
    in.gbuffer.width = in.gbuffer.height = in.rays.width = in.rays.height = kSize;
    CHECK_THROWS_AS(passes::addParticleTracePass(graph, pipelines, in), gpu::GpuError);
}

TEST_CASE("the forward pass blends particles over the lit colour where the G-buffer's depth lets it") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    Rig rig(ctx, mirrorScene(true));
    const Frame f = rig.run(passes::ReflectionMode::Hybrid, passes::RtBackend::Auto);
    const scene::Camera& camera = rig.camera();
    const auto pixelOf = [&](glm::vec3 p) {
        const glm::vec4 clip = camera.viewProjection() * glm::vec4(p, 1.0f);
        return glm::uvec2((glm::vec2(clip) / clip.w * 0.5f + 0.5f) * float(kSize));
    };
    // A, in front of the wall: its centre pixel is nearly alpha over the wall.
    const glm::uvec2 a = pixelOf(kParticleA.position);
    const size_t ia = pixelIndex(a.x, a.y);
    const float r2 = [&] {
        // The pixel centre's quad coordinates (A's quad is the plane z = A.z, facing the camera).
        const glm::vec2 ndc = test::pixelNdc(a.x, a.y);
        const float d = -kParticleA.position.z;  // 90-degree lens: x = ndc.x * d, y = -ndc.y * d
        const glm::vec2 q = (glm::vec2(ndc.x * d, -ndc.y * d) - glm::vec2(kParticleA.position)) / kParticleA.radius;
        return glm::dot(q, q);
    }();
    const float coverage = shader::particleCoverage(kParticleA.color.a, r2);
    const glm::vec3 expected = glm::vec3(kParticleA.color) * coverage + (1.0f - coverage) * glm::vec3(f.litBefore[ia]);
    MESSAGE("A's pixel " << a.x << "," << a.y << ": " << text(f.litBefore[ia]) << " -> " << text(f.litAfter[ia]));
    CHECK(coverage > 0.5f);
    CHECK(glm::all(glm::lessThanEqual(glm::abs(glm::vec3(f.litAfter[ia]) - expected),
                                      glm::vec3(4e-3f * std::max(1.0f, glm::length(expected))))));
    CHECK(f.litAfter[ia].a == f.litBefore[ia].a);
    // B, behind the wall, is hidden by the depth test; pixels away from A untouched.
    const glm::uvec2 b = pixelOf(kParticleB.position);
    CHECK(f.litAfter[pixelIndex(b.x, b.y)] == f.litBefore[pixelIndex(b.x, b.y)]);
    uint32_t changed = 0, changedFar = 0;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            if (f.litAfter[pixelIndex(x, y)] == f.litBefore[pixelIndex(x, y)]) continue;
            ++changed;
            // A covers radius / distance * 32 = 4 pixels around its centre.
            if (std::abs(int(x) - int(a.x)) > 5 || std::abs(int(y) - int(a.y)) > 5) ++changedFar;
        }
    }
    CHECK(changed > 10);
    CHECK(changedFar == 0);
}

TEST_CASE("the forward pass draws only the particles whose quads reach the view; the trace still sees them all") {
    test::GpuTest gpu;
    scene::Scene s = mirrorScene(true);
    const uint32_t inView = uint32_t(s.particles.size());
    // Behind the camera (at the origin, looking down -Z), and beside it,
    // its quad just reaching into the 90-degree view.
    s.particles.push_back({{0.0f, 0.0f, 3.0f}, 0.2f, {1.0f, 0.0f, 0.0f, 1.0f}});
    s.particles.push_back({{2.1f, 0.0f, -2.0f}, 0.2f, {0.0f, 1.0f, 0.0f, 1.0f}});
    Rig rig(gpu.ctx(), s);
    const Frame f = rig.run(passes::ReflectionMode::Hybrid, passes::RtBackend::Auto);
    CHECK(f.forwardCulled == 1u);
    CHECK(f.forwardDrawn == inView + 1u);
    CHECK(f.bvh.particles == inView + 2u);
}

TEST_CASE("the plaza's lamp glows get a particle TLAS rebuilt every frame, frames in flight, the camera moving") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    scene::Scene plaza = scene::makePlaza();
    REQUIRE_FALSE(plaza.particles.empty());
    rg::Executor executor(ctx);
    passes::BvhManager bvh(ctx, plaza);
    scene::BvhPlanner planner;
    scene::Camera camera;
    camera.resolution = {64, 48};
    camera.lens = plaza.lens;
    camera.reset(plaza.cameraPath.atFrame(0, 6), 0);
    // No waits between frames: the per-slot particle uploads and instance
    // buffers, and the every-frame rebuilds, run with frames in flight.
    for (uint32_t frame = 0; frame < 6; ++frame) {
        scene::advanceScene(plaza, 0.1 * frame);
        camera.advance(plaza.cameraPath.atFrame(frame, 6), frame);
        rg::Graph graph(executor.queueCaps());
        const scene::BvhPlan plan = planner.plan(plaza, camera);
        REQUIRE(plan.particleTlas);
        const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, plan, camera);
        REQUIRE(passes::particlesTraced(out));
        rg::FrameResources resources;
        bvh.bind(resources, out);
        executor.run(graph.compile(executor.compileOptions()), resources);
        CHECK(bvh.stats().particleTlasBuilds == 1);
        CHECK(bvh.stats().particles == plaza.particles.size());
        // The box the particle trace tests segments against holds every
        // quad, turned any way (a corner lies r sqrt(2) from the centre).
        for (const scene::Particle& p : plaza.particles) {
            const glm::vec3 reach(p.radius * std::sqrt(2.0f));
            CHECK(glm::all(glm::lessThanEqual(out.particleBoundsMin, p.position - reach)));
            CHECK(glm::all(glm::greaterThanEqual(out.particleBoundsMax, p.position + reach)));
        }
    }
    executor.waitIdle();
    // Without the camera the same manager builds no particle TLAS.
    rg::Graph graph(executor.queueCaps());
    const passes::BvhUpdateOutputs out = passes::addBvhUpdatePass(graph, bvh, planner.plan(plaza, camera.position, 99));
    CHECK_FALSE(passes::particlesTraced(out));
    CHECK(out.particleBoundsMin.x > out.particleBoundsMax.x);  // empty
    CHECK(bvh.stats().particleTlasBuilds == 0);
    rg::FrameResources resources;
    bvh.bind(resources, out);
    executor.run(graph.compile(executor.compileOptions()), resources);
    executor.waitIdle();
}
