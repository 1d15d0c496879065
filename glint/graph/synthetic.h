#pragma once

// Synthetic frames for tests and glint-graph-bench: a frame shaped like the
// reflection frame of DESIGN §3 and seeded random graphs. Synthetic: hand
// kept, not derived from passes::ReflectionRenderer::addFrame (the real
// frame's plan is tested in tests/gpu/reflection_frame_plan_test.cpp). Each is a Script -- passes and uses as
// data -- that declare() replays into a Graph, so a benchmark can time
// declaration without timing the generator.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "glint/graph/graph.h"

namespace glint::rg::synthetic {

struct ScriptResource {
    std::string name;
    ResourceKind kind = ResourceKind::Texture;
    // Transient, Imported, or HistoryCurrent for a pair: a pair takes two
    // slots, `previous` first.
    ir::Origin origin = ir::Origin::Transient;
    TextureDesc texture;
    BufferDesc buffer;
    std::optional<BoundaryState> initial;
    std::optional<BoundaryState> final;
};

struct ScriptUse {
    uint32_t slot;
    Access access;
    Subresource range;
};

struct ScriptPass {
    std::string name;
    Queue queue = Queue::Graphics;
    Pipeline pipeline = Pipeline::Compute;
    bool sideEffects = false;
    bool skipped = false; // Builder::skip(): this frame it records nothing
    std::vector<ScriptUse> uses;
};

struct Script {
    std::vector<ScriptResource> resources; // in slot order (a history pair fills two slots)
    std::vector<ScriptPass> passes;
    std::vector<uint32_t> outputs; // slots whose final version is an output
    uint32_t slotCount = 0;
};

// Replays a script: resources first, then passes in order, then outputs.
// Returns the pass ids in script order.
std::vector<PassId> declare(Graph& graph, const Script& script);

struct ReflectionOptions {
    uint32_t width = 1920;
    uint32_t height = 1080;
    Pipeline tracePipeline = Pipeline::Compute; // ray query; RayTracing for the RT pipeline variant
    std::string prefix;                         // names are prefix + name (for tiling copies)
};

// A synthetic frame after DESIGN §3: BVH update on async compute, G-buffer,
// ray generation, SSLR (which here validates screen-space hits with ray
// queries against the TLAS, so it is the first graphics consumer of the
// BVH, as in Far Cry 6; the real SSLR reads no TLAS, and the real frame's
// graphics queue waits at the ray tracer instead), hardware trace, particle
// trace, integrate, reflection motion, temporal accumulation, spatial
// filter, composite and tonemap into an imported output image.
Script reflectionFrame(const ReflectionOptions& options = {});

// Reflection frames back to back, each with its own resources, cut at
// `passes` passes: the bench's "reflection-like" shape at any size.
Script tiledReflectionFrames(uint32_t passes, uint32_t width, uint32_t height);

struct RandomOptions {
    uint32_t passes = 24;
    uint64_t seed = 1;
    bool asyncCompute = true; // declare some passes for the async compute queue
    bool imports = true;
    bool history = true;
    bool subresources = true; // textures with mips and layers, mip-chain passes
    uint32_t extent = 64;     // texture size; irrelevant to the graph's shape
};

// A random but valid frame: every use is legal, so declare() never throws
// and compile() must produce a plan the verifier accepts.
Script randomFrame(const RandomOptions& options);

// Device descriptions for tests and the bench.
QueueCaps twoQueueCaps(); // separate compute family, ray query and RT pipeline
QueueCaps oneQueueCaps(); // everything on the graphics family (lavapipe-like), with ray query

} // namespace glint::rg::synthetic
