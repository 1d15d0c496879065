// Ray-traced hits and lighting (passes/rt_trace.h) on a real device behind
// the real G-buffer and BVH update, validation on (the harness:
// rt_trace_harness.h). The ray lists are built here (PackedRays + args
// uploaded), so nothing depends on ray generation or SSLR. The scene: a
// floor the rays leave, a floating, rotated and non-uniformly scaled quad
// with known per-vertex colours and normals, and a roof that shadows part
// of it. The CPU reference starts each ray where the pass does (the
// G-buffer's depth, read back, and the same origin offset), so it holds
// whatever the rasteriser's precision. Hits match a CPU evaluation of the
// same formula (the packed surface interpolated at the hit, lit by a port
// of glint/brdf.glsl with an analytic shadow test); under probe lighting
// their colour and normal match the unquantised surface within the
// packing's quantisation; misses give the environment; both backends agree
// bit for bit; only listed rays are traced. Rays leaving a plane far from
// the origin have their own file (rt_trace_origin_test.cpp).
#include "rt_trace_harness.h"

#include "glint/gpu/error.h"
#include "glint/scene/animation.h"

#include <glm/gtc/matrix_transform.hpp>

#include <random>

using namespace glint;
using namespace glint::rt_trace_test;

namespace {

// ---------------------------------------------------------------------------
// The scene of the hit tests
// ---------------------------------------------------------------------------

// A floor at y = -1 (the rays' origins), a quad floating at z ~ -5 (4 x 2
// after its instance's scale, turned 20 degrees about y) with a colour and
// a tilted normal per vertex, and a roof at y = 3 over its left part that
// the sun (from up, right, behind the camera) casts onto it.
constexpr float kFloorY = -1.0f;
constexpr float kFloorRoughness = 0.2f;  // 51/255 in the G-buffer's unorm: exact

scene::Scene hitScene() {
    scene::Scene s;
    s.name = "rt-trace-test";
    scene::Material floor;
    floor.baseColorFactor = {0.5f, 0.5f, 0.5f, 1.0f};
    floor.roughnessFactor = kFloorRoughness;
    floor.metallicFactor = 1.0f;
    scene::Material target;
    target.roughnessFactor = 0.4f;
    target.metallicFactor = 0.2f;
    target.reflectance = 0.6f;
    // Double-sided: some rays reach it from behind (the quad is turned),
    // where a single-sided quad lets them through.
    target.doubleSided = true;
    scene::Material roof;
    roof.baseColorFactor = {0.3f, 0.3f, 0.3f, 1.0f};
    roof.roughnessFactor = 0.9f;
    roof.metallicFactor = 0.0f;
    s.materials = {floor, target, roof};

    scene::Mesh floorMesh;
    floorMesh.name = "floor";
    floorMesh.lods.push_back({{square({0, kFloorY, -20}, {1, 0, 0}, {0, 0, -1}, 30.0f, 0)}});
    scene::Mesh targetMesh;
    targetMesh.name = "target";
    scene::Geometry quad = square({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1.0f, 1);
    quad.colors = {
        {0.9f, 0.2f, 0.1f, 1.0f}, {0.1f, 0.8f, 0.2f, 1.0f}, {0.2f, 0.3f, 0.9f, 1.0f}, {0.9f, 0.9f, 0.3f, 1.0f}};
    quad.normals = {glm::normalize(glm::vec3(-0.3f, -0.2f, 1.0f)), glm::normalize(glm::vec3(0.4f, -0.1f, 1.0f)),
                    glm::normalize(glm::vec3(0.2f, 0.5f, 1.0f)), glm::normalize(glm::vec3(-0.2f, 0.3f, 1.0f))};
    targetMesh.lods.push_back({{quad}});
    scene::Mesh roofMesh;
    roofMesh.name = "roof";
    // Facing down, over x in [-5, 0.5], z in [-8, -2].
    scene::Geometry roofQuad = square({-2.25f, 3.0f, -5.0f}, {0, 0, 1}, {1, 0, 0}, 1.0f, 2);
    for (glm::vec3& p : roofQuad.positions) {
        p = glm::vec3(-2.25f + (p.x + 2.25f) * 2.75f, p.y, -5.0f + (p.z + 5.0f) * 3.0f);
    }
    roofMesh.lods.push_back({{roofQuad}});
    s.meshes = {floorMesh, targetMesh, roofMesh};

    scene::Instance floorInstance;
    floorInstance.name = "floor";
    floorInstance.mesh = 0;
    scene::Instance targetInstance;
    targetInstance.name = "target";
    targetInstance.mesh = 1;
    targetInstance.transform = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.5f, -5.0f)) *
                               glm::rotate(glm::mat4(1.0f), glm::radians(20.0f), glm::vec3(0, 1, 0)) *
                               glm::scale(glm::mat4(1.0f), glm::vec3(2.0f, 1.0f, 1.0f));
    scene::Instance roofInstance;
    roofInstance.name = "roof";
    roofInstance.mesh = 2;
    s.instances = {floorInstance, targetInstance, roofInstance};
    scene::prepareScene(s);
    return s;
}

