#pragma once

// The verifier's own statement of what each kind of use needs, written from
// the Vulkan specification's synchronization chapter (pipeline stages of
// each command and shader, access flags of each access, image layouts each
// descriptor type and attachment accepts), apart from the compiler's table
// (access.cpp). The verifier judges plans by these rules, so an entry of
// the compiler's table that is wrong makes plans the verifier rejects
// instead of plans that agree with their own mistake
// (tests/graph/verifier_rules_test.cpp corrupts the table entry by entry).
//
// It states what must hold, not what the compiler chose: a sampled read may
// find its image in any read-only layout or GENERAL, while the compiler
// picks one of them.

#include <cstdint>

#include "glint/graph/access.h"
#include "glint/graph/types.h"

namespace glint::rg::verify_rules {

struct Need {
    // Every stage the access may be performed in: the writes before it must
    // be ordered before, and visible to, each of them.
    VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 reads = VK_ACCESS_2_NONE;   // access bits of its reads
    VkAccessFlags2 writes = VK_ACCESS_2_NONE;  // access bits of its writes
    // Textures: the layouts it may find the subresource in (up to 6).
    VkImageLayout layouts[6] = {};
    uint32_t layoutCount = 0;
    bool needsContents = false;  // reads what an earlier use (or the frame's start) left

    bool allows(VkImageLayout layout) const;
};

// One kind of access to a resource kind from a pass on `pipeline`.
Need need(Access access, ResourceKind kind, Pipeline pipeline);
// A set of kinds one use merges (read kinds sharing a layout): stages and
// access bits united, the layouts every one of them allows.
Need need(AccessSet kinds, ResourceKind kind, Pipeline pipeline);

} // namespace glint::rg::verify_rules
