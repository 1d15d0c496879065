#pragma once

// Declaring a frame: passes, the resources they use and how.
//
//   rg::Graph graph(caps);
//   rg::Texture lit;
//   graph.addPass("gbuffer", rg::Queue::Graphics,
//       [&](rg::Builder& b) {
//         b.setPipeline(rg::Pipeline::Raster);
//         lit = b.write(b.createTexture("lit", {.width = w, .height = h, .format = VK_FORMAT_R16G16B16A16_SFLOAT}),
//                       rg::Access::ColorAttachment);
//       },
//       [=](rg::PassContext& ctx) { ... });
//   graph.markOutput(lit);
//   rg::Plan plan = graph.compile();
//
// Setup runs immediately, inside addPass, so misuse throws a GraphError at
// the line that declared it. A write returns the next version of the handle;
// reading an older version is a StaleHandle error, writing from one is
// UnorderedWriters (two passes would both claim to produce the next
// version). Versions change when a pass's setup finishes, so one pass may
// read and write different subresources of one handle (a mip chain step).
//
// Sharing across queues: a resource used on both queues is created with
// VK_SHARING_MODE_CONCURRENT over the graphics and compute families (the
// plan marks it crossQueue); timeline semaphores order the queues and no
// ownership-transfer barrier pairs are needed. Imports used on both queues
// must have been created that way by their owner.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <utility>

#include "glint/graph/access.h"
#include "glint/graph/error.h"
#include "glint/graph/ir.h"
#include "glint/graph/types.h"

namespace glint::rg {

struct Plan;
struct CompileOptions;
class Graph;

struct TextureImport {
    TextureDesc desc;
    std::optional<BoundaryState> initial;
    std::optional<BoundaryState> final;
};

struct BufferImport {
    BufferDesc desc;
    std::optional<BoundaryState> initial;
    std::optional<BoundaryState> final;
};

// Acceleration structures come from outside the graph (the BVH manager owns
// them: BLAS persist across frames, and their sizes come from the driver's
// build-size query), so they are imported, then built, updated and read by
// passes like any resource.
struct AccelStructImport {
    std::optional<BoundaryState> initial;
    std::optional<BoundaryState> final;
};

// Handed to a pass's setup; declares what the pass touches.
class Builder {
public:
    Texture createTexture(std::string_view name, const TextureDesc& desc);
    Buffer createBuffer(std::string_view name, const BufferDesc& desc);

    Texture read(Texture texture, Access access, Subresource range = {});
    Buffer read(Buffer buffer, Access access);
    AccelStruct read(AccelStruct accel, Access access);

    [[nodiscard]] Texture write(Texture texture, Access access, Subresource range = {});
    [[nodiscard]] Buffer write(Buffer buffer, Access access);
    [[nodiscard]] AccelStruct write(AccelStruct accel, Access access);

    // Shader stages of this pass's shader accesses; Compute unless set.
    void setPipeline(Pipeline pipeline);
    // Never culled: uploads, readbacks, anything observable outside the graph.
    void markSideEffects();
    // This frame the pass has nothing to do: the executor calls no execute
    // callback for it and carries its barriers on to the next pass of its
    // batch that runs, merged with that pass's own (rg::skipPasses), so a
    // pass idle for a frame costs no pipeline barrier of its own. Its uses
    // stay declared (the frame keeps its plan and transient memory); what
    // it would have written keeps whatever it held, and readers of it are
    // the caller's to keep from relying on that.
    void skip();

private:
    friend class Graph;
    Builder(Graph& graph, uint32_t pass) : graph_(graph), pass_(pass) {}
    Graph& graph_;
    uint32_t pass_;
};

class Graph {
public:
    explicit Graph(const QueueCaps& caps = {});
    Graph(Graph&&) noexcept;
    Graph& operator=(Graph&&) noexcept;
    Graph(const Graph&) = delete;
    Graph& operator=(const Graph&) = delete;
    ~Graph();