// No sun, a uniform white sky: a hit's radiance is its diffuse colour,
// albedo * (1 - metallic), and a miss's is 1.
shader::SceneLighting whiteSky() {
    shader::SceneLighting l{};
    l.sunDirection = glm::vec4(kSun, 0.0f);
    l.skyZenith = l.skyHorizon = l.skyGround = {1.0f, 1.0f, 1.0f, 0.0f};
    return l;
}

// No sun, sky only from above (zenith and horizon white, ground black): a
// hit's radiance is its diffuse colour times (1 + n.y) / 2.
shader::SceneLighting upperSky() {
    shader::SceneLighting l = whiteSky();
    l.skyGround = {0.0f, 0.0f, 0.0f, 0.0f};
    return l;
}

// The target quad's world point at (s, t) in [0, 1]^2 of its object square.
glm::dvec3 targetPoint(const scene::Scene& s, double a, double b) {
    const glm::dvec4 object(-1.0 + 2.0 * a, -1.0 + 2.0 * b, 0.0, 1.0);
    return glm::dvec3(glm::dmat4(s.instances[1].transform) * object);
}

// pixelOnPlane() on the floor at y = floorY.
std::optional<glm::dvec3> pixelOnFloor(const scene::Camera& camera, glm::uvec2 p, double floorY) {
    return pixelOnPlane(camera, p, {0.0, floorY, 0.0}, {0.0, 1.0, 0.0});
}

// Floor pixels in front of the target (every `step`-th), each with a ray
// aimed at a random point well inside the target quad, or, every fourth,
// up and back into the empty sky.
std::vector<ListedRay> hitTestRays(const Rig& rig, uint32_t step) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> inside(0.1, 0.9);
    std::uniform_real_distribution<float> side(-0.5f, 0.5f);
    std::vector<ListedRay> rays;
    uint32_t n = 0;
    for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const auto origin = pixelOnFloor(rig.camera(), {x, y}, kFloorY);
            if (!origin || origin->z > -1.5 || origin->z < -4.0 || (n++ % step) != 0) continue;
            ListedRay r;
            r.pixel = {x, y};
            r.origin = *origin;
            glm::vec3 dir;
            if (rays.size() % 4 == 3) {
                dir = glm::normalize(glm::vec3(side(rng), 1.0f, 1.5f));
            } else {
                dir = glm::vec3(glm::normalize(targetPoint(rig.scene(), inside(rng), inside(rng)) - *origin));
                r.aimedAtTarget = true;
            }
            r.direction = shader::unpackRayDirection(shader::packRayDirection(dir));
            rays.push_back(r);
        }
    }
    return rays;
}

// The length of a ray leaving the floor (passes/rt_trace.h's rule).
float floorRayLength(const passes::RtTraceSettings& s, float maxDistance = scene::kDefaultBvhRadius) {
    const float roughness = 51.0f / 255.0f;
    const float k = std::clamp(roughness / s.shortRangeRoughness, 0.0f, 1.0f);
    return maxDistance * glm::mix(1.0f, s.shortRangeFraction, k);
}

