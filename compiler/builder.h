// The builder: AST -> Graph (docs/language.md sections 2-7), in phases over one shared
// BuildContext and the Names it resolves (build_state.h):
//
//  1. build_scene.h  the settings directive (its seed is used by later constants);
//  2. build_names.h  material names;
//  3. build_scene.h  camera, light, background and the materials' items;
//  4. build_names.h  modules and their rules in notations A and B, definitions, assigned
//                    parameters, exactly one axiom, the definition order and cycles;
//  5. build_csg.h    S-, T-, C-, paint, operator and primitive nodes, each definition
//                    built once and shared, with expressions compiled by build_exprs.h
//                    to the stack code of graph.h;
//  6. build_checks.h no triangle under an intersection or a difference.
//
// Every phase runs even after errors, so that one run reports as many as it can.
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
