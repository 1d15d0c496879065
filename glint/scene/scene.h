#pragma once
// The scene model: what a frame needs to know about the world. Plain data
// with indices instead of pointers, so an engine can fill it from its own
// assets; the glTF loader (gltf_loader.h) and the built-in scenes
// (builtin_scenes.h) are two such fillers. After filling, call
// prepareScene() (animation.h) once, then advanceScene() every frame.

#include "glint/scene/camera.h"

#include "glint/packing.h"
#include "glint/texture_transform.h"

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_precision.hpp>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace glint::scene {

// "No index" for the int32_t references below.
inline constexpr int32_t kNone = -1;

// ---------------------------------------------------------------------------
// Bounds
// ---------------------------------------------------------------------------

struct Aabb {
    glm::vec3 min{std::numeric_limits<float>::infinity()};
    glm::vec3 max{-std::numeric_limits<float>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    glm::vec3 center() const { return (min + max) * 0.5f; }
    glm::vec3 size() const { return max - min; }
    void extend(const glm::vec3& p);
    void extend(const Aabb& b);
};

// Bounds of `box` after `transform` (all eight corners).
Aabb transformBounds(const Aabb& box, const glm::mat4& transform);
// Euclidean distance from `point` to the box; 0 inside.
float distanceToBounds(const Aabb& box, const glm::vec3& point);

// ---------------------------------------------------------------------------
// Textures and materials
// ---------------------------------------------------------------------------

enum class TextureFormat : uint8_t { Rgba8, Rgba32Float };

// A decoded image, base level only (mips are the GPU side's business).
// Colour space is a property of the material slot that uses it (glTF: base
// colour and emissive are sRGB, the others linear), not of the texture.
struct Texture {
    std::string name;
    uint32_t width = 0;
    uint32_t height = 0;
    TextureFormat format = TextureFormat::Rgba8;
    std::vector<uint8_t> rgba8;  // width * height * 4 when Rgba8
    std::vector<float> rgba32f;  // width * height * 4 when Rgba32Float

    bool valid() const;
    // Texel (x, y) as stored: 8-bit values map to [0, 1], no colour-space
    // conversion.
    glm::vec4 texel(uint32_t x, uint32_t y) const;
};

enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

struct TextureRef {
    int32_t texture = kNone;  // index into Scene::textures
    // 0: texcoords0, 1: texcoords1 (KHR_texture_transform's texCoord
    // override already applied).
    uint32_t texCoord = 0;
    Wrap wrapS = Wrap::Repeat;
    Wrap wrapT = Wrap::Repeat;
    // KHR_texture_transform; the defaults are the identity.
    glm::vec2 offset{0.0f};
    float rotation = 0.0f;  // radians
    glm::vec2 scale{1.0f};

    bool valid() const { return texture != kNone; }
    // The affine map the shaders and the CPU sampling apply to the
    // texture coordinates (glint/texture_transform.h).
    shader::UvTransform uvTransform() const { return shader::makeUvTransform(offset, rotation, scale); }
};

// Bilinear sample of the base level at `uv` (glTF convention: (0, 0) is the
// top-left corner of the image).
glm::vec4 sampleBilinear(const Texture& texture, glm::vec2 uv, Wrap wrapS, Wrap wrapT);

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// glTF 2.0 metallic-roughness material; defaults are the glTF defaults.
struct Material {
    std::string name;
    glm::vec4 baseColorFactor{1.0f};
    float metallicFactor = 1.0f;
    float roughnessFactor = 1.0f;
    glm::vec3 emissiveFactor{0.0f};
    float emissiveStrength = 1.0f;  // KHR_materials_emissive_strength
    float normalScale = 1.0f;
    float occlusionStrength = 1.0f;
    // Dielectric specular, Filament's convention (see glint/packing.h);
    // from KHR_materials_ior when a file gives an index of refraction.
    float reflectance = shader::kDefaultReflectance;
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    bool doubleSided = false;

    TextureRef baseColorTexture;          // sRGB; RGB times factor, A = alpha
    TextureRef metallicRoughnessTexture;  // linear; G = roughness, B = metallic
    TextureRef normalTexture;             // linear; tangent-space normal
    TextureRef emissiveTexture;           // sRGB
    TextureRef occlusionTexture;          // linear; R
};

// ---------------------------------------------------------------------------
// Geometry
// ---------------------------------------------------------------------------

// A morph target (glTF 2.0 3.7.2.2): per-vertex displacements added, times
// the target's weight, to the base attributes. Arrays are empty or one
// entry per vertex of the geometry.
struct MorphTarget {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec3> tangents;  // xyz only; the sign stays the base's
};

// One draw of one material (a glTF primitive), always an indexed triangle
// list. Attribute arrays are either empty or one entry per position.
struct Geometry {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec4> tangents;  // xyz tangent, w = bitangent sign
    std::vector<glm::vec2> texcoords0;
    std::vector<glm::vec2> texcoords1;
    std::vector<glm::vec4> colors;     // linear RGBA, multiplies base colour
    std::vector<glm::u16vec4> joints;  // skinned: indices into the skin's joints
    std::vector<glm::vec4> weights;    // skinned: weights summing to 1
    std::vector<uint32_t> indices;     // three per triangle
    // Every geometry of a mesh has the same number of targets as the mesh
    // has default weights (Mesh::morphWeights).
    std::vector<MorphTarget> morphTargets;
    uint32_t material = 0;
    Aabb bounds;  // of positions (the base shape, without morphing)

    uint32_t vertexCount() const { return uint32_t(positions.size()); }
    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
    bool skinned() const { return !joints.empty(); }
};

struct MeshLod {
    std::vector<Geometry> geometries;
};

struct Mesh {
    std::string name;
    std::vector<MeshLod> lods;  // lods[0] is full detail, each next one coarser
    // LOD the reflection BLAS uses. Unset: lods[1] when the mesh has one
    // (Far Cry 6 traces reflections against a lower LOD).
    std::optional<uint32_t> reflectionLod;
    Aabb bounds;  // of lods[0], with every shape its morph targets reach at weights in [0, 1]
    // Default morph target weights (glTF mesh.weights, zeros when absent),
    // one per target of each LOD-0 geometry; empty: the mesh does not morph.
    std::vector<float> morphWeights;
};

uint32_t reflectionLodIndex(const Mesh& mesh);
uint64_t triangleCount(const MeshLod& lod);

// ---------------------------------------------------------------------------
// Hierarchy, skins, animation
// ---------------------------------------------------------------------------

struct Node {
    std::string name;
    int32_t parent = kNone;
    glm::vec3 translation{0.0f};
    glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
    glm::vec3 scale{1.0f};
    // glTF lets a node give a matrix instead of TRS; such a node is not
    // animated.
    std::optional<glm::mat4> matrix;
    // Morph target weights of the mesh this node instantiates (glTF
    // node.weights, else the mesh's defaults); animated by `weights`
    // channels. Empty when the mesh does not morph.
    std::vector<float> morphWeights;

    glm::mat4 localTransform() const;
};

struct Skin {
    std::string name;
    std::vector<uint32_t> joints;                // node indices
    std::vector<glm::mat4> inverseBindMatrices;  // one per joint
};

enum class Interpolation : uint8_t { Step, Linear, CubicSpline };
enum class AnimationPath : uint8_t { Translation, Rotation, Scale, Weights };

struct AnimationSampler {
    Interpolation interpolation = Interpolation::Linear;
    std::vector<float> times;  // seconds, non-decreasing
    // One value per key (xyz for translation and scale, quaternion xyzw for
    // rotation); CUBICSPLINE stores three per key: in-tangent, value,
    // out-tangent.
    std::vector<glm::vec4> values;
    // Morph target weights (AnimationPath::Weights): `weightCount` floats
    // per value, in the same key layout as `values`, which stays empty.
    std::vector<float> weights;
    uint32_t weightCount = 0;
};

struct AnimationChannel {
    uint32_t sampler = 0;
    uint32_t node = 0;
    AnimationPath path = AnimationPath::Translation;
};

struct Animation {
    std::string name;
    std::vector<AnimationSampler> samplers;
    std::vector<AnimationChannel> channels;

    float duration() const;  // last key time over all samplers
};

// An animation playing in the scene: node TRS at scene time t is the
// animation evaluated at (t * speed), wrapped into its duration if looping.
struct AnimationPlayback {
    uint32_t animation = 0;
    float speed = 1.0f;
    bool loop = true;
};

// ---------------------------------------------------------------------------
// Instances
// ---------------------------------------------------------------------------

// How an instance may change. Rigid motion of any instance is a TLAS
// instance update; only deformation needs a BLAS rebuild.
enum class Motion : uint8_t {
    Static,   // never moves: its BLAS is built once and shared by every static instance of the mesh
    Dynamic,  // moves and may deform (vertex animation): own BLAS, rebuilt when deformVersion changes
    Skinned,  // deformed by a skin every frame it animates: own BLAS, rebuilt when its joints change
};

struct Instance {
    std::string name;
    uint32_t mesh = 0;
    int32_t node = kNone;  // when set, the transform follows this node's world transform
    int32_t skin = kNone;  // Skinned only
    Motion motion = Motion::Static;
    bool firstPerson = false;  // player group: BLAS rebuilt every frame it deforms
    bool longRange = false;    // terrain group: reaches further than the BVH radius

    glm::mat4 transform{1.0f};
    glm::mat4 previousTransform{1.0f};
    uint32_t jointOffset = 0;  // Skinned: first joint matrix in Scene::jointMatrices
    // Morph target weights this frame (its node's, else the mesh's
    // defaults); empty when the mesh does not morph. Changes bump
    // deformVersion (advanceScene).
    std::vector<float> morphWeights;
    // Last frame's morphWeights (motion vectors of the morph itself).
    std::vector<float> previousMorphWeights;
    // Bumped every time the vertices change shape (skinning, vertex
    // animation): the BVH planner rebuilds a BLAS only when it changed.
    uint64_t deformVersion = 0;
};

// A soft round sprite: a camera-facing billboard in the direct view, three
// quads (one per camera axis) in the particle TLAS (glint/particles_shared.h).
struct Particle {
    glm::vec3 position{0.0f};
    float radius = 0.1f;
    glm::vec4 color{1.0f};  // linear RGB, alpha
};

// ---------------------------------------------------------------------------
// Lighting
// ---------------------------------------------------------------------------

struct DirectionalLight {
    glm::vec3 directionToLight{0.0f, 1.0f, 0.0f};  // unit, from the surface towards the sun
    glm::vec3 color{1.0f};                         // linear RGB
    float illuminance = 100000.0f;                 // lux at normal incidence (clear-sky sun)
    float angularDiameterRadians = 0.0093f;        // the sun seen from the earth, 0.53 degrees
};

// A three-colour gradient sky; cheap, and enough to light and reflect.
struct ProceduralSky {
    glm::vec3 zenithColor{0.20f, 0.35f, 0.65f};  // linear radiance scale
    glm::vec3 horizonColor{0.70f, 0.75f, 0.80f};
    glm::vec3 groundColor{0.20f, 0.18f, 0.16f};
    float sunDiskIntensity = 1.0f;  // multiplies the sun's colour inside its disk
};

enum class EnvironmentKind : uint8_t { ProceduralSky, EquirectangularImage };

// The environment seen by rays that miss: a procedural sky or an
// equirectangular HDR image (prefiltered by roughness on the GPU).
struct Environment {
    EnvironmentKind kind = EnvironmentKind::ProceduralSky;
    ProceduralSky sky;
    Texture image;  // Rgba32Float, equirectangular (see equirectUv)
    float intensity = 1.0f;
    float rotationRadians = 0.0f;  // about +Y
};

// Direction -> equirectangular image coordinates: u grows with the
// longitude atan2(x, -z) (so -Z is the image centre), v = 0 at +Y.
glm::vec2 equirectUv(const glm::vec3& direction);
glm::vec3 equirectDirection(const glm::vec2& uv);

// ---------------------------------------------------------------------------
// The scene
// ---------------------------------------------------------------------------

struct SceneView {
    std::string name;
    Lens lens;
    glm::vec3 position{0.0f};
    glm::vec3 target{0.0f, 0.0f, -1.0f};
};

struct Scene {
    std::string name;  // file or built-in scene name; errors name it

    std::vector<Texture> textures;
    std::vector<Material> materials;
    std::vector<Mesh> meshes;
    std::vector<Node> nodes;
    std::vector<Skin> skins;
    std::vector<Animation> animations;
    std::vector<AnimationPlayback> playbacks;
    std::vector<Instance> instances;
    std::vector<Particle> particles;

    // Joint palette of all skinned instances (Instance::jointOffset):
    // object-space skinning matrices of this and last frame.
    std::vector<glm::mat4> jointMatrices;
    std::vector<glm::mat4> previousJointMatrices;

    // Node placed at the camera every frame; first-person objects hang below it.
    int32_t cameraNode = kNone;

    DirectionalLight sun;
    Environment environment;

    // A suggested view: the lens and a path (one key for a still camera).
    Lens lens;
    CameraPath cameraPath;
    // Named viewpoints: a glTF file's perspective camera nodes in document
    // order, or a built-in scene's presets (glint-render --camera).
    std::vector<SceneView> views;

    double time = 0.0;  // seconds, set by advanceScene

    // Edits between frames. Instances (added, removed, reordered, moved,
    // given another mesh or motion), particles, the sun, the environment
    // and the animation state may change freely: the renderers read them
    // every frame. Meshes, materials and textures are uploaded once and
    // baked into vertex and BVH data: after changing any of them (a
    // material's factor, a mesh's geometry, a texture's texels) bump
    // assetRevision, and the renderers upload them again before their next
    // frame. Adding or removing meshes, materials or textures is noticed
    // without it (assetStamp).
    uint64_t assetRevision = 0;
};

// What the renderers compare to notice edited assets (Scene::assetRevision):
// the revision and how many meshes, materials and textures there are.
struct AssetStamp {
    uint64_t revision = 0;
    size_t meshes = 0;
    size_t materials = 0;
    size_t textures = 0;
    bool operator==(const AssetStamp&) const = default;
};
AssetStamp assetStamp(const Scene& scene);

// The view `nameOrIndex` names (a view's name, or its index in decimal);
// throws SceneError naming the scene and listing the views otherwise.
const SceneView& findView(const Scene& scene, std::string_view nameOrIndex);
// Makes `view` the scene's suggested view: its lens and a one-key path.
void useView(Scene& scene, const SceneView& view);

// Triangles of all meshes at LOD 0, each mesh once.
uint64_t meshTriangleCount(const Scene& scene);
// Triangles drawn: LOD 0 of every instance.
uint64_t instancedTriangleCount(const Scene& scene);

// The geometry's material blends (glTF alphaMode BLEND): the transparent
// pass draws it; the G-buffer, the shadow map and the BVH leave it out.
bool blended(const Scene& scene, const Geometry& geometry);

// World bounds of an instance this frame. For a skinned instance the bounds
// cover every joint's transform of the bind-pose bounds, which contains the
// skinned vertices (each is a convex combination of joint transforms).
Aabb instanceBounds(const Scene& scene, const Instance& instance);
// Union of the rigid (unskinned) world bounds of all instances.
Aabb sceneBounds(const Scene& scene);

// Checks every index and array length an engine could get wrong when
// filling a scene itself; throws SceneError naming the scene and element.
void validateScene(const Scene& scene);

} // namespace glint::scene