// Whether the roof shadows a hit, analytically: the sun's ray from the hit
// and from four points `margin` away along the triangle's edges, each
// lifted off the face towards the sun. Edge: they disagree (the hit lies
// within `margin` of the shadow's edge, which the tests leave out).
enum class SunShadow { Lit, Shadowed, Edge };

SunShadow analyticSunShadow(const CpuScene& cpu, const CpuHit& h, glm::vec3 position, double margin) {
    const glm::dvec3* v = h.triangle->v;
    const glm::dvec3 e1 = glm::normalize(v[1] - v[0]), e2 = glm::normalize(v[2] - v[0]);
    const glm::dvec3 face = glm::normalize(glm::cross(e1, e2));
    const glm::dvec3 lift = face * (glm::dot(face, glm::dvec3(kSun)) > 0.0 ? 1e-4 : -1e-4);
    bool anyOccluded = false, allOccluded = true;
    for (const glm::dvec3 offset : {glm::dvec3(0), margin * e1, -margin * e1, margin * e2, -margin * e2}) {
        const bool occluded = cpu.trace(glm::dvec3(position) + offset + lift, glm::dvec3(kSun), 0.0, 200.0, false).hit;
        anyOccluded = anyOccluded || occluded;
        allOccluded = allOccluded && occluded;
    }
    if (anyOccluded != allOccluded) return SunShadow::Edge;
    return allOccluded ? SunShadow::Shadowed : SunShadow::Lit;
}

} // namespace

