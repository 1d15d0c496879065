#include "glint/graph/graph.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <string>

#include "glint/graph/compile.h"
#include "glint/graph/plan.h"

namespace glint::rg {
namespace {

// Handles carry their graph's id; 0 is never used so a default handle is
// foreign to every graph.
std::atomic<uint32_t> gNextGraphId{1};

const std::string kNoPass = "(graph)";

// The throw helpers here are cold and never inlined, not even into a
// caller's cold part: with their message building inside, a check such as
// validateTexture() or endPass() saved six registers and set up a frame on
// every call.
[[noreturn, gnu::cold, gnu::noinline]] void throwInvalidTexture(std::string_view name, const TextureDesc& d) {
    std::string problem;
    if (d.width == 0 || d.height == 0 || d.depth == 0 || d.layers == 0 || d.mips == 0)
        problem = "every extent, the layer count and the mip count must be at least 1";
    else if (d.depth > 1 && d.layers > 1)
        problem = "a 3D texture has one layer";
    else if (d.format == VK_FORMAT_UNDEFINED)
        problem = "format is VK_FORMAT_UNDEFINED";
    else if (d.mips > static_cast<uint32_t>(std::bit_width(std::max({d.width, d.height, d.depth}))))
        problem = "more mips than the extent halves to 1";
    throw GraphError(ErrorKind::InvalidDescription, kNoPass, std::string(name), problem);
}

// Every texture a frame declares comes through here: the test stays free of
// the strings that describe a failure.
void validateTexture(std::string_view name, const TextureDesc& d) {
    const bool valid = d.width != 0 && d.height != 0 && d.depth != 0 && d.layers != 0 && d.mips != 0 &&
                       !(d.depth > 1 && d.layers > 1) && d.format != VK_FORMAT_UNDEFINED &&
                       // bit_width of the OR is bit_width of the largest.
                       d.mips <= static_cast<uint32_t>(std::bit_width(d.width | d.height | d.depth));
    if (!valid) [[unlikely]]
        throwInvalidTexture(name, d);
}

[[noreturn, gnu::cold, gnu::noinline]] void throwInvalidBuffer(std::string_view name) {
    throw GraphError(ErrorKind::InvalidDescription, kNoPass, std::string(name), "buffer size is 0");
}

void validateBuffer(std::string_view name, const BufferDesc& d) {
    if (d.size == 0) [[unlikely]]
        throwInvalidBuffer(name);
}

bool rangesOverlap(const Subresource& a, const Subresource& b) {
    return a.baseMip < b.baseMip + b.mipCount && b.baseMip < a.baseMip + a.mipCount &&
           a.baseLayer < b.baseLayer + b.layerCount && b.baseLayer < a.baseLayer + a.layerCount;
}

// The kinds that need a raster pipeline (attachments), as one set.
const AccessSet kNeedsRasterKinds = [] {
    AccessSet set = 0;
    for (uint32_t a = 0; a < kAccessCount; ++a)
        if (accessNeedsRaster(static_cast<Access>(a))) set |= accessBit(static_cast<Access>(a));
    return set;
}();

// The accesses a plain use may take, by resource kind, direction (read,
// write), queue and pipeline of the pass: not boundary-only, allowed on the
// kind, writing exactly when declared with write(), and available on the
// queue with that pipeline. use() checks all of that with one bit test.
struct PlainAccesses {
    AccessSet of[3][2][kQueueCount][3] = {};
};
const PlainAccesses kPlain = [] {
    PlainAccesses set;
    for (uint32_t i = 0; i < kAccessCount; ++i) {
        const auto a = static_cast<Access>(i);
        if (accessIsBoundaryOnly(a)) continue;
        for (uint32_t k = 0; k < 3; ++k) {
            if (!accessAllowedOn(a, static_cast<ResourceKind>(k))) continue;
            for (uint32_t q = 0; q < kQueueCount; ++q)
                for (uint32_t p = 0; p < 3; ++p)
                    if (queueSupports(static_cast<Queue>(q), a, static_cast<Pipeline>(p)))
                        set.of[k][accessWrites(a) ? 1 : 0][q][p] |= accessBit(a);
        }
    }
    return set;
}();

// The kinds that need the subresource to hold data already, as one set.
const AccessSet kNeedsContentsKinds = [] {
    AccessSet set = 0;
    for (uint32_t a = 0; a < kAccessCount; ++a)
        if (accessNeedsContents(static_cast<Access>(a))) set |= accessBit(static_cast<Access>(a));
    return set;
}();

// New resources are copied from this rather than value-initialised: GCC
// clears a value-initialised Resource with `rep stos`, slow to start, and
// declaring a frame makes thousands.
constexpr ir::Resource kFreshResource{};

VkImageLayout layoutOf(AccessSet kinds) { return accessScope(kinds, ResourceKind::Texture, Pipeline::Compute).layout; }

// Records a checked use; returns the version the handle has after it.
inline uint32_t appendUse(ir::Declaration& d, uint32_t pass, uint32_t index, uint32_t version, AccessSet bit,
                          bool write, const Subresource& range) {
    ir::Resource& r = d.resources[index];
    r.lastUser = pass;
    // Braces, not parentheses: clang 14 (the fuzz build) has no
    // parenthesised aggregate initialisation.
    d.uses.emplace_back(ir::Use{index, version, r.lastWriter, bit, write, range});
    ir::Pass& owner = d.passes[pass];
    ++owner.useCount;
    owner.kinds |= bit;
    return write ? version + 1 : version;
}

} // namespace

// ---- Names -------------------------------------------------------------------

void ir::NameArena::grow(size_t size) {
    // Chunks double (4 KiB first, 64 KiB at most): a 1024-pass frame's
    // names take a handful.
    constexpr size_t kFirst = 4096, kLargest = 65536;
    capacity_ = std::max(size, chunks_.empty() ? kFirst : std::min(2 * capacity_, kLargest));
    chunks_.push_back(std::make_unique_for_overwrite<char[]>(capacity_));
    used_ = 0;
}

namespace {

// Copies `size` bytes as two fixed-size copies that overlap when the size is
// not a multiple (memcpy's own trick for short sizes), without calling it:
// names are short (a frame's are 2 to 30 bytes), and the call cost more
// than the copy.
template <size_t N>
void copyOverlapping(char* out, const char* in, size_t size) {
    std::memcpy(out, in, N);
    std::memcpy(out + size - N, in + size - N, N);
}

void copyName(char* out, std::string_view name) {
    const size_t size = name.size();
    if (size >= 16 && size <= 32)
        copyOverlapping<16>(out, name.data(), size);
    else if (size >= 8 && size < 16)
        copyOverlapping<8>(out, name.data(), size);
    else if (size >= 4 && size < 8)
        copyOverlapping<4>(out, name.data(), size);
    else if (size != 0)
        std::memcpy(out, name.data(), size);
}

} // namespace

// Every pass and resource name comes through here; the rare new chunk stays
// out of line so this stays small.
std::string_view ir::NameArena::store(std::string_view a, std::string_view b) {
    const size_t size = a.size() + b.size();
    if (used_ + size > capacity_) [[unlikely]]
        grow(size);
    char* out = chunks_.back().get() + used_;
    copyName(out, a);
    copyName(out + a.size(), b);
    used_ += size;
    return {out, size};
}

ir::Declaration::Declaration(const Declaration& other)
    : graphId(other.graphId), passes(other.passes), uses(other.uses), resources(other.resources),
      outputs(other.outputs), orderings(other.orderings), written(other.written), cellCount(other.cellCount),
      uploads(other.uploads), uploadBytes(other.uploadBytes) {
    for (Pass& p : passes) p.name = names.store(p.name);
    for (Resource& r : resources) r.name = names.store(r.name);
}

// ---- Builder -----------------------------------------------------------------

Texture Builder::read(Texture t, Access a, Subresource range) {
    graph_.use(pass_, ResourceKind::Texture, t.index, t.version, t.graph, a, range, false);
    return t;
}

Buffer Builder::read(Buffer b, Access a) {
    graph_.use(pass_, ResourceKind::Buffer, b.index, b.version, b.graph, a, {}, false);
    return b;
}

AccelStruct Builder::read(AccelStruct s, Access a) {
    graph_.use(pass_, ResourceKind::AccelStruct, s.index, s.version, s.graph, a, {}, false);
    return s;
}

Texture Builder::write(Texture t, Access a, Subresource range) {
    t.version = graph_.use(pass_, ResourceKind::Texture, t.index, t.version, t.graph, a, range, true);
    return t;
}

Buffer Builder::write(Buffer b, Access a) {
    b.version = graph_.use(pass_, ResourceKind::Buffer, b.index, b.version, b.graph, a, {}, true);
    return b;
}

AccelStruct Builder::write(AccelStruct s, Access a) {
    s.version = graph_.use(pass_, ResourceKind::AccelStruct, s.index, s.version, s.graph, a, {}, true);
    return s;
}

// ---- Graph -------------------------------------------------------------------

Graph::Graph(const QueueCaps& caps) : caps_(caps), decl_(std::make_shared<ir::Declaration>()) {
    decl_->graphId = gNextGraphId.fetch_add(1, std::memory_order_relaxed);
}

Graph::Graph(Graph&& other) noexcept
    : caps_(other.caps_), decl_(std::move(other.decl_)), passFirstResource_(other.passFirstResource_),
      passFirstCell_(other.passFirstCell_), mayBeShared_(other.mayBeShared_.load(std::memory_order_relaxed)) {}

Graph& Graph::operator=(Graph&& other) noexcept {
    caps_ = other.caps_;
    decl_ = std::move(other.decl_);
    passFirstResource_ = other.passFirstResource_;
    passFirstCell_ = other.passFirstCell_;
    mayBeShared_.store(other.mayBeShared_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    return *this;
}
Graph::~Graph() = default;

void Graph::reserve(uint32_t passes, uint32_t resources, uint32_t uses) {
    ir::Declaration& d = mutableDecl();
    d.passes.reserve(passes);
    d.resources.reserve(resources);
    d.uses.reserve(uses);
    d.written.reserve(resources);
}

void Graph::unshareDecl() {
    if (decl_.use_count() > 1) decl_ = std::make_shared<ir::Declaration>(*decl_);
    mayBeShared_.store(false, std::memory_order_relaxed);
}

// Resources are built in place: moving a Resource into the vector costs
// more than everything else declaring it does. The name is stored first
// (stored after, its byte copies could alias anything, and the caller
// reloaded the resource's address), and the resource comes back by
// reference, so callers fill it in without indexing again. Inline, like
// finishResource.
inline Graph::NewResource Graph::newResource(std::string_view name, ResourceKind kind, ir::Origin origin,
                                              std::string_view suffix) {
    ir::Declaration& d = mutableDecl();
    const auto index = static_cast<uint32_t>(d.resources.size());
    const std::string_view stored = d.names.store(name, suffix);
    ir::Resource& r = d.resources.emplace_back(kFreshResource);
    r.name = stored;
    r.kind = kind;
    r.origin = origin;
    r.declarableAs = static_cast<uint8_t>(kind);
    return {index, r};
}

// Gives a resource, once described, its cells: mips x layers of a texture,
// one otherwise. The caller passes the count from the description it
// holds; read back from the resource just written, it waited on the stores.
// Inline (only this file calls it): a call cost about as much as its work.
inline void Graph::finishResource(ir::Resource& r, uint32_t cells) {
    ir::Declaration& d = *decl_;
    r.cellBase = d.cellCount;
    r.cellCount = cells;
    d.cellCount = r.cellBase + r.cellCount;
    // Most resources have one cell; resize() would call memset for it.
    if (r.cellCount == 1)
        d.written.push_back(r.contentsAtStart ? 1 : 0);
    else
        d.written.resize(d.cellCount, r.contentsAtStart ? 1 : 0);
}

uint32_t Graph::declareTexture(std::string_view name, const TextureDesc& desc) {
    validateTexture(name, desc);
    const auto [index, r] = newResource(name, ResourceKind::Texture, ir::Origin::Transient);
    r.texture = desc;
    finishResource(r, desc.mips * desc.layers);
    return index;
}

uint32_t Graph::declareBuffer(std::string_view name, const BufferDesc& desc) {
    validateBuffer(name, desc);
    const auto [index, r] = newResource(name, ResourceKind::Buffer, ir::Origin::Transient);
    r.buffer = desc;
    finishResource(r, 1);
    return index;
}

namespace {

[[noreturn, gnu::cold, gnu::noinline]] void throwInvalidBoundary(std::string_view name, ResourceKind kind,
                                                                  Access access) {
    throw GraphError(ErrorKind::InvalidAccess, kNoPass, std::string(name),
                     "boundary state " + std::string(toString(access)) + " is not valid for a " +
                         std::string(toString(kind)));
}

// A boundary state must name an access the kind can take (Present: a
// texture); raw states are taken as they are.
void validateBoundary(std::string_view name, ResourceKind kind, const std::optional<BoundaryState>& state) {
    if (!state || state->isRaw || state->access == Access::None) return;
    const bool valid =
        state->access == Access::Present ? kind == ResourceKind::Texture : accessAllowedOn(state->access, kind);
    if (!valid) [[unlikely]]
        throwInvalidBoundary(name, kind, state->access);
}

} // namespace

// The states are checked before the resource exists, so a bad one leaves
// nothing to take back.
Graph::NewResource Graph::addImport(std::string_view name, ResourceKind kind,
                                    const std::optional<BoundaryState>& initial,
                                    const std::optional<BoundaryState>& final) {
    validateBoundary(name, kind, initial);
    validateBoundary(name, kind, final);
    const NewResource made = newResource(name, kind, ir::Origin::Imported);
    ir::Resource& r = made.resource;
    r.hasInitial = initial.has_value();
    r.hasFinal = final.has_value();
    if (!r.hasInitial || !r.hasFinal) r.declarableAs = ir::Resource::kNotDeclarable;
    if (initial) r.initial = *initial;
    if (final) r.final = *final;
    // Contents exist at the start when the initial state names a use that
    // left data behind (raw states: when they name a layout or any access).
    if (r.hasInitial) {
        const SyncScope s = boundaryScope(r.initial, kind);
        r.contentsAtStart = kind == ResourceKind::Texture
                                ? s.layout != VK_IMAGE_LAYOUT_UNDEFINED
                                : (r.initial.isRaw ? (s.stages | s.access) != 0 : r.initial.access != Access::None);
    }
    return made;
}

uint32_t Graph::declareTextureImport(std::string_view name, const TextureImport& import) {
    validateTexture(name, import.desc);
    const auto [index, r] = addImport(name, ResourceKind::Texture, import.initial, import.final);
    r.texture = import.desc;
    finishResource(r, import.desc.mips * import.desc.layers);
    return index;
}

uint32_t Graph::declareBufferImport(std::string_view name, const BufferImport& import) {
    validateBuffer(name, import.desc);
    const auto [index, r] = addImport(name, ResourceKind::Buffer, import.initial, import.final);
    r.buffer = import.desc;
    finishResource(r, 1);
    return index;
}

Buffer Graph::uploadBuffer(std::string_view name, std::span<const std::byte> bytes) {
    if (bytes.empty() || bytes.size() % 4 != 0 || bytes.size() > UINT32_MAX) {
        throw GraphError(ErrorKind::InvalidDescription, name, name,
                         "an upload must be a non-zero multiple of 4 bytes, not " + std::to_string(bytes.size()));
    }
    // Written by the host before the frame is submitted (the submission
    // makes it visible); its final state is no one's concern (Access::None:
    // no barrier at the frame's end), as the next frame in flight writes
    // other memory.
    constexpr BoundaryState kHostWritten =
        BoundaryState::raw(VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED);
    const uint32_t index = declareBufferImport(name, {{bytes.size()}, kHostWritten, BoundaryState::of(Access::None)});
    ir::Declaration& d = mutableDecl();
    d.uploads.push_back({index, static_cast<uint32_t>(d.uploadBytes.size()), static_cast<uint32_t>(bytes.size())});
    d.uploadBytes.insert(d.uploadBytes.end(), bytes.begin(), bytes.end());
    return Buffer{index, 0, id()};
}

uint32_t Graph::declareAccelStructImport(std::string_view name, const AccelStructImport& import) {
    const auto [index, r] = addImport(name, ResourceKind::AccelStruct, import.initial, import.final);
    finishResource(r, 1);
    return index;
}

HistoryTexture Graph::createHistoryTexture(std::string_view name, const TextureDesc& desc) {
    validateTexture(name, desc);
    const auto [previous, current] = addHistory(name, ResourceKind::Texture);
    for (uint32_t r : {previous, current}) {
        ir::Resource& half = decl_->resources[r];
        half.texture = desc;
        finishResource(half, desc.mips * desc.layers);
    }
    return {Texture{previous, 0, id()}, Texture{current, 0, id()}};
}

HistoryBuffer Graph::createHistoryBuffer(std::string_view name, const BufferDesc& desc) {
    validateBuffer(name, desc);
    const auto [previous, current] = addHistory(name, ResourceKind::Buffer);
    for (uint32_t r : {previous, current}) {
        ir::Resource& half = decl_->resources[r];
        half.buffer = desc;
        finishResource(half, 1);
    }
    return {Buffer{previous, 0, id()}, Buffer{current, 0, id()}};
}

// Both halves of a pair; the description is filled in by the caller.
std::pair<uint32_t, uint32_t> Graph::addHistory(std::string_view name, ResourceKind kind) {
    const auto [previous, p] = newResource(name, kind, ir::Origin::HistoryPrevious, ".previous");
    p.contentsAtStart = true;
    p.partner = previous + 1;
    // The second emplace may reallocate: the first half is set up before it.
    const auto [current, c] = newResource(name, kind, ir::Origin::HistoryCurrent, ".current");
    c.partner = previous;
    return {previous, current};
}

// Every use checks its handle: the common case stays inline, the messages
// live in throwBadHandle.
inline const ir::Resource& Graph::checkHandle(ResourceKind kind, uint32_t index, uint32_t graph,
                                              std::string_view pass) const {
    const ir::Declaration& d = *decl_;
    if (graph != d.graphId || index >= d.resources.size() || d.resources[index].kind != kind) [[unlikely]]
        throwBadHandle(kind, index, graph, pass);
    return d.resources[index];
}

void Graph::throwBadHandle([[maybe_unused]] ResourceKind kind, uint32_t index, uint32_t graph,
                           std::string_view pass) const {
    const ir::Declaration& d = *decl_;
    if (graph != d.graphId || index >= d.resources.size()) {
        const std::string what = graph == 0 ? "an invalid (default-constructed) handle"
                                            : "a handle from another graph (graph " + std::to_string(graph) +
                                                  ", this is graph " + std::to_string(d.graphId) + ")";
        throw GraphError(ErrorKind::ForeignHandle, std::string(pass), "#" + std::to_string(index), "uses " + what);
    }
    const ir::Resource& r = d.resources[index];
    throw GraphError(ErrorKind::ForeignHandle, std::string(pass), r.name,
                     "handle kind does not match the resource (a " + std::string(toString(r.kind)) + ")");
}

void Graph::markOutput(Texture t) { markOutput(ResourceKind::Texture, t.index, t.version, t.graph); }
void Graph::markOutput(Buffer b) { markOutput(ResourceKind::Buffer, b.index, b.version, b.graph); }
void Graph::markOutput(AccelStruct s) { markOutput(ResourceKind::AccelStruct, s.index, s.version, s.graph); }

void Graph::markOutput(ResourceKind kind, uint32_t index, uint32_t version, uint32_t graph) {
    static const std::string kOutput = "(output)";
    const ir::Resource& r = checkHandle(kind, index, graph, kOutput);
    if (version != r.version)
        throw GraphError(ErrorKind::StaleHandle, kOutput, r.name,
                         "marks version " + std::to_string(version) + " as output, but version " +
                             std::to_string(r.version) + " is current");
    if (version == 0 && !r.contentsAtStart)
        throw GraphError(ErrorKind::ReadBeforeWrite, kOutput, r.name, "is marked as output but no pass writes it");
    mutableDecl().outputs.push_back({index, version, r.lastWriter});
}

void Graph::order(PassId before, PassId after) {
    const ir::Declaration& d = *decl_;
    for (const PassId p : {before, after})
        if (p.graph != d.graphId || p.index >= d.passes.size())
            throw GraphError(ErrorKind::ForeignHandle, "#" + std::to_string(p.index), "",
                             "order() got a pass id from another graph");
    mutableDecl().orderings.push_back({before.index, after.index});
}

Builder Graph::beginPass(std::string_view name, Queue queue, ExecuteFn& execute) {
    ir::Declaration& d = mutableDecl();
    ir::Pass& p = d.passes.emplace_back();
    p.name = d.names.store(name);
    p.queue = queue;
    p.firstUse = static_cast<uint32_t>(d.uses.size());
    // Swapped rather than move-assigned: p.execute is empty, and
    // move-assignment goes through a temporary.
    p.execute.swap(execute);
    passFirstResource_ = static_cast<uint32_t>(d.resources.size());
    passFirstCell_ = d.cellCount;
    return Builder(*this, static_cast<uint32_t>(d.passes.size() - 1));
}

void Graph::abortPass(uint32_t pass) {
    // Setup (or endPass's checks) threw: forget the pass and what it created,
    // so the graph stays usable. Versions move only once endPass's checks
    // pass, so nothing else changed.
    ir::Declaration& d = mutableDecl();
    d.uses.resize(d.passes[pass].firstUse);
    d.passes.pop_back();
    d.resources.resize(passFirstResource_);
    // An upload declared inside the failed setup goes with its resource.
    while (!d.uploads.empty() && d.uploads.back().resource >= passFirstResource_) {
        d.uploadBytes.resize(d.uploads.back().offset);
        d.uploads.pop_back();
    }
    d.cellCount = passFirstCell_;
    d.written.resize(passFirstCell_);
}

namespace {

// endPass found a use that needs a raster pipeline on a pass without one, or
// a raster pass on the async compute queue: says which, as it always has.
[[noreturn, gnu::cold, gnu::noinline]] void throwPassNeedsRaster(const ir::Declaration& d, uint32_t pass) {
    const ir::Pass& p = d.passes[pass];
    const uint32_t end = p.firstUse + p.useCount;
    if (p.pipeline != Pipeline::Raster) {
        for (uint32_t u = p.firstUse; u < end; ++u) {
            const ir::Use& use = d.uses[u];
            for (AccessSet rest = use.kinds; rest; rest &= static_cast<AccessSet>(rest - 1)) {
                const auto a = static_cast<Access>(std::countr_zero(rest));
                if (accessNeedsRaster(a))
                    throw GraphError(
                        ErrorKind::InvalidAccess, p.name, d.resources[use.resource].name,
                        std::string(toString(a)) + " needs a raster pipeline; call setPipeline(Pipeline::Raster)");
            }
        }
    }
    throw GraphError(ErrorKind::QueueCannotAccess, p.name,
                     end > p.firstUse ? d.resources[d.uses[p.firstUse].resource].name : "",
                     "the async compute queue has no raster pipeline");
}

} // namespace

PassId Graph::endPass(uint32_t pass) {
    ir::Declaration& d = mutableDecl();
    const ir::Pass& p = d.passes[pass];
    const ir::Use* const first = d.uses.data() + p.firstUse;
    const ir::Use* const last = first + p.useCount;
    // Pipeline-dependent checks wait until setup has had its chance to call
    // setPipeline(). (A raster pass may use anything these look for.) The
    // messages are built out of line, so the loop here stays in registers.
    if ((p.pipeline != Pipeline::Raster && (p.kinds & kNeedsRasterKinds)) ||
        !queueSupports(p.queue, Access::None, p.pipeline)) [[unlikely]]
        throwPassNeedsRaster(d, pass);
    // Commit: every resource this pass wrote moves to its next version.
    for (const ir::Use* use = first; use != last; ++use) {
        if (!use->writes) continue;
        ir::Resource& r = d.resources[use->resource];
        r.version = use->version + 1;
        r.lastWriter = pass;
        // Most resources have one cell: it needs no range looked at.
        if (r.cellCount == 1) {
            d.written[r.cellBase] = 1;
            continue;
        }
        // Cell (m, l) is cellBase + m * layers + l (ir::cellOf). Mostly one
        // cell, stored without the loops' setup; otherwise a loop still
        // beats a call to memset. The range is copied: the
        // byte stores below could alias it, which would reload it each time.
        const Subresource range = use->range;
        const uint32_t layers = r.kind == ResourceKind::Texture ? r.texture.layers : 1u;
        uint8_t* cells = d.written.data() + r.cellBase + range.baseLayer;
        if (range.mipCount == 1 && range.layerCount == 1) {
            cells[range.baseMip * layers] = 1;
            continue;
        }
        for (uint32_t m = range.baseMip; m < range.baseMip + range.mipCount; ++m)
            for (uint32_t l = 0; l < range.layerCount; ++l) cells[m * layers + l] = 1;
    }
    return PassId{pass, d.graphId};
}

// Every use of every pass comes through here, and nearly all are the plain
// case: a valid handle of the current version, an access the resource and
// queue allow, a legal range, contents where needed, and no other use of
// the same subresource in the pass. That case is checked with a few
// comparisons and recorded; anything else -- an error, a read that merges
// with an earlier one -- goes to useGeneral(), which decides and words the
// errors. The fast path only ever declines: it changes nothing before
// handing over, so useGeneral() sees the same state it always did. Inline:
// each Builder::read/write knows its kind and direction, which folds away
// a good part of the checks.
inline uint32_t Graph::use(uint32_t pass, ResourceKind kind, uint32_t index, uint32_t version, uint32_t graph,
                           Access access, Subresource range, bool write) {
    ir::Declaration& d = mutableDecl();
    // index < size(), compared in bytes: size() divides by sizeof(Resource)
    // (a multiply), and the byte offset is needed anyway.
    if (graph != d.graphId || size_t{index} * sizeof(ir::Resource) >= d.resources.size() * sizeof(ir::Resource) ||
        access >= Access::Count) [[unlikely]]
        return useGeneral(pass, kind, index, version, graph, access, range, write);
    const ir::Resource& r = d.resources[index];
    const ir::Pass& p = d.passes[pass];
    const AccessSet bit = accessBit(access);
    const AccessSet plainAccesses = kPlain.of[static_cast<uint32_t>(kind)][write][static_cast<uint32_t>(p.queue)]
                                             [static_cast<uint32_t>(p.pipeline)];
    // Bitwise, not short-circuit: every term is cheap, and one branch
    // predicts better than four.
    const bool plain = (r.declarableAs == static_cast<uint8_t>(kind)) & ((plainAccesses & bit) != 0) &
                       (version == r.version);
    if (!plain) [[unlikely]]
        return useGeneral(pass, kind, index, version, graph, access, range, write);

    // Most uses name one cell: a buffer, a structure, or a texture of one mip
    // and one layer used whole. Those need no range resolved and check one
    // byte of contents.
    Subresource resolved{0, 1, 0, 1};
    bool oneCell = true;
    if (kind != ResourceKind::Texture) {
        if (range != Subresource{}) [[unlikely]]
            return useGeneral(pass, kind, index, version, graph, access, range, write);
    } else if (r.cellCount != 1 || range != Subresource{}) {
        oneCell = false;
        const TextureDesc& t = r.texture;
        resolved = range;
        if (resolved.mipCount == Subresource::kAll)
            resolved.mipCount = resolved.baseMip < t.mips ? t.mips - resolved.baseMip : 0;
        if (resolved.layerCount == Subresource::kAll)
            resolved.layerCount = resolved.baseLayer < t.layers ? t.layers - resolved.baseLayer : 0;
        if (resolved.mipCount == 0 || resolved.layerCount == 0 || resolved.baseMip + resolved.mipCount > t.mips ||
            resolved.baseLayer + resolved.layerCount > t.layers) [[unlikely]]
            return useGeneral(pass, kind, index, version, graph, access, range, write);
    }

    if (kNeedsContentsKinds & bit) {
        // Cell (m, l) is cellBase + m * layers + l (ir::cellOf).
        const uint8_t* written = d.written.data() + r.cellBase;
        if (oneCell) {
            if (!written[0]) [[unlikely]]
                return useGeneral(pass, kind, index, version, graph, access, range, write);
        } else {
            const uint32_t layers = r.texture.layers;
            // One mip and layer of a larger texture: the loops' setup costs
            // more than the check.
            if (resolved.mipCount == 1 && resolved.layerCount == 1) {
                if (!written[resolved.baseMip * layers + resolved.baseLayer]) [[unlikely]]
                    return useGeneral(pass, kind, index, version, graph, access, range, write);
            } else {
                for (uint32_t m = resolved.baseMip; m < resolved.baseMip + resolved.mipCount; ++m)
                    for (uint32_t l = resolved.baseLayer; l < resolved.baseLayer + resolved.layerCount; ++l)
                        if (!written[m * layers + l]) [[unlikely]]
                            return useGeneral(pass, kind, index, version, graph, access, range, write);
            }
        }
    }

    // Most resources are used once per pass: only one this pass has used
    // already needs its uses searched for an overlap.
    if (r.lastUser == pass) {
        for (uint32_t u = p.firstUse; u < p.firstUse + p.useCount; ++u) {
            const ir::Use& other = d.uses[u];
            if (other.resource == index && rangesOverlap(other.range, resolved)) [[unlikely]]
                return useGeneral(pass, kind, index, version, graph, access, range, write);
        }
    }

    return appendUse(d, pass, index, version, bit, write, resolved);
}

// Every case use() does not take: all the checks in order, each error in
// words, and reads that merge into an earlier use of the pass.
uint32_t Graph::useGeneral(uint32_t pass, ResourceKind kind, uint32_t index, uint32_t version, uint32_t graph,
                           Access access, Subresource range, bool write) {
    ir::Declaration& d = mutableDecl();
    const std::string_view passName = d.passes[pass].name;
    const ir::Resource& r = checkHandle(kind, index, graph, passName);
    const ir::Pass& p = d.passes[pass];

    auto fail = [&](ErrorKind k, const std::string& detail) { throw GraphError(k, passName, r.name, detail); };

    if (access >= Access::Count || accessIsBoundaryOnly(access))
        fail(ErrorKind::InvalidAccess, std::string(toString(access)) + " describes a frame boundary, not a pass's use");
    if (!accessAllowedOn(access, kind))
        fail(ErrorKind::InvalidAccess,
             std::string(toString(access)) + " is not an access a " + std::string(toString(kind)) + " can take");
    if (accessWrites(access) != write)
        fail(ErrorKind::InvalidAccess, std::string(toString(access)) +
                                           (write ? " does not write; declare it with read()"
                                                  : " writes; declare it with write() and use the handle it returns"));
    if (!queueSupports(p.queue, access, p.pipeline))
        fail(ErrorKind::QueueCannotAccess,
             std::string(toString(access)) + " is not available on the " + std::string(toString(p.queue)) + " queue");
    if (r.origin == ir::Origin::Imported && (!r.hasInitial || !r.hasFinal))
        fail(ErrorKind::ImportWithoutState, std::string("was imported without ") +
                                                (!r.hasInitial ? "an initial" : "a final") +
                                                " state; the graph cannot synchronise against an unknown state");

    if (version != r.version) {
        if (version > r.version) fail(ErrorKind::ForeignHandle, "names a version this graph never made");
        const std::string writer(r.lastWriter != kNoIndex ? d.passes[r.lastWriter].name : std::string_view("?"));
        if (write)
            fail(ErrorKind::UnorderedWriters,
                 "writes from version " + std::to_string(version) + ", which pass '" + writer +
                     "' already wrote; nothing orders the two writers (write the handle '" + writer + "' returned)");
        fail(ErrorKind::StaleHandle, "reads version " + std::to_string(version) + ", but pass '" + writer +
                                         "' has since written version " + std::to_string(r.version));
    }

    // Resolve the subresource range.
    if (kind == ResourceKind::Texture) {
        const TextureDesc& t = r.texture;
        if (range.mipCount == Subresource::kAll) range.mipCount = range.baseMip < t.mips ? t.mips - range.baseMip : 0;
        if (range.layerCount == Subresource::kAll)
            range.layerCount = range.baseLayer < t.layers ? t.layers - range.baseLayer : 0;
        if (range.mipCount == 0 || range.layerCount == 0 || range.baseMip + range.mipCount > t.mips ||
            range.baseLayer + range.layerCount > t.layers)
            fail(ErrorKind::InvalidSubresource,
                 "mips [" + std::to_string(range.baseMip) + ", +" + std::to_string(range.mipCount) + ") layers [" +
                     std::to_string(range.baseLayer) + ", +" + std::to_string(range.layerCount) + ") are outside " +
                     std::to_string(t.mips) + " mips x " + std::to_string(t.layers) + " layers");
    } else {
        if (range != Subresource{}) fail(ErrorKind::InvalidSubresource, "only textures have subresources");
        range = {0, 1, 0, 1};
    }

    if (accessNeedsContents(access)) {
        for (uint32_t m = range.baseMip; m < range.baseMip + range.mipCount; ++m)
            for (uint32_t l = range.baseLayer; l < range.baseLayer + range.layerCount; ++l)
                if (!d.written[ir::cellOf(r, m, l)]) {
                    std::string where = kind == ResourceKind::Texture
                                            ? " (mip " + std::to_string(m) + ", layer " + std::to_string(l) + ")"
                                            : std::string();
                    fail(ErrorKind::ReadBeforeWrite,
                         std::string(toString(access)) + " needs contents, but nothing wrote it" + where +
                             (r.origin == ir::Origin::Imported ? "; it was imported with undefined contents" : ""));
                }
    }

    // One subresource, one use per pass: reads that share a layout merge
    // (depth test plus sampling); anything else is ambiguous.
    const AccessSet bit = accessBit(access);
    for (uint32_t u = p.firstUse; u < p.firstUse + p.useCount; ++u) {
        ir::Use& other = d.uses[u];
        if (other.resource != index || !rangesOverlap(other.range, range)) continue;
        const bool sameLayout = kind != ResourceKind::Texture || layoutOf(other.kinds) == layoutOf(bit);
        if (!write && !other.writes && other.range == range && sameLayout) {
            other.kinds |= bit;
            d.passes[pass].kinds |= bit;
            return version;
        }
        fail(ErrorKind::ConflictingAccess,
             "is used twice on overlapping subresources (" + std::string(toString(access)) +
                 " and an earlier use); a pass that reads and writes one subresource declares StorageReadWrite");
    }

    return appendUse(d, pass, index, version, bit, write, range);
}

Plan Graph::compile(const CompileOptions& options, Plan&& recycled) const {
    return rg::compile(*this, caps_, options, std::move(recycled));
}

Plan Graph::compile(const CompileOptions& options) const { return rg::compile(*this, caps_, options, Plan{}); }

Plan Graph::compile() const { return rg::compile(*this, caps_, CompileOptions{}, Plan{}); }

void Graph::shareDeclaration(Plan& plan) const {
    plan.declaration = decl_;
    mayBeShared_.store(true, std::memory_order_relaxed);
}

} // namespace glint::rg
