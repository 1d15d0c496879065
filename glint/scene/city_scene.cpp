// The built-in "city" (builtin_scenes.h): a wet street grid between blocks
// of instanced, finely tessellated buildings, sized by its options so the
// reflections can be measured against scene size.

#include "glint/scene/builtin_scenes.h"

#include "glint/scene/animation.h"
#include "glint/scene/error.h"
#include "glint/scene/mesh_tools.h"
#include "glint/scene/procedural_meshes.h"
#include "glint/scene/scene_builder.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

namespace glint::scene {

namespace {

// ---------------------------------------------------------------------------
// Layout (metres). Streets run along Z at x = k * kStreetPitch; each has a
// row of building plots on both sides, kSlotPitch apart along the street,
// every kCrossingEvery-th plot a cross street instead of a building.
// ---------------------------------------------------------------------------

constexpr float kRoadWidth = 10.0f;
constexpr float kSidewalkWidth = 3.0f;
constexpr float kStreetWidth = kRoadWidth + 2.0f * kSidewalkWidth;  // facade to facade
constexpr float kPlotDepth = 20.0f;                                   // a row's depth behind its facades
constexpr float kStreetPitch = kStreetWidth + 2.0f * kPlotDepth;      // 56: back-to-back rows between streets
constexpr float kSlotPitch = 24.0f;
constexpr uint32_t kCrossingEvery = 5;
constexpr float kKerbHeight = 0.15f;
constexpr float kFloorHeight = 3.2f;
// The first plot's centre; the main street runs from here towards -Z, the
// camera path starting a little behind it.
constexpr float kFirstSlotZ = 2.0f * kSlotPitch;

// A kind of building: footprint (street-facing width x depth), floors, bay
// width, and its materials' looks.
struct BuildingKind {
    const char* name;
    float width, depth;
    uint32_t floors;
    float bay;
    glm::vec3 wall;
    float wallRoughness;
    bool mirrorGlass;  // office glass (metallic, near mirror) rather than dark window glass
    bool shopfront;    // a glazed ground floor with a lit sign band
};

constexpr std::array<BuildingKind, 6> kKinds = {{
    {"ochre apartments", 20.0f, 14.0f, 8, 2.5f, {0.72f, 0.55f, 0.36f}, 0.85f, false, true},
    {"blue apartments", 16.0f, 14.0f, 11, 2.6f, {0.25f, 0.42f, 0.55f}, 0.8f, false, false},
    {"white block", 22.0f, 16.0f, 6, 3.0f, {0.82f, 0.8f, 0.76f}, 0.7f, false, true},
    {"glass office", 20.0f, 18.0f, 18, 2.2f, {0.35f, 0.37f, 0.4f}, 0.4f, true, false},
    {"brick walk-up", 14.0f, 12.0f, 5, 2.4f, {0.45f, 0.2f, 0.14f}, 0.9f, false, true},
    {"concrete tower", 18.0f, 18.0f, 24, 2.4f, {0.5f, 0.5f, 0.52f}, 0.75f, true, false},
}};

struct CityMaterials {
    uint32_t road, sidewalk, kerb, ground, frame, sign, lampGlow, lampPost, tyre, carGlass;
    std::array<uint32_t, kKinds.size()> wall{}, glass{};
    std::array<uint32_t, 4> carPaint{};
};

// Wet asphalt: glossy under its film of water, near-mirror in puddles (an
// fBm mask, as the plaza's paving; Lagarde, "Water drop 2b - Dynamic rain
// and its effects", 2013), lane markings.
struct RoadTextures {
    Texture baseColor;
    Texture metallicRoughness;
};

RoadTextures makeRoadTextures(uint32_t size, uint32_t seed) {
    RoadTextures t;
    t.baseColor = {"wet_asphalt_base_color", size, size, TextureFormat::Rgba8, {}, {}};
    t.metallicRoughness = {"wet_asphalt_metallic_roughness", size, size, TextureFormat::Rgba8, {}, {}};
    t.baseColor.rgba8.resize(size_t(size) * size * 4);
    t.metallicRoughness.rgba8.resize(size_t(size) * size * 4);
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            // The texture spans 10 m across the road (u) and 10 m along it (v).
            const float u = (float(x) + 0.5f) / float(size);
            const float v = (float(y) + 0.5f) / float(size);
            const float grain = 0.85f + 0.3f * valueNoise(u * 128.0f, v * 128.0f, 128, seed + 3u);
            const float puddle = glm::smoothstep(0.55f, 0.6f, fbm(u, v, seed + 11u));
            // A dashed centre line (0.15 m wide, 3 m dashes every 6 m).
            const bool marking = std::abs(u - 0.5f) < 0.0075f && std::fmod(v * 10.0f, 6.0f) < 3.0f;
            glm::vec3 albedo = glm::vec3(0.07f, 0.07f, 0.075f) * grain;
            // A film of water on the whole road: glossy (0.08-0.18) between the
            // puddles, so that the street reflects everywhere, blurred.
            float roughness = 0.08f + 0.1f * grain;
            if (marking) {
                albedo = glm::vec3(0.7f, 0.68f, 0.6f);
                roughness = 0.5f;
            }
            albedo *= 1.0f - 0.5f * puddle;
            roughness = glm::mix(roughness, 0.02f, puddle);
            const size_t i = (size_t(y) * size + x) * 4;
            t.baseColor.rgba8[i + 0] = toSrgbByte(albedo.r);
            t.baseColor.rgba8[i + 1] = toSrgbByte(albedo.g);
            t.baseColor.rgba8[i + 2] = toSrgbByte(albedo.b);
            t.baseColor.rgba8[i + 3] = 255;
            t.metallicRoughness.rgba8[i + 0] = 255;
            t.metallicRoughness.rgba8[i + 1] = toByte(roughness);
            t.metallicRoughness.rgba8[i + 2] = 0;
            t.metallicRoughness.rgba8[i + 3] = 255;
        }
    }
    return t;
}

