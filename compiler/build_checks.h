// The builder's checks on the finished graph (docs/language.md section 5): no triangle
// may be reachable as an operand of an intersection or a difference, through any nodes
// (unions, transformations, C-nodes, paint, definitions and every rule of every S-node).
// Reported once per operator, at its first operator token, naming one such triangle.
// (Unknown parameters are checked as expressions are compiled, build_exprs.h; unknown
// names as they are lowered, build_csg.h.)
#pragma once

#include "build_state.h"

namespace pcsg {

void checkTriangles(BuildContext& ctx);

}  // namespace pcsg
