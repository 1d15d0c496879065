#pragma once

// An independent check of a Plan, written apart from barrier placement.
//
// It replays several consecutive frames of the plan in submission order
// and models Vulkan's rules directly: per subresource, the last write and
// the reads since; a pipeline barrier orders earlier work whose stages (or
// execution-dependency chain) meet its source stages before its
// destination stages, on any resource, and makes writes in its memory
// scope available and visible; semaphores order whole batches across
// queues; layout transitions are writes done by the barrier; aliased memory
// passes between resources. Every pair of conflicting accesses must be
// ordered (stages) and, after a write, visible (access masks); every use
// must find its layout; nothing may read contents that were discarded or
// clobbered by an alias. It exists because the validation layer of this
// Vulkan SDK (1.3.239) does not see hazards between shader writes of
// successive dispatches, nor around acceleration-structure builds.
//
// It also checks the plan's shape (every surviving pass once, on its
// queue, each use finding the writer its declaration names, waits naming
// earlier submissions,
// heaps per queue, concurrent sharing where both queues touch a resource)
// and that no barrier is redundant: each does something for its own
// resource -- a layout change, or ordering or visibility its resource's own
// synchronisation had not provided -- in at least one frame.

#include <cstdint>
#include <string>
#include <vector>

#include "glint/graph/plan.h"

namespace glint::rg {

struct Violation {
    enum class Kind : uint8_t {
        Structure, // the plan's shape is inconsistent
        Order,     // a use finds data from another writer than its declaration names
        Deadlock,  // a wait names a batch not submitted before it
        Layout,    // a use or a transition meets another layout
        Contents,  // a read of discarded or clobbered contents
        ReadAfterWrite,
        WriteAfterRead,
        WriteAfterWrite,
        TransitionRace,   // a layout transition not ordered after earlier uses
        FinalState,       // an import does not end in its declared state
        RedundantBarrier, // a barrier that orders nothing for its resource
        UnmergedBarriers, // two barriers of one pass on one subresource
    };
    Kind kind;
    uint32_t frame;
    std::string message;
};

std::string_view toString(Violation::Kind kind);

struct VerifyOptions {
    // Frames replayed back to back: three let both halves of every history
    // pair play both roles, with frame 1 and 2 in steady state.
    uint32_t frames = 3;
    bool checkRedundancy = true;
};

struct VerifyReport {
    std::vector<Violation> violations;
    bool ok() const { return violations.empty(); }
    bool has(Violation::Kind kind) const;
    std::string text() const; // one violation per line
};

VerifyReport verify(const Plan& plan, const VerifyOptions& options = {});

} // namespace glint::rg
