#pragma once
// Blended surfaces (glTF alphaMode BLEND): two passes on the graphics
// queue after the reflections are resolved, a compute clear of their layer
// ("transparent.clear") and the raster pass that draws them
// ("transparent"), declared only in frames with a blended surface in view.
//
// The G-buffer, the shadow map and the BVH leave blended geometry out, so
// no pass that reads them sees it: SSLR cannot hit it, ray-traced
// reflections and shadow rays pass through it, and it casts no shadow; a
// blended surface is therefore absent from reflections in every mode alike
// (it is not traced as a transmissive surface). This pass draws it forward
// over the opaque frame instead:
//   - the instances the G-buffer drew (same frustum test, same LOD-0
//     geometry, skinning, morphing and per-pixel material textures: the
//     G-buffer renderer's own buffers), their blended geometries sorted back
//     to front by the distance from the camera to each geometry's bounds
//     centre (within one geometry, triangles keep their order);
//   - depth-tested against the G-buffer's reversed-Z depth, not written;
//     single-sided materials cull back faces, double-sided ones shade the
//     side facing the viewer;
//   - lit as the G-buffer lights (the sun through the shadow map, diffuse
//     sky, emission) plus the specular sky light from the environment,
//     which an opaque surface gets from the reflection passes instead; the
//     Khronos sample viewer's blending: the whole radiance times the
//     coverage (base colour factor x COLOR_0 x texel alpha);
//   - into a layer of its own (kTransparentFormat, cleared to zero):
//     premultiplied "over", rgb = the blended radiance, a = the coverage of
//     everything drawn. Composite puts it over the opaque result
//     (CompositeInputs::transparency):
//       final = layer.rgb + (1 - layer.a) * (lit + reflection * envBRDF)
//
//   passes::GBufferRenderer gbufferRenderer(ctx, scene);
//   each frame:
//     const auto gbuf = passes::addGBufferPass(graph, gbufferRenderer, {camera}, {});
//     ... reflections ...
//     // Invalid when nothing blended is in view: composite then has no layer.
//     const rg::Texture layer = passes::addTransparentPass(graph, gbufferRenderer, {gbuf}).layer;
//     passes::addCompositePass(graph, pipelines, {gbuf, reflections, camera, layer});
//
// Known limits: a surface behind a blended one gets its reflection as
// usual, but a blended surface's own reflection shows the environment
// only, never the scene; intersecting blended surfaces, and a concave
// blended mesh, sort per geometry, not per pixel; particles (drawn into
// the lit colour, passes/particles.h) end up under blended surfaces even
// where they are in front of them.

#include "glint/graph/graph.h"
#include "glint/passes/gbuffer.h"

#include <cstdint>

namespace glint::passes {

inline constexpr VkFormat kTransparentFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

struct TransparentInputs {
    // This frame's G-buffer, from the renderer passed to addTransparentPass:
    // its depth (tested, not written) and shadow map (sampled).
    GBufferOutputs gbuffer;
    // The prefiltered environment the G-buffer's lighting looks up, as given
    // to addGBufferPass (invalid for the procedural sky).
    rg::Texture environment;
    // With no blended surface in view the pass is not declared and the
    // layer is invalid; set, it is declared anyway (a cleared layer: for
    // a debug view of it).
    bool declareEmpty = false;
};

struct TransparentOutputs {
    // kTransparentFormat, premultiplied radiance, a = coverage; invalid when
    // nothing blended is in view (see TransparentInputs::declareEmpty).
    rg::Texture layer;
    uint32_t width = 0;
    uint32_t height = 0;
};

// Declares two passes over the frame `renderer`'s last addGBufferPass
// declared, when an instance it draws has blended geometry: a compute
// clear of the layer ("transparent.clear"; a load-op clear costs ten
// times more on GPUs with a small graphics engine) and the raster pass
// ("transparent"). Throws gpu::GpuError when the renderer declared no
// frame, or when the G-buffer in `inputs` has another size than that
// frame's.
TransparentOutputs addTransparentPass(rg::Graph& graph, GBufferRenderer& renderer, const TransparentInputs& inputs);

} // namespace glint::passes