CityMaterials cityMaterials(SceneBuilder& b, uint32_t seed) {
    CityMaterials m{};
    const RoadTextures road = makeRoadTextures(256, seed);
    Material wet = makeMaterial("wet asphalt", glm::vec3(1.0f), 1.0f, 1.0f);
    wet.baseColorTexture.texture = b.texture(road.baseColor);
    wet.metallicRoughnessTexture.texture = b.texture(road.metallicRoughness);
    m.road = b.material(wet);
    m.sidewalk = b.material(makeMaterial("wet paving slabs", {0.3f, 0.28f, 0.26f}, 0.0f, 0.2f));
    m.kerb = b.material(makeMaterial("granite kerb", {0.35f, 0.35f, 0.36f}, 0.0f, 0.5f));
    m.ground = b.material(makeMaterial("waste ground", {0.12f, 0.11f, 0.1f}, 0.0f, 0.95f));
    m.frame = b.material(makeMaterial("stone trim", {0.6f, 0.58f, 0.55f}, 0.0f, 0.6f));
    m.sign = b.material(makeEmissive("shop sign", {1.0f, 0.45f, 0.2f}, 2.5f));
    m.lampGlow = b.material(makeEmissive("street lamp", {1.0f, 0.8f, 0.55f}, 5.0f));
    m.lampPost = b.material(makeMaterial("painted steel", {0.05f, 0.06f, 0.05f}, 1.0f, 0.35f));
    m.tyre = b.material(makeMaterial("tyre rubber", {0.03f, 0.03f, 0.03f}, 0.0f, 0.8f));
    m.carGlass = b.material(makeMaterial("car glass", {0.02f, 0.02f, 0.025f}, 0.0f, 0.03f));
    for (size_t k = 0; k < kKinds.size(); ++k) {
        const BuildingKind& kind = kKinds[k];
        m.wall[k] = b.material(makeMaterial(std::string(kind.name) + " wall", kind.wall, 0.0f, kind.wallRoughness));
        m.glass[k] = b.material(kind.mirrorGlass
                                    ? makeMaterial(std::string(kind.name) + " glass", {0.6f, 0.66f, 0.7f}, 1.0f, 0.04f)
                                    : makeMaterial(std::string(kind.name) + " glass", {0.02f, 0.025f, 0.03f}, 0.0f,
                                                   0.03f));
    }
    const std::array<glm::vec3, 4> paints = {
        glm::vec3{0.5f, 0.03f, 0.02f}, {0.04f, 0.09f, 0.45f}, {0.8f, 0.8f, 0.78f}, {0.02f, 0.02f, 0.02f}};
    for (size_t c = 0; c < paints.size(); ++c) {
        m.carPaint[c] = b.material(makeMaterial("car paint " + std::to_string(c), paints[c], 0.3f, 0.1f));
    }
    return m;
}

