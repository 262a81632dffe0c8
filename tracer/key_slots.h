// The parameters an instance key must hash (instance_boxes.h): fewer than the ones a
// module's sub-graph reads.
//
// walk.h's ModuleDependencies::reads holds every slot read anywhere below a module's
// S-node. Two kinds of them cannot tell two instances of the module apart:
//  - dead ones: every path from the S-node assigns the slot before it reads it (the
//    terrain's sd, rnd, h12, h13, h23: scratch values of its C-nodes), so its value on
//    entry is never seen;
//  - fixed ones (compiler/fixed_slots.h): the slot holds one value in every instance of
//    the module (the growing tree's segments, dSG and L at its TR module: set once above
//    it, changed only in the SG recursion below it; fold_constants.h folds the slots that
//    are constant everywhere).
// Leaving them out keeps the key exact (instances with equal keys still unroll to the
// same primitives) and makes it cheaper to compute: the terrain's T1 hashed 17 values,
// now 12; the growing tree's TR 8, now 3.
#pragma once

#include <vector>

#include "fixed_slots.h"
#include "graph.h"
#include "walk.h"

namespace pcsg::tracer {

// Removes the dead slots and the `fixed` ones from each analysed module's `reads`. Leaves
// `deps` as it is when the graph is too large to analyse cheaply.
void narrowKeySlots(const Graph& g, const FixedSlots& fixed, std::vector<ModuleDependencies>& deps);

}  // namespace pcsg::tracer
