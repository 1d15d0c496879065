#pragma once

// Passes skipped for a frame (Builder::skip): the plan as that frame runs.
//
// A pass with nothing to do this frame (the hybrid's SSLR passes while the
// host's gate renders the frame as rt) still has barriers before it: on a
// GPU each vkCmdPipelineBarrier2 is a wait for the queue's earlier work and
// a cache flush, whether or not a dispatch follows. skipPasses() carries a
// skipped pass's barriers on to the next pass of its batch that runs (or to
// the batch's end barriers) and merges them there into that pass's one
// barrier call: two barriers on the same subresource become one, from the
// first's source scope and old layout (both sources, in fact: the skipped
// pass's own accesses did not happen, but naming them costs nothing) to
// the second's destination scope and new layout. Every transition still
// happens, in the same batch, before anything that needs it.
//
// Merging is refused -- the carried barriers then stay a call of their
// own, recorded where the last skipped pass before it stood -- where one
// call could not keep their order: the same resource over overlapping but
// different subresource ranges, two layouts that do not chain, or two
// transients whose memory overlaps (an aliasing barrier and a carried
// transition of the memory's previous owner).
//
// The passes keep their places, queues, batches, waits and timestamp
// queries: a skipped pass stays in `passes` with `skipped` set (and no
// barriers, or the carried ones where merging was refused). Semaphores the
// caller placed on imports follow the original plan's batches, which this
// one keeps. verify() checks such a plan like any other, without the
// skipped passes' uses.

#include "glint/graph/plan.h"

namespace glint::rg {

// Whether the declaration behind `plan` skips any of its planned passes.
bool hasSkippedPasses(const Plan& plan);

// `plan` with the skipped passes' barriers carried on and merged (see
// above). A plan that skips nothing comes back unchanged.
Plan skipPasses(const Plan& plan);

} // namespace glint::rg