// ---------------------------------------------------------------------------
// Geometry
// ---------------------------------------------------------------------------

// Appends a flat rectangle from `origin` spanning `u` and `v` (its normal
// is u x v), split into cells.x x cells.y quads, texture coordinates in
// metres.
void appendPanel(Geometry& g, const glm::vec3& origin, const glm::vec3& u, const glm::vec3& v, glm::uvec2 cells) {
    const glm::vec3 n = glm::normalize(glm::cross(u, v));
    const float lu = glm::length(u), lv = glm::length(v);
    const uint32_t first = g.vertexCount();
    for (uint32_t j = 0; j <= cells.y; ++j) {
        for (uint32_t i = 0; i <= cells.x; ++i) {
            const float a = float(i) / float(cells.x), c = float(j) / float(cells.y);
            g.positions.push_back(origin + a * u + c * v);
            g.normals.push_back(n);
            g.texcoords0.push_back({a * lu, c * lv});
        }
    }
    const uint32_t row = cells.x + 1;
    for (uint32_t j = 0; j < cells.y; ++j) {
        for (uint32_t i = 0; i < cells.x; ++i) {
            const uint32_t a = first + j * row + i;
            // Counter-clockwise seen from n: (0,0), (1,0), (1,1), (0,1).
            g.indices.insert(g.indices.end(), {a, a + 1, a + 1 + row, a, a + 1 + row, a + row});
        }
    }
}

Geometry finished(Geometry g, uint32_t material) {
    g.material = material;
    generateTangents(g);
    g.bounds = computeBounds(g.positions);
    return g;
}

// Window openings of a facade cell (fractions of the cell): the margins
// left and right, below and above; shopfronts open most of the ground floor.
constexpr float kWindowSide = 0.22f, kWindowBelow = 0.28f, kWindowAbove = 0.15f;
constexpr float kShopSide = 0.06f, kShopBelow = 0.04f, kShopAbove = 0.3f;
constexpr float kRecess = 0.25f;  // how deep windows sit behind the wall

// Triangles of one facade cell at subdivision s: the wall around the
// opening (4 panels of s x s), the reveals (4 of s x 1) and the pane (s x s).
uint64_t cellTriangles(uint32_t s) { return 2ull * (5ull * s * s + 4ull * s); }

struct Facade {
    glm::vec3 origin;  // bottom-left corner, seen from outside
    glm::vec3 right;   // unit, along the facade
    glm::vec3 out;     // unit outward normal
    float width;
    uint32_t bays;
};

// The facades of a building centred on the origin, the street side facing +Z.
std::array<Facade, 4> facades(const BuildingKind& kind) {
    const float hw = 0.5f * kind.width, hd = 0.5f * kind.depth;
    const auto bays = [&](float w) { return std::max(1u, uint32_t(std::lround(w / kind.bay))); };
    return {{
        {{-hw, 0, hd}, {1, 0, 0}, {0, 0, 1}, kind.width, bays(kind.width)},
        {{hw, 0, -hd}, {-1, 0, 0}, {0, 0, -1}, kind.width, bays(kind.width)},
        {{hw, 0, hd}, {0, 0, -1}, {1, 0, 0}, kind.depth, bays(kind.depth)},
        {{-hw, 0, -hd}, {0, 0, 1}, {-1, 0, 0}, kind.depth, bays(kind.depth)},
    }};
}