    template <class Setup>
    PassId addPass(std::string_view name, Queue queue, Setup&& setup, ExecuteFn execute = {}) {
        Builder builder = beginPass(name, queue, execute);
        try {
            std::forward<Setup>(setup)(builder);
            return endPass(builder.pass_);
        } catch (...) {
            abortPass(builder.pass_);
            throw;
        }
    }

    // A pass whose execute callback needs handles its own setup made (its
    // outputs): setup fills a Data, execute receives it. The Data lives as
    // long as the declaration (the graph and the plans compiled from it).
    //   const auto& out = graph.addPass<BlurData>("blur", rg::Queue::Graphics,
    //       [&](rg::Builder& b, BlurData& d) { d.dst = b.write(b.createTexture(...), ...); },
    //       [=](const BlurData& d, rg::PassContext& ctx) { ... ctx.view(d.dst) ... });
    template <class Data, class Setup, class Execute>
    const Data& addPass(std::string_view name, Queue queue, Setup&& setup, Execute&& execute) {
        auto data = std::make_shared<Data>();
        addPass(name, queue, [&](Builder& b) { std::forward<Setup>(setup)(b, *data); },
                [data, run = std::forward<Execute>(execute)](PassContext& ctx) { run(*data, ctx); });
        return *data;
    }

    // These make the handle inline, in the caller: returned from a call,
    // GCC assembles a 12-byte handle on the stack and reloads it as one
    // word, a store-forwarding stall that was a third of declaring a
    // resource.
    Texture createTexture(std::string_view name, const TextureDesc& desc) {
        return Texture{declareTexture(name, desc), 0, id()};
    }
    Buffer createBuffer(std::string_view name, const BufferDesc& desc) {
        return Buffer{declareBuffer(name, desc), 0, id()};
    }
    Texture importTexture(std::string_view name, const TextureImport& import) {
        return Texture{declareTextureImport(name, import), 0, id()};
    }
    Buffer importBuffer(std::string_view name, const BufferImport& import) {
        return Buffer{declareBufferImport(name, import), 0, id()};
    }
    // A buffer holding `bytes` (copied now) when the frame starts: an import
    // the executor binds to host-visible memory of its own, one buffer per
    // frame in flight, and fills before it submits the frame, so no pass,
    // transfer or barrier of the GPU's puts the bytes there. For a pass's
    // constants (rg::addUpload). Readers declare their own reads. The buffer
    // bound may be larger than the bytes (it is reused across frames): a
    // shader that takes an array's length() from the binding counts the
    // rest too. Throws a GraphError naming it unless the size is a non-zero
    // multiple of 4.
    Buffer uploadBuffer(std::string_view name, std::span<const std::byte> bytes);
    AccelStruct importAccelStruct(std::string_view name, const AccelStructImport& import) {
        return AccelStruct{declareAccelStructImport(name, import), 0, id()};
    }
    // A ping-pong pair, identified across frames by `name` (the executor keeps
    // its two images under that name and swaps them every frame).
    HistoryTexture createHistoryTexture(std::string_view name, const TextureDesc& desc);
    HistoryBuffer createHistoryBuffer(std::string_view name, const BufferDesc& desc);

    // The frame must produce this version. Writes to imports and to the
    // current half of a history pair are outputs implicitly: they are observed
    // outside this frame.
    void markOutput(Texture texture);
    void markOutput(Buffer buffer);
    void markOutput(AccelStruct accel);

    // Orders two passes that share no resource but must not reorder (they
    // talk through something the graph does not see). Contradicting the data
    // flow makes compile() throw a Cycle error.
    void order(PassId before, PassId after);

    // compile(*this, caps(), options, recycled); see compile.h.
    Plan compile(const CompileOptions& options, Plan&& recycled) const;
    Plan compile(const CompileOptions& options) const;
    Plan compile() const;

    const QueueCaps& caps() const { return caps_; }
    uint32_t id() const { return decl_->graphId; }
    const ir::Declaration& declaration() const { return *decl_; }
    // Lets a caller that builds big graphs every frame keep the vectors warm.
    void reserve(uint32_t passes, uint32_t resources, uint32_t uses);

private:
    friend class Builder;
    friend class PlanCache;
    friend Plan compile(const Graph&, const QueueCaps&, const CompileOptions&, Plan&&);

