// The builder's reading of one `material` directive (docs/language.md sections 7 and 10):
// the flat shorthand items and the POV-Ray blocks pigment, finish, normal and interior,
// from the parser's atoms (ast.h) into a Material. Values are constants or read the time
// (kept as TimedValues of the material, like the other directives' values); an item of
// POV-Ray's that the language does not have is an error naming it.
#pragma once

#include "build_exprs.h"
#include "build_state.h"

namespace pcsg {

// Reads the body of material statement `s` into ctx.g.materials[index].
void readMaterial(BuildContext& ctx, ExprCompiler& exprs, const Stmt& s, uint32_t index);

// Reads the body of a `sky_sphere { pigment { ... } }` directive into ctx.g.scene (its
// values are constants).
void readSkySphere(BuildContext& ctx, ExprCompiler& exprs, const Stmt& s);

}  // namespace pcsg