uint32_t facadeCells(const BuildingKind& kind) {
    uint32_t cells = 0;
    for (const Facade& f : facades(kind)) cells += f.bays * kind.floors;
    return cells;
}

// One building at subdivision `s`: wall, window panes (recessed, their own
// glass material), trim (a cornice per floor), the roof; with a shopfront,
// a lit sign band above the ground floor on the street side.
std::vector<Geometry> buildingGeometry(const BuildingKind& kind, size_t kindIndex, const CityMaterials& mat,
                                       uint32_t s, bool cornices) {
    Geometry wall, glass, trim, sign;
    const glm::vec3 up(0, 1, 0);
    const float height = float(kind.floors) * kFloorHeight;
    const glm::uvec2 fine{s, s}, reveal{s, 1};
    for (const Facade& f : facades(kind)) {
        const float bayWidth = f.width / float(f.bays);
        for (uint32_t floor = 0; floor < kind.floors; ++floor) {
            const bool shop = kind.shopfront && floor == 0;
            const float side = (shop ? kShopSide : kWindowSide) * bayWidth;
            const float below = (shop ? kShopBelow : kWindowBelow) * kFloorHeight;
            const float above = (shop ? kShopAbove : kWindowAbove) * kFloorHeight;
            for (uint32_t bay = 0; bay < f.bays; ++bay) {
                const glm::vec3 corner = f.origin + f.right * (float(bay) * bayWidth) + up * (float(floor) * kFloorHeight);
                const float openW = bayWidth - 2.0f * side, openH = kFloorHeight - below - above;
                const glm::vec3 openCorner = corner + f.right * side + up * below;
                // The wall around the opening.
                appendPanel(wall, corner, f.right * bayWidth, up * below, fine);
                appendPanel(wall, corner + up * (below + openH), f.right * bayWidth, up * above, fine);
                appendPanel(wall, corner + up * below, f.right * side, up * openH, fine);
                appendPanel(wall, openCorner + f.right * openW, f.right * side, up * openH, fine);
                // The reveals, from the wall's plane back to the pane.
                const glm::vec3 back = -f.out * kRecess;
                // Each panel's normal is u x v (appendPanel): into the opening.
                appendPanel(wall, openCorner, back, up * openH, {1, s});                          // left, faces +right
                appendPanel(wall, openCorner + f.right * openW + back, -back, up * openH, {1, s});  // right, faces -right
                appendPanel(wall, openCorner, f.right * openW, back, reveal);                     // sill, faces up
                appendPanel(wall, openCorner + up * openH, back, f.right * openW, {1, s});        // head, faces down
                appendPanel(glass, openCorner + back, f.right * openW, up * openH, fine);
            }
            if (cornices && floor > 0) {
                // A stone band along the facade at each floor line.
                Geometry band = makeBox({f.width + 0.2f, 0.18f, 0.2f}, 0, 1.0f);
                const glm::vec3 centre = f.origin + f.right * (0.5f * f.width) + up * (float(floor) * kFloorHeight) +
                                         f.out * 0.1f;
                const glm::mat4 frame(glm::vec4(f.right, 0), glm::vec4(up, 0), glm::vec4(f.out, 0),
                                      glm::vec4(centre, 1));
                appendGeometry(trim, transformed(band, frame));
            }
        }
        if (kind.shopfront && f.out.z > 0.5f) {
            Geometry band = makeBox({f.width * 0.8f, 0.5f, 0.12f}, 0, 1.0f);
            const glm::vec3 centre = f.origin + f.right * (0.5f * f.width) +
                                     up * ((1.0f - 0.5f * kShopAbove) * kFloorHeight) + f.out * 0.06f;
            appendGeometry(sign, transformed(band, glm::translate(glm::mat4(1.0f), centre)));
        }
    }
    // The roof and its parapet.
    appendGeometry(trim, transformed(makeBox({kind.width, 0.6f, kind.depth}, 0, 1.0f),
                                     glm::translate(glm::mat4(1.0f), {0, height + 0.3f, 0})));
    std::vector<Geometry> parts;
    parts.push_back(finished(std::move(wall), mat.wall[kindIndex]));
    parts.push_back(finished(std::move(glass), mat.glass[kindIndex]));
    parts.push_back(finished(std::move(trim), mat.frame));
    if (!sign.indices.empty()) parts.push_back(finished(std::move(sign), mat.sign));
    return parts;
}