TEST_CASE("RT hits interpolate the packed triangle and light it as the CPU does; misses give the environment") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    Rig rig(gpu.ctx(), hitScene(), test::testCamera());
    const CpuScene cpu(rig.scene());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    REQUIRE(rays.size() > 60);
    const RayList list = toList(rays);

    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        CHECK((pipelines.backend() == backend));
        const passes::RtTraceSettings settings = settingsFor(backend);
        const float tMax = floorRayLength(settings);
        const shader::SceneLighting lit = sunAndSky();
        const shader::SceneLighting white = whiteSky();
        const RtFrame litFrame = rig.trace(pipelines, list, lit, settings);
        const RtFrame whiteFrame = rig.trace(pipelines, list, white, settings);
        const RtFrame upperFrame = rig.trace(pipelines, list, upperSky(), settings);

        uint32_t hits = 0, misses = 0, shadowed = 0, sunlit = 0;
        float worstAlbedo = 0.0f, worstNormalY = 0.0f;
        for (const ListedRay& r : rays) {
            CAPTURE(r.pixel.x);
            CAPTURE(r.pixel.y);
            const size_t i = pixelIndex(r.pixel);
            const glm::vec4 got = litFrame.radiance[i];
            REQUIRE(got.a == 1.0f);
            REQUIRE(whiteFrame.radiance[i].a == 1.0f);
            const glm::dvec3 origin = rig.rayOrigin(litFrame, r.pixel, {0, 1, 0});
            const CpuHit h = cpu.trace(origin, glm::dvec3(r.direction), 0.0, tMax);
            REQUIRE(h.hit == r.aimedAtTarget);
            if (!h.hit) {
                ++misses;
                const glm::vec3 env = environmentRadiance(lit, r.direction, 51.0f / 255.0f);
                CHECK_MESSAGE(near(glm::vec3(got), env, 2e-3f, 1e-4f), text(glm::vec3(got)) << " vs " << text(env));
                CHECK(litFrame.hitDistance[i] == shader::kMissHitDistance);
                CHECK(near(glm::vec3(whiteFrame.radiance[i]), glm::vec3(1.0f), 0.0f, 1e-3f));
                continue;
            }
            ++hits;
            REQUIRE(h.triangle->instance == 1u);
            CHECK(litFrame.hitDistance[i] == doctest::Approx(h.t).epsilon(1e-4));
            const glm::vec3 position = glm::vec3(origin + h.t * glm::dvec3(r.direction));

            // White sky: the radiance is the interpolated diffuse colour.
            const CpuSurface packed = hitSurface(h, position, r.direction, true);
            const CpuSurface truth = hitSurface(h, position, r.direction, false);
            const glm::vec3 diffuse = glm::vec3(whiteFrame.radiance[i]);
            CHECK_MESSAGE(near(diffuse, packed.albedo * (1.0f - packed.metallic), 2e-3f, 2e-4f),
                          text(diffuse) << " vs packed " << text(packed.albedo * (1.0f - packed.metallic)));
            // Against the unquantised surface: half an 8-bit sRGB step is at
            // most ~0.005 in linear, and metallic's step 0.002.
            const glm::vec3 trueDiffuse = truth.albedo * (1.0f - truth.metallic);
            worstAlbedo = std::max(worstAlbedo, glm::length(diffuse - trueDiffuse));
            CHECK_MESSAGE(near(diffuse, trueDiffuse, 0.0f, 0.006f), text(diffuse) << " vs true " << text(trueDiffuse));
            // Sky from above only: the radiance is that colour times
            // (1 + n.y) / 2, which gives the world normal's y, through the
            // instance's rotation and non-uniform scale: within the
            // octahedral normals' ~1 degree of the unquantised one.
            const glm::vec3 upper = glm::vec3(upperFrame.radiance[i]);
            const float normalY = 2.0f * (upper.x + upper.y + upper.z) / (diffuse.x + diffuse.y + diffuse.z) - 1.0f;
            CHECK_MESSAGE(std::abs(normalY - packed.normal.y) < 2e-3f, normalY << " vs packed " << packed.normal.y);
            // A ray nearly tangent to the shading normal may see the front
            // of one normal and the back of the other (each is turned
            // towards the ray): the unquantised comparison leaves it out.
            if (std::abs(glm::dot(truth.normal, r.direction)) > 0.05f) {
                worstNormalY = std::max(worstNormalY, std::abs(normalY - truth.normal.y));
                CHECK_MESSAGE(std::abs(normalY - truth.normal.y) < 0.02f, normalY << " vs true " << truth.normal.y);
            }

            // Sun and sky, with an analytic shadow test. Hits within a
            // hand's width of the roof's shadow edge are left out.
            const SunShadow shadow = analyticSunShadow(cpu, h, position, 0.05);
            if (shadow == SunShadow::Edge) continue;
            const bool allOccluded = shadow == SunShadow::Shadowed;
            const float visibility = allOccluded ? 0.0f : 1.0f;
            (allOccluded ? shadowed : sunlit)++;
            const glm::vec3 expected = shadeSurface(lit, packed, -r.direction, visibility);
            CHECK_MESSAGE(near(glm::vec3(got), expected, 3e-3f, 3e-4f),
                          text(glm::vec3(got)) << " vs " << text(expected) << " visibility " << visibility);
        }
        MESSAGE(name << ": " << hits << " hits (" << sunlit << " sunlit, " << shadowed << " shadowed), " << misses
                     << " misses; worst error against the unquantised surface: diffuse colour " << worstAlbedo
                     << ", normal y " << worstNormalY);
        CHECK(hits > 40);
        CHECK(misses > 10);
        CHECK(sunlit > 10);
        CHECK(shadowed > 10);
    }
}

