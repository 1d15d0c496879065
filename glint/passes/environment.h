#pragma once
// The environment prefilter: turns scene::Environment's equirectangular HDR
// image into what every environment lookup reads (glint/environment.glsl):
// one RGBA16F equirectangular image whose mips are the image prefiltered
// by GGX roughness (level 0 the image itself, the last level roughness 1,
// 8x4 texels) and nine SH coefficients of its diffuse irradiance
// (conventions: glint/environment_shared.h).
//
// It is one-time GPU work, done as the G-buffer uploads its meshes: the
// EnvironmentMap prefilters when it is created and again when update()
// sees a new environment, with one submission it waits for (source upload
// -> sanitising copy -> source mip chain -> filtered importance sampling
// per level -> SH projection, read back once). Frames then only read: the
// graph imports the result as a texture that is sampled before and after
// the frame, so no pass of any frame writes it and no barrier is needed.
// NaN, Inf and negative source texels become black before any filter runs;
// values above the half-float range are clamped.
//
// The procedural sky needs none of it: no image is created, the lighting
// says so (SceneLighting::environment.x = 0) and the passes bind a texture
// they read anyway in the environment's slot, which the shaders never read
// in that mode.
//
//   passes::EnvironmentMap environment(ctx, scene);
//   each frame:
//     environment.update();                       // prefilters if the environment changed
//     const rg::Texture env = passes::importEnvironment(graph, environment);
//     const shader::SceneLighting lighting = environment.lighting(settings.lighting);
//     ... passes given {lighting, env} ...
//     environment.bind(resources, env);

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/executor.h"
#include "glint/graph/graph.h"
#include "glint/passes/lighting.h"
#include "glint/scene/scene.h"

#include "glint/gbuffer_shared.h"

#include <array>
#include <cstdint>

namespace glint::passes {

inline constexpr VkFormat kEnvironmentFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

struct EnvironmentSettings {
    // Level 0 is the source halved until it is at most this wide: 2048
    // keeps a 2K sky's pixels as they are; the levels below it cost a
    // quarter each.
    uint32_t maxWidth = 2048;
    // GGX samples per texel of the first rough level, doubled per level
    // below it (at most 1024). Filtered importance sampling reads a mip as
    // wide as each sample's share of the lobe, so 32 samples leave no
    // visible noise (Krivanek and Colbert 2008 use 20-40); the doubling
    // keeps the structured error of the wide lobes under 3% of a horizon's
    // step (tests/gpu/environment_test.cpp).
    uint32_t samples = 32;
};

struct EnvironmentStats {
    uint32_t width = 0;   // level 0; 0 for the procedural sky
    uint32_t height = 0;
    uint32_t levels = 0;
    uint32_t sourceWidth = 0;
    uint32_t sourceHeight = 0;
    uint32_t prefilters = 0;     // times the image was prefiltered
    double prefilterMs = 0.0;    // wall time of the last prefilter (upload to readback)
    uint64_t bytes = 0;          // device memory of the prefiltered image
};

// The sampler every environment lookup uses: trilinear, repeating in u
// (longitude) and clamped in v (the poles).
gpu::Sampler createEnvironmentSampler(gpu::Context& ctx, const std::string& name);

class EnvironmentMap {
public:
    // `scene` must outlive the map; its environment may change between
    // frames (update()).
    EnvironmentMap(gpu::Context& ctx, const scene::Scene& scene, const EnvironmentSettings& settings = {});
    ~EnvironmentMap();
    EnvironmentMap(const EnvironmentMap&) = delete;
    EnvironmentMap& operator=(const EnvironmentMap&) = delete;

    // Prefilters again when the scene's environment is not the one last
    // prefiltered: another kind, or an image of another size or pixel
    // storage (a newly loaded image). Pixels edited in place need
    // refresh(). Returns whether it prefiltered. Waits for the GPU to be
    // idle before replacing an image frames may still read.
    bool update();
    void refresh();

    bool hasImage() const { return static_cast<bool>(radiance_); }
    // The prefiltered image (kEnvironmentFormat, stats().levels mips, left
    // in READ_ONLY_OPTIMAL); throws for the procedural sky.
    const gpu::Image& radiance() const;
    // The nine cosine-convolved SH coefficients of the image's irradiance
    // (rgb), unscaled; zero for the procedural sky.
    const std::array<glm::vec4, 9>& irradianceSh() const { return irradianceSh_; }
    // The sun and the environment for the shaders: sceneLighting() with the
    // sky colours computed once per environment, plus the image's fields.
    shader::SceneLighting lighting(const LightingSettings& settings) const;
    const EnvironmentStats& stats() const { return stats_; }

    // Binds the handle importEnvironment() returned (nothing for the
    // procedural sky's invalid handle).
    void bind(rg::FrameResources& resources, rg::Texture handle) const;

private:
    struct Fingerprint {
        scene::EnvironmentKind kind = scene::EnvironmentKind::ProceduralSky;
        uint32_t width = 0;
        uint32_t height = 0;
        const float* pixels = nullptr;
        friend bool operator==(const Fingerprint&, const Fingerprint&) = default;
    };
    Fingerprint fingerprint() const;
    void prefilter(const scene::Texture& image);

    gpu::Context& ctx_;
    const scene::Scene& scene_;
    EnvironmentSettings settings_;
    gpu::Pipeline source_;
    gpu::Pipeline downsample_;
    gpu::Pipeline prefilter_;
    gpu::Pipeline irradiance_;
    gpu::Sampler sampler_;
    gpu::Image radiance_;
    std::array<glm::vec4, 9> irradianceSh_{};
    SkyColors sky_{};
    Fingerprint last_;
    EnvironmentStats stats_;
};

// Declares this frame's use of the prefiltered image: an import sampled
// before and after the frame ("environment.radiance"), or an invalid
// handle for the procedural sky. Passes declare SampledRead on it.
rg::Texture importEnvironment(rg::Graph& graph, const EnvironmentMap& map);

} // namespace glint::passes
