#pragma once

// Passes skipped for a frame (Builder::skip): the plan as that frame runs.
//
// A pass with nothing to do this frame (the hybrid's SSLR passes while the
// host's gate renders the frame as rt) still has barriers before it: on a
// GPU each vkCmdPipelineBarrier2 is a wait for the queue's earlier work and
// a cache flush, whether or not a dispatch follows. skipPasses() carries a
// skipped pass's barriers on until the next pass of its batch that touches
// their resource (a barrier of its own on it, or a declared use), or the
// batch's end barriers, and merges them into that one barrier call:
// - two barriers on the same subresource become one, from the first's old
//   layout to the second's new one, with both source and both destination
//   scopes (the second's source may name the skipped pass's accesses, which
//   did not happen: naming them costs nothing; a pass after it may rely on
//   the first's destination, a read the compiler found visible already);
//   where their ranges overlap without matching, both are split into
//   single subresources first;
// - a barrier that takes memory a carried resource held (an alias)
//   absorbs the carried barriers of that old owner: their source scopes,
//   not their transitions (its contents and layout are dead);
// - where a skipped pass was the first to write an aliased resource (its
//   barrier claimed the memory), the barriers on that resource stay
//   aliasing ones, with the old owner's source scope, until a pass that
//   runs writes it.
// Every transition still happens, in its batch, before anything that needs
// it.
//
// The passes keep their places, queues, batches, waits and timestamp
// queries: a skipped pass stays in `passes` with `skipped` set and no
// barriers. Semaphores the caller placed on imports follow the original
// plan's batches, which this one keeps. verify() checks such a plan like
// any other, without the skipped passes' uses
// (tests/graph/skip_test.cpp: random graphs with a third of their passes
// skipped).

#include "glint/graph/plan.h"

namespace glint::rg {

// Whether the declaration behind `plan` skips any of its planned passes.
bool hasSkippedPasses(const Plan& plan);

// `plan` with the skipped passes' barriers carried on and merged (see
// above). A plan that skips nothing comes back unchanged.
Plan skipPasses(const Plan& plan);

} // namespace glint::rg
