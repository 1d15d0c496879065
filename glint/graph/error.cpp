#include "glint/graph/error.h"

namespace glint::rg {
namespace {

std::string describe(ErrorKind kind, std::string_view pass, std::string_view resource, std::string_view detail) {
    std::string message = "render graph: ";
    message += toString(kind);
    message += ": pass '";
    message += pass;
    message += "', resource '";
    message += resource;
    message += "': ";
    message += detail;
    return message;
}

} // namespace

std::string_view toString(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::ReadBeforeWrite:
            return "read before write";
        case ErrorKind::StaleHandle:
            return "stale handle";
        case ErrorKind::UnorderedWriters:
            return "unordered writers";
        case ErrorKind::Cycle:
            return "cycle";
        case ErrorKind::QueueCannotAccess:
            return "queue cannot access";
        case ErrorKind::ForeignHandle:
            return "foreign handle";
        case ErrorKind::ImportWithoutState:
            return "import without state";
        case ErrorKind::InvalidAccess:
            return "invalid access";
        case ErrorKind::InvalidSubresource:
            return "invalid subresource";
        case ErrorKind::ConflictingAccess:
            return "conflicting access";
        case ErrorKind::UnsupportedFeature:
            return "unsupported feature";
        case ErrorKind::InvalidDescription:
            return "invalid description";
    }
    return "error";
}

GraphError::GraphError(ErrorKind kind, std::string_view pass, std::string_view resource, std::string_view detail)
    : std::runtime_error(describe(kind, pass, resource, detail)), kind_(kind), pass_(pass), resource_(resource) {}

} // namespace glint::rg