TEST_CASE("hits the G-buffer's shadow map covers take the sun's visibility from it") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    // The scene's sun is the test lighting's, so that the G-buffer's map
    // holds the roof's shadow where the shadow rays find it.
    scene::Scene s = hitScene();
    s.sun.directionToLight = kSun;
    Rig rig(gpu.ctx(), std::move(s), test::testCamera());
    const CpuScene cpu(rig.scene());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    const RayList list = toList(rays);
    const shader::SceneLighting lit = sunAndSky();
    // Shadow rays a hundredth of a unit long reach no roof: only the map
    // can shadow a hit.
    const float shortShadows = 0.01f;
    for (const passes::RtBackend backend : backends) {
        CAPTURE(passes::rtBackendName(backend));
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        passes::RtTraceSettings settings = settingsFor(backend);
        const RtFrame rayFrame = rig.trace(pipelines, list, lit, settings, scene::kDefaultBvhRadius, shortShadows);
        settings.shadowMapAtHits = true;
        const RtFrame mapFrame = rig.trace(pipelines, list, lit, settings, scene::kDefaultBvhRadius, shortShadows);
        uint32_t shadowed = 0, sunlit = 0;
        float worst = 0.0f;
        for (const ListedRay& r : rays) {
            if (!r.aimedAtTarget) continue;
            CAPTURE(r.pixel.x);
            CAPTURE(r.pixel.y);
            const size_t i = pixelIndex(r.pixel);
            const glm::dvec3 origin = rig.rayOrigin(mapFrame, r.pixel, {0, 1, 0});
            const CpuHit h = cpu.trace(origin, glm::dvec3(r.direction), 0.0, floorRayLength(settings));
            REQUIRE(h.hit);
            const glm::vec3 position = glm::vec3(origin + h.t * glm::dvec3(r.direction));
            const CpuSurface packed = hitSurface(h, position, r.direction, true);
            if (!(glm::dot(packed.normal, kSun) > 0.0f)) continue;  // turned from the sun: no shadow to find
            // The roof's shadow, analytically; the map's filter and biases
            // blur its edge over a few of its texels: hits within a hand's
            // width of the edge are left out.
            const SunShadow shadow = analyticSunShadow(cpu, h, position, 0.1);
            if (shadow == SunShadow::Edge) continue;
            const bool allOccluded = shadow == SunShadow::Shadowed;
            (allOccluded ? shadowed : sunlit)++;
            const glm::vec3 litColour = shadeSurface(lit, packed, -r.direction, 1.0f);
            // The short shadow rays find nothing: every hit sunlit.
            CHECK_MESSAGE(near(glm::vec3(rayFrame.radiance[i]), litColour, 3e-3f, 3e-4f),
                          text(glm::vec3(rayFrame.radiance[i])) << " vs " << text(litColour));
            // The map shadows those under the roof. Its visibility is the
            // G-buffer's, filtered over a few texels and biased against acne
            // along the hit's shading normal (the G-buffer's is the geometric
            // one), so it is read back from the radiance (linear in it) and
            // compared with a tolerance.
            const glm::vec3 dark = shadeSurface(lit, packed, -r.direction, 0.0f);
            const float sunTerm = glm::dot(litColour - dark, glm::vec3(1.0f));
            REQUIRE(sunTerm > 1e-3f);
            const float visibility = glm::dot(glm::vec3(mapFrame.radiance[i]) - dark, glm::vec3(1.0f)) / sunTerm;
            worst = std::max(worst, std::abs(visibility - (allOccluded ? 0.0f : 1.0f)));
            CHECK_MESSAGE(std::abs(visibility - (allOccluded ? 0.0f : 1.0f)) < 0.15f,
                          "visibility " << visibility << " where the roof " << (allOccluded ? "shadows" : "does not"));
        }
        MESSAGE(sunlit << " sunlit and " << shadowed << " shadowed hits; the map's visibility at most " << worst
                       << " from the analytic one");
        CHECK(sunlit > 10);
        CHECK(shadowed > 10);
    }
}

