// The builder's name phase: everything that needs the whole file before any node is made
// (docs/language.md sections 2 and 4; material names of section 7). Modules are declared
// and their rules numbered 1..n exactly once, in one notation per module, with the same
// formals in every notation-B rule; module and definition names are unique in their
// shared namespace; materials are unique; the parameters that some C-node or formal
// assigns are collected; the file has exactly one axiom; definitions are put in an order
// where each comes after those it names, and those that refer to themselves through
// definitions only are reported (section 5, "From expressions to the graph").
#pragma once

#include <string>
#include <vector>

#include "build_state.h"

namespace pcsg {

// Registers the material names (Graph::materials[0] is already "default") before any
// directive's items are read or any paint() is built: materials may come later.
void declareMaterials(BuildContext& ctx, Names& names);

// Modules, rules, definitions, assigned parameters, the axiom and the definition order.
void resolveNames(BuildContext& ctx, Names& names);

// "c, d": the names of formal parameters (token indices), for messages.
std::string formalList(const BuildContext& ctx, const std::vector<uint32_t>& toks);

}  // namespace pcsg
