// Constant parameters: a compiler pass over the finished graph.
//
// Systems like the paper's figure 5a set many parameters once, in the axiom's C-node,
// and never change them (`alpha1 = -60`, `fBR1 = 0.73`): they are constants written as
// parameters. Left as parameters, every T-node that uses one (`rotx(alpha1)
// uscale(fBR1)`) is rebuilt (sines, cosines, an inverse) at every visit of every ray.
//
// A slot is folded to the constant v when
//   - every assignment to it, anywhere in the graph, is a constant expression whose
//     value is v (the same double), and
//   - every read of it is dominated by an assignment: no path from the axiom reaches a
//     read without passing a C-node that assigns it (and inside such a C-node, the read
//     comes after the assignment). So folding never hides the run-time error of reading
//     an unassigned parameter.
// Then every `Load slot` becomes `Const v`, expressions that become constant are
// collapsed to one instruction, and T-nodes and primitives whose arguments all became
// constant get their precomputed matrix and values, exactly as if the numbers had been
// written in their place. Repeated until nothing changes (a folded slot can make another
// slot's assignments constant: `dSG = 1/segments`).
//
// The meaning of the graph is unchanged: every evaluation gives the same double as
// before, since constant expressions are evaluated by the same code (eval.h).
#pragma once

#include <cstddef>

#include "graph.h"

namespace pcsg {

// Folds the graph's constant parameters in place; returns how many slots were folded.
size_t foldConstantParameters(Graph& g);

}  // namespace pcsg