TEST_CASE("without shadows the roof's shadow is gone; rougher surfaces trace shorter rays") {
    test::GpuTest gpu;
    Rig rig(gpu.ctx(), hitScene(), test::testCamera());
    const CpuScene cpu(rig.scene());
    passes::RtTracePipelines pipelines(gpu.ctx());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    const RayList list = toList(rays);
    passes::RtTraceSettings settings;
    settings.shadows = false;
    const shader::SceneLighting lit = sunAndSky();
    const RtFrame f = rig.trace(pipelines, list, lit, settings);
    uint32_t checked = 0, underRoof = 0;
    for (const ListedRay& r : rays) {
        if (!r.aimedAtTarget) continue;
        const glm::dvec3 origin = rig.rayOrigin(f, r.pixel, {0, 1, 0});
        const CpuHit h = cpu.trace(origin, glm::dvec3(r.direction), 0.0, 100.0);
        REQUIRE(h.hit);
        const glm::vec3 position = glm::vec3(origin + h.t * glm::dvec3(r.direction));
        const glm::vec3 expected = shadeSurface(lit, hitSurface(h, position, r.direction, true), -r.direction, 1.0f);
        CHECK(near(glm::vec3(f.radiance[pixelIndex(r.pixel)]), expected, 3e-3f, 3e-4f));
        ++checked;
        if (cpu.trace(glm::dvec3(position), glm::dvec3(kSun), 1e-3, 200.0, false).hit) ++underRoof;
    }
    CHECK(checked > 40);
    CHECK(underRoof > 10);  // hits the roof shadows when shadows are on

    // Rays from the floor (roughness 0.2) with maxDistance 12 shrinking to a
    // quarter by roughness 0.1: 3 units long. The target lies 1-5 units
    // away: nearer hits stay, farther ones become misses.
    settings.shortRangeFraction = 0.25f;
    settings.shortRangeRoughness = 0.1f;
    const float length = floorRayLength(settings, 12.0f);
    REQUIRE(length == doctest::Approx(3.0f));
    const RtFrame shortRays = rig.trace(pipelines, list, lit, settings, 12.0f);
    uint32_t nearHits = 0, cutOff = 0;
    for (const ListedRay& r : rays) {
        if (!r.aimedAtTarget) continue;
        const CpuHit h = cpu.trace(rig.rayOrigin(shortRays, r.pixel, {0, 1, 0}), glm::dvec3(r.direction), 0.0, 100.0);
        if (std::abs(h.t - length) < 0.01) continue;
        const size_t i = pixelIndex(r.pixel);
        CHECK(shortRays.radiance[i].a == 1.0f);
        if (h.t < length) {
            ++nearHits;
            CHECK(shortRays.hitDistance[i] == doctest::Approx(h.t).epsilon(1e-3));
        } else {
            ++cutOff;
            CHECK(shortRays.hitDistance[i] == shader::kMissHitDistance);
        }
    }
    CHECK(nearHits > 5);
    CHECK(cutOff > 5);
}

TEST_CASE("ray query and the ray tracing pipeline write bit-identical radiance and hit distances") {
    test::GpuTest gpu;
    auto& ctx = gpu.ctx();
    if (!(passes::RtTracePipelines::supported(ctx, passes::RtBackend::RayQuery) &&
          passes::RtTracePipelines::supported(ctx, passes::RtBackend::Pipeline))) {
        MESSAGE("device '" << ctx.caps().deviceName << "' has one backend; nothing to compare");
        return;
    }
    Rig rig(ctx, hitScene(), test::testCamera());
    // One ray per pixel, random over the upper hemisphere with a bias
    // towards the target: floor, target, roof and sky pixels, hits, misses,
    // shadowed and sunlit hits.
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    RayList list;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            const float across = u(rng), up = 0.2f + std::abs(u(rng)), back = 0.3f - 1.2f * std::abs(u(rng));
            const glm::vec3 d = glm::normalize(glm::vec3(across, up, back));
            list.entries.push_back({shader::packRayPixel({x, y}, false), shader::packRayDirection(d)});
        }
    }
    list.count = uint32_t(list.entries.size());
    passes::RtTracePipelines pipelines(ctx, passes::RtBackend::RayQuery);
    const RtFrame query = rig.trace(pipelines, list, sunAndSky(), settingsFor(passes::RtBackend::RayQuery));
    const RtFrame pipeline = rig.trace(pipelines, list, sunAndSky(), settingsFor(passes::RtBackend::Pipeline));
    uint32_t hits = 0, misses = 0, differing = 0;
    for (size_t i = 0; i < query.hitDistance.size(); ++i) {
        if (query.radianceBits[i] != pipeline.radianceBits[i] ||
            std::memcmp(&query.hitDistance[i], &pipeline.hitDistance[i], sizeof(float)) != 0) {
            if (differing++ < 5) {
                MESSAGE("pixel " << i << ": " << text(glm::vec3(query.radiance[i])) << " at " << query.hitDistance[i]
                                 << " vs " << text(glm::vec3(pipeline.radiance[i])) << " at "
                                 << pipeline.hitDistance[i]);
            }
        }
        if (query.radiance[i].a == 1.0f) (query.hitDistance[i] == shader::kMissHitDistance ? misses : hits)++;
    }
    MESSAGE(hits << " hits and " << misses << " misses compared");
    CHECK(differing == 0);
    // 358 measured: the roof is single-sided and faces up, so the rays
    // from below pass through it (833 before back faces were culled).
    CHECK(hits > 300);
    CHECK(misses > 500);
}

