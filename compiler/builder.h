// The builder: AST -> Graph (docs/language.md sections 2-7).
//
// First the checks that need the whole file: modules declared and their rules numbered
// 1..n exactly once, one notation per module, names that resolve, parameters that some
// C-node or formal assigns, function and operator arities, materials, definitions that do
// not refer to themselves through definitions only, exactly one axiom, and no triangle
// under an intersection or a difference. Then the graph: one S-node per module, T-, C-
// and paint nodes for the unary operators, n-ary operator nodes, primitives, each
// definition built once and shared, expressions compiled to the stack code of graph.h.
#pragma once

#include <optional>

#include "ast.h"
#include "diagnostics.h"
#include "graph.h"
#include "lexer.h"

namespace pcsg {

// Builds the graph of a parsed file; nothing when an error was reported.
std::optional<Graph> build(const Source& src, const TokenStream& tokens, const Ast& ast,
                           Diagnostics& diags);

inline constexpr uint32_t kMaxMaxDepth = 10000;  // the largest settings { max_depth }

}  // namespace pcsg