// The largest subdivision whose facade cells stay within `triangles`.
uint32_t subdivisionFor(const BuildingKind& kind, uint64_t triangles) {
    const uint64_t cells = facadeCells(kind);
    uint32_t s = 1;
    while (s < 64 && cells * cellTriangles(s + 1) <= triangles) ++s;
    return s;
}

// A street segment one plot long: the road between two raised sidewalks.
std::vector<Geometry> streetGeometry(const CityMaterials& mat) {
    std::vector<Geometry> parts;
    Geometry road = makeGrid({kRoadWidth, kSlotPitch}, {10, 24}, mat.road, 0.1f);
    parts.push_back(std::move(road));
    for (const float side : {-1.0f, 1.0f}) {
        const float x = side * (0.5f * kRoadWidth + 0.5f * kSidewalkWidth);
        parts.push_back(transformed(makeBox({kSidewalkWidth, kKerbHeight, kSlotPitch}, mat.sidewalk, 0.5f),
                                    translation({x, 0.5f * kKerbHeight, 0})));
    }
    return parts;
}

// A cross street: road across the two plot rows between this street and the next.
std::vector<Geometry> crossingGeometry(const CityMaterials& mat) {
    const float length = 2.0f * kPlotDepth;
    Geometry road = makeGrid({length, kRoadWidth}, {40, 10}, mat.road, 0.1f);
    std::vector<Geometry> parts;
    parts.push_back(std::move(road));
    return parts;
}

std::vector<Geometry> carGeometry(const CityMaterials& mat, uint32_t paint) {
    std::vector<Geometry> parts;
    parts.push_back(transformed(makeBox({1.8f, 0.7f, 4.3f}, paint), translation({0, 0.65f, 0})));
    parts.push_back(transformed(makeBox({1.6f, 0.55f, 2.3f}, mat.carGlass), translation({0, 1.27f, -0.2f})));
    Geometry wheels;
    for (const float x : {-0.85f, 0.85f}) {
        for (const float z : {-1.4f, 1.4f}) {
            const glm::mat4 m = glm::translate(glm::mat4(1.0f), {x - 0.1f, 0.33f, z}) *
                                glm::mat4_cast(axisAngle({0, 0, 1}, -glm::half_pi<float>()));
            appendGeometry(wheels, transformed(makeCylinder(0.33f, 0.22f, 16, mat.tyre), m));
        }
    }
    wheels.material = mat.tyre;
    parts.push_back(std::move(wheels));
    return parts;
}

uint32_t parseValue(std::string_view spec, std::string_view key, std::string_view text) {
    uint32_t value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || text.empty()) {
        throw SceneError(std::string(spec), std::string(key),
                         "'" + std::string(text) + "' is not a non-negative integer");
    }
    return value;
}

} // namespace