TEST_CASE("only listed rays are traced; entries past the count, without a surface or a ray trace nothing") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    Rig rig(gpu.ctx(), hitScene(), test::testCamera());
    const std::vector<ListedRay> rays = hitTestRays(rig, 7);
    REQUIRE(rays.size() > 20);
    RayList list = toList(rays);
    // Entries that name nothing to trace: no ray, a sky pixel (top right:
    // over the floor's far end and beside the roof), a pixel outside the image.
    list.entries.push_back({shader::kNoRay, 0});
    list.entries.push_back({shader::packRayPixel({60, 0}, false), shader::packRayDirection({0, 1, 0})});
    list.entries.push_back({shader::packRayPixel({kSize + 3, 2}, false), shader::packRayDirection({0, 1, 0})});
    // A follower's entry names its quad leader: the leader's pixel is written.
    list.entries[0].pixelFlags = shader::packRayPixel(rays[0].pixel, true);
    list.count = uint32_t(list.entries.size());
    // Past the count: valid rays for every other floor pixel, which must
    // stay untouched.
    std::vector<bool> listed(size_t(kSize) * kSize, false);
    for (const ListedRay& r : rays) listed[pixelIndex(r.pixel)] = true;
    for (uint32_t y = kSize / 2 + 1; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            if (!listed[pixelIndex({x, y})]) {
                list.entries.push_back({shader::packRayPixel({x, y}, false), shader::packRayDirection({0, 1, 0})});
            }
        }
    }

    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        // Cleared first, so that what the trace leaves alone reads zero (the
        // frame itself clears nothing: its readers read listed pixels only).
        passes::RtTraceSettings settings = settingsFor(backend);
        settings.clearUntraced = true;
        const RtFrame f = rig.trace(pipelines, list, sunAndSky(), settings);
        uint32_t traced = 0;
        for (size_t i = 0; i < listed.size(); ++i) {
            CAPTURE(i);
            if (listed[i]) {
                ++traced;
                CHECK(f.radiance[i].a == 1.0f);
                CHECK(f.hitDistance[i] > 0.0f);
            } else {
                CHECK(f.untouched(i));
            }
        }
        CHECK(traced == rays.size());

        // An empty list (args {0, 1, 1, 0, 1, 1}) traces nothing, whatever
        // the list holds.
        RayList empty = list;
        empty.count = 0;
        const RtFrame none = rig.trace(pipelines, empty, sunAndSky(), settings);
        size_t touched = 0;
        for (size_t i = 0; i < listed.size(); ++i) touched += none.untouched(i) ? 0 : 1;
        CHECK(touched == 0);
    }
}

TEST_CASE("an unsupported backend is refused with a clear error") {
    gpu::ContextOptions options;
    options.disableRayQuery = true;
    test::GpuTest gpu(options);
    CHECK_FALSE(passes::RtTracePipelines::supported(gpu.ctx(), passes::RtBackend::RayQuery));
    CHECK_THROWS_WITH_AS(passes::RtTracePipelines(gpu.ctx(), passes::RtBackend::RayQuery),
                         doctest::Contains("has no ray query"), gpu::GpuError);
    // Auto falls back to the ray tracing pipeline (NVIDIA's case).
    passes::RtTracePipelines pipelines(gpu.ctx());
    CHECK((pipelines.backend() == passes::RtBackend::Pipeline));
}

