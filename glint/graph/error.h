#pragma once

// Misuse of the graph is reported as a GraphError naming the pass and the
// resource involved, thrown where the mistake is declared (or, for what only
// the whole graph shows, by compile()).

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace glint::rg {

enum class ErrorKind : uint8_t {
    ReadBeforeWrite,    // a use needs contents no pass (or import, or last frame) provides
    StaleHandle,        // a read names a version some later write has replaced
    UnorderedWriters,   // two passes write from the same version: nothing orders them
    Cycle,              // explicit orderings contradict the data flow
    QueueCannotAccess,  // e.g. a colour attachment on the async compute queue
    ForeignHandle,      // a handle (or pass id) from another graph, or an invalid one
    ImportWithoutState, // an import used without an initial or final state
    InvalidAccess,      // an access kind the resource kind or pipeline cannot take
    InvalidSubresource, // mips/layers outside the resource
    ConflictingAccess,  // one pass uses one subresource in two incompatible ways
    UnsupportedFeature, // ray query / ray tracing pipeline the device lacks
    InvalidDescription, // a zero-sized texture, an unknown format, ...
};

std::string_view toString(ErrorKind);

class GraphError : public std::runtime_error {
public:
    GraphError(ErrorKind kind, std::string_view pass, std::string_view resource, std::string_view detail);

    ErrorKind kind() const noexcept { return kind_; }
    const std::string& pass() const noexcept { return pass_; }
    const std::string& resource() const noexcept { return resource_; }

private:
    ErrorKind kind_;
    std::string pass_;
    std::string resource_;
};

} // namespace glint::rg
