// The builder's scene phase: the directives camera, light, background, material and
// settings (docs/language.md section 7) read into Graph::scene and Graph::materials. Their
// values are constants (ExprCompiler::constant), or read the time (section 11) and are
// kept as Graph::timedValues for setTime() (scene_time.h); material names are registered before,
// by build_names.h, so that paint() may name a material defined later in the file.
#pragma once

#include "build_exprs.h"
#include "build_state.h"

namespace pcsg {

// The settings directive, first of all: rand(x) in later constants uses its seed.
void readSettings(BuildContext& ctx, ExprCompiler& exprs);

// camera, light, background and the items of each material, in file order.
void readDirectives(BuildContext& ctx, const Names& names, ExprCompiler& exprs);

// The default light, when the file gives none.
void addDefaultLight(BuildContext& ctx);

}  // namespace pcsg