TEST_CASE("an RT hit on an emissive triangle returns its emission: factor x strength x the texture's mean, scaled") {
    test::GpuTest gpu;
    const auto backends = availableBackends(gpu.ctx());
    REQUIRE_FALSE(backends.empty());
    // The target's left half emits through a 2x2 sRGB texture (the packed
    // primitives cannot carry it, so the hit adds the texture's mean,
    // linear); its right half, a second geometry of the same mesh, is black
    // and emits nothing: the table is read per (instance, geometry).
    scene::Scene s = hitScene();
    scene::Material black;
    black.baseColorFactor = {0.0f, 0.0f, 0.0f, 1.0f};
    s.materials.push_back(black);
    s.meshes[1].lods[0].geometries = {square({-0.5f, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}, 1.0f, 1),
                                      square({0.5f, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}, 1.0f, 3)};
    scene::prepareScene(s);
    scene::Texture texture;
    texture.name = "emissive";
    texture.width = texture.height = 2;
    texture.rgba8 = {255, 0, 0, 255, 0, 128, 0, 255, 0, 0, 64, 255, 200, 200, 200, 255};
    s.textures.push_back(texture);
    scene::Material& target = s.materials[1];
    target.baseColorFactor = {0.0f, 0.0f, 0.0f, 1.0f};
    target.emissiveFactor = {1.0f, 0.5f, 0.25f};
    target.emissiveStrength = 6.0f;
    target.emissiveTexture.texture = 0;
    glm::vec3 mean(0.0f);
    for (size_t t = 0; t < 4; ++t) {
        for (int c = 0; c < 3; ++c) {
            mean[c] += shader::srgbToLinear(float(texture.rgba8[t * 4 + size_t(c)]) / 255.0f) / 4.0f;
        }
    }
    constexpr float kEmissiveScale = 0.75f;
    const glm::vec3 expected = target.emissiveFactor * target.emissiveStrength * mean * kEmissiveScale;
    CHECK(near(scene::meanEmission(s, target), expected / kEmissiveScale, 1e-5f, 1e-6f));

    Rig rig(gpu.ctx(), s, test::testCamera());
    const std::vector<ListedRay> rays = hitTestRays(rig, 3);
    const RayList list = toList(rays);
    // No sun, a black sky: a hit's radiance is its emission alone, a miss's zero.
    shader::SceneLighting dark{};
    dark.sunDirection = glm::vec4(kSun, kEmissiveScale);
    std::vector<RtFrame> frames;
    for (const passes::RtBackend backend : backends) {
        const std::string name = passes::rtBackendName(backend);
        CAPTURE(name);
        passes::RtTracePipelines pipelines(gpu.ctx(), backend);
        frames.push_back(rig.trace(pipelines, list, dark, settingsFor(backend)));
        const RtFrame& f = frames.back();
        const glm::dmat4 worldToTarget = glm::inverse(glm::dmat4(rig.scene().instances[1].transform));
        uint32_t emissiveHits = 0, darkHits = 0;
        for (const ListedRay& r : rays) {
            const size_t i = pixelIndex(r.pixel);
            const glm::vec3 got(f.radiance[i]);
            if (!r.aimedAtTarget) {
                CHECK(got == glm::vec3(0.0f));
                continue;
            }
            // Which half the ray met, from its hit distance (the origin is
            // within millimetres of the analytic one).
            const glm::dvec3 hit = r.origin + double(f.hitDistance[i]) * glm::dvec3(r.direction);
            const double x = (worldToTarget * glm::dvec4(hit, 1.0)).x;
            if (std::abs(x) < 0.05) continue;
            const glm::vec3 want = x < 0.0 ? expected : glm::vec3(0.0f);
            INFO("pixel " << r.pixel.x << ", " << r.pixel.y << " (x " << x << "): " << text(got) << " vs " << text(want));
            // Half-float output: 2^-11 relative rounding.
            CHECK(near(got, want, 1.0f / 1024.0f, 1e-6f));
            ++(x < 0.0 ? emissiveHits : darkHits);
        }
        CHECK(emissiveHits > 20);
        CHECK(darkHits > 20);
    }
    // Both backends agree bit for bit on the traced pixels (the others are
    // never written: whatever the memory held).
    if (frames.size() == 2) {
        for (const ListedRay& r : rays) {
            const size_t i = pixelIndex(r.pixel);
            CHECK(frames[0].radianceBits[i] == frames[1].radianceBits[i]);
            CHECK(frames[0].hitDistance[i] == frames[1].hitDistance[i]);
        }
    }
}