CityOptions parseCityOptions(std::string_view spec) {
    CityOptions options;
    const size_t colon = spec.find(':');
    if (spec.substr(0, colon) != "city") {
        throw SceneError(std::string(spec), "", "not a city scene (city or city:instances=N,triangles=T,seed=S)");
    }
    if (colon == std::string_view::npos) return options;
    std::string_view rest = spec.substr(colon + 1);
    while (!rest.empty()) {
        const size_t comma = rest.find(',');
        const std::string_view item = rest.substr(0, comma);
        rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
        const size_t equals = item.find('=');
        if (equals == std::string_view::npos) {
            throw SceneError(std::string(spec), std::string(item), "expected KEY=VALUE (instances, triangles, seed)");
        }
        const std::string_view key = item.substr(0, equals), value = item.substr(equals + 1);
        if (key == "instances") {
            options.instances = parseValue(spec, key, value);
        } else if (key == "triangles") {
            options.triangles = parseValue(spec, key, value);
        } else if (key == "seed") {
            options.seed = parseValue(spec, key, value);
        } else {
            throw SceneError(std::string(spec), std::string(key), "unknown option (instances, triangles, seed)");
        }
    }
    if (options.instances < kCityMinInstances || options.instances > kCityMaxInstances) {
        throw SceneError(std::string(spec), "instances",
                         std::to_string(options.instances) + " is outside " + std::to_string(kCityMinInstances) +
                             ".." + std::to_string(kCityMaxInstances));
    }
    if (options.triangles < kCityMinTriangles || options.triangles > kCityMaxTriangles) {
        throw SceneError(std::string(spec), "triangles",
                         std::to_string(options.triangles) + " is outside " + std::to_string(kCityMinTriangles) +
                             ".." + std::to_string(kCityMaxTriangles));
    }
    return options;
}

