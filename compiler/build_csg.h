// The builder's lowering phase: CSG expressions to the nodes of the Graph
// (docs/language.md section 5, "From expressions to the graph"; S-nodes of section 4).
// One S-node per module with its selection function or its rules' conditions; each
// definition built once, in build_names.h's order, and shared by every use; then the
// rules' bodies and the axiom: T-, C- and paint nodes for the unary operators, n-ary
// operator nodes for ∪ ∩ \, primitives, notation-B calls as simultaneous C-nodes over the
// module's S-node. Names are checked here where they are used: modules, definitions,
// materials, the arguments of transformations, primitives and calls. Whatever cannot be
// built becomes one shared `empty` placeholder, so that the graph stays whole.
#pragma once

#include "build_exprs.h"
#include "build_state.h"

namespace pcsg {

void lowerCsg(BuildContext& ctx, Names& names, ExprCompiler& exprs);

}  // namespace pcsg
