#pragma once
// Pass 8 of the reflection pipeline: composite and debug views.
//
// Composite, one compute pass:
//   opaque = lit + reflection * envBRDF(F0, roughness, N.V)
//   final = layer.rgb + (1 - layer.a) * opaque
// (layer: the transparent pass's premultiplied blended surfaces,
// passes/transparent.h; without one, final = opaque)
// where envBRDF is Karis's analytic fit of the split-sum environment BRDF
// of GGX ("Physically Based Shading on Mobile", 2014) and F0 comes from the
// G-buffer's albedo, metallic and reflectance as glint/brdf.glsl's
// surfaceF0 computes it; then exposure, a tonemap (Tonemap below) and the
// sRGB encoding, into an RGBA8_UNORM storage image whose bytes are
// sRGB-encoded (for PNG as they are).
//
// Debug view, one compute pass: any texture the graph knows (float, UNORM,
// sRGB, depth or unsigned-integer formats; the format comes from the
// declaration) to the same RGBA8 output: HDR colour tonemapped, a scalar
// through a colour ramp, or colours that are already display values.
//
//   passes::CompositePipelines compositePipelines(ctx);  // once
//   each frame:
//     const auto image = passes::addCompositePass(graph, compositePipelines, {gbuf, stable.resolved, camera});
//     const auto view = passes::addDebugViewPass(graph, compositePipelines, stable.historyLength, w, h,
//                                                {passes::DebugViewKind::Scalar, 0.0f, 32.0f});

#include "glint/gpu/context.h"
#include "glint/gpu/pipeline.h"
#include "glint/gpu/resources.h"
#include "glint/graph/graph.h"
#include "glint/passes/gbuffer.h"
#include "glint/scene/camera.h"

#include <cstdint>

namespace glint::passes {

inline constexpr VkFormat kCompositeFormat = VK_FORMAT_R8G8B8A8_UNORM;

enum class Tonemap : uint32_t {
    // Khronos PBR Neutral (Khronos 3D Formats Working Group, 2024): exact
    // below 0.76 but for a small near-black offset, then a smooth roll-off
    // of the brightest channel to 1 with slight desaturation; keeps base
    // colours recognisable. The default.
    KhronosPbrNeutral = 0,
    // Narkowicz's fit of the ACES reference curve ("ACES Filmic Tone
    // Mapping Curve", 2016), per channel: filmic contrast and saturation.
    AcesFitted = 1,
    // No curve: clamp to [0, 1] (for comparing linear values).
    Clamp = 2,
};

struct CompositeInputs {
    GBufferOutputs gbuffer;    // lit, albedo, normal, roughnessMetal, depth
    rg::Texture reflections;   // resolved reflections, a > 0 where they exist; invalid: the lit colour alone
    scene::Camera camera;      // the G-buffer's (its matrices, position)
    // Premultiplied blended surfaces over the opaque image (the transparent
    // pass's layer, the G-buffer's size); invalid: none.
    rg::Texture transparency;
};

struct CompositeSettings {
    // Linear scale before the tonemap.
    float exposure = 1.0f;
    Tonemap tonemap = Tonemap::KhronosPbrNeutral;
};

struct CompositeOutputs {
    rg::Texture color;  // kCompositeFormat, sRGB-encoded bytes, alpha 1
    uint32_t width = 0;
    uint32_t height = 0;
};

enum class DebugViewKind {
    Color,   // HDR rgb x exposure, tonemapped, sRGB-encoded
    Scalar,  // r through viridis over [minValue, maxValue] (below: the first colour, above: the last)
    Raw,     // rgb clamped to [0, 1] and stored as they are: already display colours (class colours)
};

// Every kind shows NaN and Inf as magenta (255, 0, 255), which viridis
// never is.
struct DebugViewSettings {
    DebugViewKind kind = DebugViewKind::Color;
    float minValue = 0.0f;
    float maxValue = 1.0f;
    float exposure = 1.0f;
    Tonemap tonemap = Tonemap::KhronosPbrNeutral;
};

// The pipelines and the sampler the passes record with; created once.
class CompositePipelines {
public:
    explicit CompositePipelines(gpu::Context& ctx);

private:
    friend CompositeOutputs addCompositePass(rg::Graph&, CompositePipelines&, const CompositeInputs&,
                                             const CompositeSettings&);
    friend CompositeOutputs addDebugViewPass(rg::Graph&, CompositePipelines&, rg::Texture, uint32_t, uint32_t,
                                             const DebugViewSettings&);
    gpu::Context& ctx_;
    gpu::Pipeline composite_;
    gpu::Pipeline debugView_;      // float, UNORM, sRGB and depth sources
    gpu::Pipeline debugViewUint_;  // unsigned-integer sources
    gpu::Sampler nearest_;
};

// Declares the composite (see the top of this file) on the graphics queue.
CompositeOutputs addCompositePass(rg::Graph& graph, CompositePipelines& pipelines, const CompositeInputs& inputs,
                                  const CompositeSettings& settings = {});

// Declares a debug view of `source` (a 2D texture of one layer; mip 0 of one with mips;
// its first width x height texels are shown, or, of a source half that size (each side
// halved and rounded down, as mip 1 of it would be: the SSLR pyramid), every texel as
// 2x2 pixels) on the graphics queue.
// Signed-integer and stencil sources are refused.
CompositeOutputs addDebugViewPass(rg::Graph& graph, CompositePipelines& pipelines, rg::Texture source, uint32_t width,
                                  uint32_t height, const DebugViewSettings& settings = {});

} // namespace glint::passes