Scene makeCity(const CityOptions& options) {
    if (options.instances < kCityMinInstances || options.instances > kCityMaxInstances ||
        options.triangles < kCityMinTriangles || options.triangles > kCityMaxTriangles) {
        throw SceneError("city", "", "instances must lie in " + std::to_string(kCityMinInstances) + ".." +
                                         std::to_string(kCityMaxInstances) + ", triangles in " +
                                         std::to_string(kCityMinTriangles) + ".." + std::to_string(kCityMaxTriangles));
    }
    SceneBuilder b("city");
    const CityMaterials mat = cityMaterials(b, options.seed);
    Scene& s = b.scene;

    // Each kind at full detail (LOD 0) and at half the subdivision for the
    // reflection BLAS (LOD 1: Far Cry 6 traces reflections against a lower
    // LOD), without the cornices.
    std::array<uint32_t, kKinds.size()> buildingMesh{};
    for (size_t k = 0; k < kKinds.size(); ++k) {
        const uint32_t sub = subdivisionFor(kKinds[k], options.triangles);
        buildingMesh[k] = b.mesh(kKinds[k].name, {buildingGeometry(kKinds[k], k, mat, sub, true),
                                                  buildingGeometry(kKinds[k], k, mat, std::max(1u, sub / 2), false)});
    }
    const uint32_t streetMesh = b.mesh("street", {streetGeometry(mat)});
    const uint32_t crossingMesh = b.mesh("cross street", {crossingGeometry(mat)});

    // Plots per row: the rows grow longer with the city (about 1.25 sqrt(2N)
    // plots), so the main street's canyon lengthens as well as widening
    // into more streets.
    const uint32_t n = options.instances;
    const uint32_t slots =
        std::clamp(uint32_t(std::ceil(1.25 * std::sqrt(2.0 * double(n)))), 10u, 80u);
    const uint32_t buildingsPerRow = slots - slots / kCrossingEvery;
    const uint32_t rows = (n + buildingsPerRow - 1) / buildingsPerRow;
    // Rows in order 0 (main street, west side), 1 (main, east), then the
    // streets at x = +pitch, -pitch, +2 pitch, ... each with both sides.
    const auto streetOfRow = [](uint32_t row) {
        const int32_t k = int32_t(row / 2);  // 0, 0, 1, 1, 2, 2, ...
        return k == 0 ? 0 : (k % 2 ? (k + 1) / 2 : -(k / 2));
    };
    const auto slotZ = [](uint32_t slot) { return kFirstSlotZ - float(slot) * kSlotPitch; };

    uint32_t placed = 0;
    for (uint32_t row = 0; row < rows; ++row) {
        const int32_t street = streetOfRow(row);
        const float side = row % 2 == 0 ? -1.0f : 1.0f;  // west, east of the street's centre line
        const float streetX = float(street) * kStreetPitch;
        for (uint32_t slot = 0; slot < slots && placed < n; ++slot) {
            if (slot % kCrossingEvery == kCrossingEvery - 1) continue;
            const uint32_t kind = uint32_t(hash01(int32_t(row), int32_t(slot), options.seed) * float(kKinds.size()));
            const BuildingKind& k = kKinds[std::min<size_t>(kind, kKinds.size() - 1)];
            // Facing the street: the front (+Z) turned to -side along X.
            const float x = streetX + side * (0.5f * kStreetWidth + 0.5f * k.depth);
            const glm::quat facing = axisAngle({0, 1, 0}, side < 0.0f ? glm::half_pi<float>() : -glm::half_pi<float>());
            b.place("building " + std::to_string(placed), buildingMesh[std::min<size_t>(kind, kKinds.size() - 1)],
                    {x, 0.0f, slotZ(slot)}, facing);
            ++placed;
        }
    }
    // Street segments along every street, cross streets between each street
    // and the next one east.
    int32_t westmost = 0, eastmost = 0;
    for (uint32_t row = 0; row < rows; ++row) {
        westmost = std::min(westmost, streetOfRow(row));
        eastmost = std::max(eastmost, streetOfRow(row));
    }
    for (int32_t street = westmost; street <= eastmost; ++street) {
        const float streetX = float(street) * kStreetPitch;
        for (uint32_t slot = 0; slot < slots; ++slot) {
            b.place("street " + std::to_string(street) + "." + std::to_string(slot), streetMesh,
                    {streetX, 0.0f, slotZ(slot)});
            // East of every street, and west of the westmost one (the cross
            // street between two streets belongs to the western one).
            if (slot % kCrossingEvery == kCrossingEvery - 1) {
                for (const float side : {-1.0f, 1.0f}) {
                    if (side < 0.0f && street != westmost) continue;
                    b.place("cross street " + std::to_string(street) + "." + std::to_string(slot) +
                                (side < 0 ? "w" : "e"),
                            crossingMesh, {streetX + side * (0.5f * kStreetWidth + kPlotDepth), 0.0f, slotZ(slot)});
                }
            }
        }
    }
    // The ground the blocks stand on, reaching past the city to the horizon
    // (long range: the BVH keeps it beyond its radius).
    {
        const float extentX = float(eastmost - westmost + 1) * kStreetPitch + 400.0f;
        const float extentZ = float(slots) * kSlotPitch + 400.0f;
        const float centreX = 0.5f * float(eastmost + westmost) * kStreetPitch;
        const float centreZ = kFirstSlotZ - 0.5f * float(slots - 1) * kSlotPitch;
        const uint32_t ground =
            b.mesh("city ground", {{makeGrid({extentX, extentZ}, {16, 16}, mat.ground, 0.05f)}});
        b.place("city ground", ground, {centreX, -0.02f, centreZ}).longRange = true;
    }

    // Street lamps on the main street's sidewalks, one per plot each side.
    {
        const uint32_t lamp = b.mesh(
            "street lamp", {{makeCylinder(0.09f, 6.0f, 12, mat.lampPost),
                             transformed(makeSphere(0.35f, 16, 8, mat.lampGlow), translation({0, 6.2f, 0}))}});
        for (uint32_t slot = 0; slot < slots; ++slot) {
            for (const float side : {-1.0f, 1.0f}) {
                b.place("street lamp " + std::to_string(slot) + (side < 0 ? "w" : "e"), lamp,
                        {side * (0.5f * kRoadWidth + 0.4f), kKerbHeight, slotZ(slot) + 0.25f * kSlotPitch});
            }
        }
    }

    // Traffic: cars driving both ways along every street, looping over its
    // length (rigid motion: TLAS instance updates, motion vectors).
    {
        std::array<uint32_t, 4> carMesh{};
        for (size_t c = 0; c < carMesh.size(); ++c) {
            carMesh[c] = b.mesh("car " + std::to_string(c), {carGeometry(mat, mat.carPaint[c])});
        }
        const uint32_t cars = std::clamp(n / 4u, 4u, 96u);
        const float length = float(slots) * kSlotPitch;
        const float period = length / 9.0f;  // 9 m/s, about 32 km/h
        Animation traffic;
        traffic.name = "traffic";
        for (uint32_t c = 0; c < cars; ++c) {
            const int32_t street = westmost + int32_t(c % uint32_t(eastmost - westmost + 1));
            const bool north = c % 2 == 0;  // towards -Z, in the west lane
            const float x = float(street) * kStreetPitch + (north ? -0.25f : 0.25f) * kRoadWidth;
            const std::string name = "car " + std::to_string(c);
            const glm::quat heading = north ? glm::quat(1, 0, 0, 0) : axisAngle({0, 1, 0}, glm::pi<float>());
            const uint32_t node = b.node(name, kNone, {x, 0.0f, 0.0f}, heading);
            b.instance(name, carMesh[c % carMesh.size()], node, Motion::Dynamic);
            // Where along the street (0..1) the car is at time 0; it wraps
            // back to the street's start once a period, within a millisecond.
            const float phase = 0.05f + 0.9f * hash01(int32_t(c), 7, options.seed);
            const float wrap = (1.0f - phase) * period;
            const float startZ = kFirstSlotZ + 0.5f * kSlotPitch;
            const auto at = [&](float along) {
                return glm::vec3(x, 0.0f, north ? startZ - along * length : startZ - length + along * length);
            };
            b.keyedTrack(traffic, node, AnimationPath::Translation, {0.0f, wrap - 1e-3f, wrap, period},
                         {glm::vec4(at(phase), 0.0f), glm::vec4(at(1.0f), 0.0f), glm::vec4(at(0.0f), 0.0f),
                          glm::vec4(at(phase), 0.0f)});
        }
        b.play(std::move(traffic));
    }

    // --- Light, sky, camera: a low afternoon sun after rain.
    s.sun.directionToLight = glm::normalize(glm::vec3(0.55f, 0.4f, -0.45f));
    s.sun.color = {1.0f, 0.85f, 0.7f};
    s.sun.illuminance = 70000.0f;
    s.environment.sky.zenithColor = {0.2f, 0.32f, 0.55f};
    s.environment.sky.horizonColor = {0.85f, 0.75f, 0.65f};
    s.environment.sky.groundColor = {0.1f, 0.1f, 0.1f};
    s.lens = {glm::radians(60.0f), 0.1f, kInfiniteFar};
    // Down the main street: the canyon ahead mirrored in the puddles (SSLR
    // can), then turned towards the facades, whose windows mirror the
    // street behind and beside the camera (only RT can), down at the
    // puddles, and up above the traffic.
    const float z0 = kFirstSlotZ;
    s.cameraPath.keys = {
        {0.0f, {-2.0f, 1.7f, z0 + 10.0f}, {-1.0f, 1.3f, z0 - 60.0f}},
        {5.0f, {0.5f, 1.7f, z0 - 25.0f}, {3.0f, 1.0f, z0 - 90.0f}},
        {9.0f, {2.5f, 1.6f, z0 - 50.0f}, {-8.0f, 3.0f, z0 - 56.0f}},
        {13.0f, {-2.5f, 1.7f, z0 - 70.0f}, {5.0f, 0.0f, z0 - 82.0f}},
        {17.0f, {0.0f, 4.5f, z0 - 95.0f}, {0.0f, 1.0f, z0 - 170.0f}},
        {20.0f, {-1.0f, 1.7f, z0 - 110.0f}, {-1.0f, 1.3f, z0 - 180.0f}},
    };
    const auto pathView = [&](const char* name, float seconds) {
        const CameraPose pose = s.cameraPath.evaluate(seconds);
        s.views.push_back({name, s.lens, pose.position, pose.target});
    };
    pathView("down-street", 0.0f);
    pathView("facades", 9.0f);
    pathView("puddles", 13.0f);
    pathView("overlook", 17.0f);
    prepareScene(s);
    return std::move(b.scene);
}

} // namespace glint::scene
