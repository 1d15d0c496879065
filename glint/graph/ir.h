#pragma once

// The declared graph as data: what Graph/Builder record and what compile()
// and the verifier read. Flat vectors indexed by pass, use and resource;
// a pass's uses are contiguous.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "glint/graph/access.h"
#include "glint/graph/types.h"

namespace glint::rg::ir {

enum class Origin : uint8_t {
    Transient,       // described here, created (and aliased) by the executor
    Imported,        // owned by the caller, with boundary states
    HistoryPrevious, // last frame's image of a ping-pong pair
    HistoryCurrent,  // this frame's image of the pair
};

// The names of one declaration, back to back in chunks that never move, so
// views into them survive the vectors growing. Tiled names such as
// "f12/gbuffer.depth" outgrow std::string's small buffer: one allocation
// per name to declare it and one to free it were a tenth of declaring.
class NameArena {
public:
    // Stores a + b; the view lives as long as the arena.
    std::string_view store(std::string_view a, std::string_view b = {});

private:
    void grow(size_t size); // a new chunk with room for `size`

    std::vector<std::unique_ptr<char[]>> chunks_;
    size_t used_ = 0;
    size_t capacity_ = 0;
};

// Field order: what declaring a use reads and writes comes first, together
// (a use touches one or two cache lines of its resource, not three; the
// compile phases read the same fields), and the small fields share what was
// padding, so a resource is 144 bytes instead of 160.
struct Resource {
    std::string_view name; // in Declaration::names
    ResourceKind kind = ResourceKind::Texture;
    Origin origin = Origin::Transient;
    // Declaration bookkeeping: the kind a use must name to take the fast
    // path -- `kind`, or kNotDeclarable for an import without both boundary
    // states (no use of it is legal; the general path says why) -- so one
    // compare stands for three.
    static constexpr uint8_t kNotDeclarable = 0xff;
    uint8_t declarableAs = 0;
    // Imports only: whether `initial` and `final` below hold a state.
    bool hasInitial = false;
    bool hasFinal = false;
    bool contentsAtStart = false; // imports with a defined initial state, history previous
    // Per-subresource state lives in "cells": mips x layers of a texture, one
    // for a buffer or acceleration structure. Cell (m, l) is cellBase + m*layers + l.
    uint32_t cellBase = 0;
    uint32_t cellCount = 1;
    // Declaration bookkeeping: the current version and the pass that made it.
    uint32_t version = 0;
    uint32_t lastWriter = kNoIndex;
    // Declaration bookkeeping: the last pass that declared a use of it (or
    // one that was declared and dropped). Only a pass whose index matches
    // can have used it already, so only then does a use look for overlaps.
    uint32_t lastUser = kNoIndex;
    uint32_t partner = kNoIndex; // the other half of a history pair
    TextureDesc texture;
    BufferDesc buffer;
    // Imports only.
    BoundaryState initial;
    BoundaryState final;
};

struct Use {
    uint32_t resource = kNoIndex;
    uint32_t version = 0;         // the version read, or written from
    uint32_t producer = kNoIndex; // pass that made `version`; kNoIndex: it came from outside the frame
    AccessSet kinds = 0;          // one kind, or several reads sharing a layout
    bool writes = false;
    Subresource range; // resolved, no kAll
};

struct Pass {
    std::string_view name; // in Declaration::names
    Queue queue = Queue::Graphics; // as declared; compile() maps it to a family
    Pipeline pipeline = Pipeline::Compute;
    bool sideEffects = false;
    // Builder::skip(): this frame the pass records nothing. Not part of the
    // plan's shape (a reused plan serves frames that skip and frames that
    // do not); the executor carries its barriers on (rg::skipPasses).
    bool skipped = false;
    // Declaration bookkeeping: every access kind its uses take, so endPass
    // checks the pipeline without walking the uses again.
    AccessSet kinds = 0;
    uint32_t firstUse = 0;
    uint32_t useCount = 0;
    ExecuteFn execute;
};

struct Output {
    uint32_t resource;
    uint32_t version;
    uint32_t producer;
};

struct Ordering {
    uint32_t before;
    uint32_t after;
};

struct Declaration {
    Declaration() = default;
    Declaration(const Declaration& other); // stores the names again in its own arena
    Declaration& operator=(const Declaration&) = delete;
    Declaration(Declaration&&) noexcept = default;
    Declaration& operator=(Declaration&&) noexcept = default;

    uint32_t graphId = 0;
    std::vector<Pass> passes;
    std::vector<Use> uses;
    std::vector<Resource> resources;
    std::vector<Output> outputs;
    std::vector<Ordering> orderings;
    std::vector<uint8_t> written; // per cell: holds data some pass (or the frame's start) wrote
    uint32_t cellCount = 0;
    NameArena names;
    // Buffers Graph::uploadBuffer declared: imports that the executor binds
    // to host-visible memory of its own and fills with these bytes
    // (uploadBytes[offset, offset + size)) before the frame is submitted.
    // Not part of a plan's shape: a reused plan runs its frame's bytes.
    struct Upload {
        uint32_t resource;
        uint32_t offset;
        uint32_t size;
    };
    std::vector<Upload> uploads;
    std::vector<std::byte> uploadBytes;
};

inline uint32_t cellOf(const Resource& r, uint32_t mip, uint32_t layer) {
    return r.cellBase + mip * (r.kind == ResourceKind::Texture ? r.texture.layers : 1u) + layer;
}

} // namespace glint::rg::ir
