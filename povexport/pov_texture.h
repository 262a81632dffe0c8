// A material's pigment and normal as POV-Ray 3.7 text (docs/language.md section 10),
// exactly as the compiler read them: the pattern with its list colours or colour map, its
// modifiers and its transformations in the order written.
#pragma once

#include <string>

#include "graph.h"

namespace pcsg {

// `pigment { ... }` of material m.
std::string povPigment(const Material& m);

// `pigment { ... }` of a pigment whose plain colour is `plain`.
std::string povPigment(const Pigment& p, const FilterColour& plain);

// ` normal { ... }` (with its leading blank) of material m, or "" without a normal pattern.
std::string povNormal(const Material& m);

}  // namespace pcsg