    // Gives `plan` this declaration (a plan cache's reused plan), shared as
    // compile() shares it.
    void shareDeclaration(Plan& plan) const;

    // Takes the callback out of `execute`, leaving it empty: by reference,
    // so no third std::function is moved into and destroyed for every pass.
    Builder beginPass(std::string_view name, Queue queue, ExecuteFn& execute);
    void abortPass(uint32_t pass);
    PassId endPass(uint32_t pass);

    // A compiled Plan shares the declaration; the first change after a
    // compile copies it so the plan's view stays frozen. Only compile()
    // shares it, and it raises mayBeShared_: every use declared asks, and
    // one flag is cheaper to read than the shared count.
    ir::Declaration& mutableDecl() {
        if (mayBeShared_.load(std::memory_order_relaxed)) [[unlikely]]
            unshareDecl();
        return *decl_;
    }
    void unshareDecl();
    // The resource-making halves of createTexture() and the like: the index.
    uint32_t declareTexture(std::string_view name, const TextureDesc& desc);
    uint32_t declareBuffer(std::string_view name, const BufferDesc& desc);
    uint32_t declareTextureImport(std::string_view name, const TextureImport& import);
    uint32_t declareBufferImport(std::string_view name, const BufferImport& import);
    uint32_t declareAccelStructImport(std::string_view name, const AccelStructImport& import);
    // A resource just made: its index, and the resource itself (valid
    // until the next one is made).
    struct NewResource {
        uint32_t index;
        ir::Resource& resource;
    };
    NewResource newResource(std::string_view name, ResourceKind kind, ir::Origin origin, std::string_view suffix = {});
    void finishResource(ir::Resource& resource, uint32_t cells);
    NewResource addImport(std::string_view name, ResourceKind kind, const std::optional<BoundaryState>& initial,
                          const std::optional<BoundaryState>& final);
    std::pair<uint32_t, uint32_t> addHistory(std::string_view name, ResourceKind kind);
    uint32_t use(uint32_t pass, ResourceKind kind, uint32_t index, uint32_t version, uint32_t graph, Access access,
                 Subresource range, bool write);
    uint32_t useGeneral(uint32_t pass, ResourceKind kind, uint32_t index, uint32_t version, uint32_t graph,
                        Access access, Subresource range, bool write);
    void markOutput(ResourceKind kind, uint32_t index, uint32_t version, uint32_t graph);
    const ir::Resource& checkHandle(ResourceKind kind, uint32_t index, uint32_t graph, std::string_view pass) const;
    [[noreturn]] void throwBadHandle(ResourceKind kind, uint32_t index, uint32_t graph, std::string_view pass) const;

    QueueCaps caps_;
    // Shared with the Plans compiled from it (they need the names and execute
    // callbacks); copied on the first change after a compile.
    std::shared_ptr<ir::Declaration> decl_;
    // Resources created by the pass being declared, for rollback.
    uint32_t passFirstResource_ = 0;
    uint32_t passFirstCell_ = 0;
    // Set by compile() (a const operation, hence atomic), cleared by
    // unshareDecl(): whether a Plan may share decl_.
    mutable std::atomic<bool> mayBeShared_{false};
};

// Once per pass; inline, they are a store.
inline void Builder::setPipeline(Pipeline pipeline) { graph_.mutableDecl().passes[pass_].pipeline = pipeline; }

inline void Builder::markSideEffects() { graph_.mutableDecl().passes[pass_].sideEffects = true; }

inline void Builder::skip() { graph_.mutableDecl().passes[pass_].skipped = true; }

// Inline for the same reason as Graph::createTexture.
inline Texture Builder::createTexture(std::string_view name, const TextureDesc& desc) {
    return graph_.createTexture(name, desc);
}

inline Buffer Builder::createBuffer(std::string_view name, const BufferDesc& desc) {
    return graph_.createBuffer(name, desc);
}

} // namespace glint::rg
