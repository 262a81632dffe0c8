// What the builder's phases share (builder.h runs them; docs/language.md sections 2-7).
//
//  - BuildContext: the inputs (source, tokens, syntax tree), the diagnostics and the
//    Graph being built, with the helpers every phase uses to quote the source.
//  - Names: what build_names.cpp resolves from the whole file (modules and their rules,
//    definitions and the order to build them in, materials, assigned parameters, the
//    axiom), read by the later phases.
//  - The one per-primitive fact that compiler/primitive_table.h does not hold: the
//    names of the arguments, for messages.
//
// Phase-local state (the S-node of each definition, the directives seen once, the
// expression code generator's mode) stays in the phase that owns it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "ast.h"
#include "diagnostics.h"
#include "graph.h"
#include "lexer.h"
#include "primitive_table.h"

namespace pcsg {

struct BuildContext {
    const Source& src;
    const std::vector<Token>& tokens;
    const Ast& ast;
    Diagnostics& diags;
    Graph g;

    FileLoc loc(uint32_t tok) const { return src.loc(tokens[tok].offset); }
    std::string_view text(uint32_t tok) const { return spelling(src, tokens[tok]); }
    uint32_t line(uint32_t tok) const { return loc(tok).line; }
    void error(uint32_t tok, std::string message) { diags.error(loc(tok), std::move(message)); }
};

// A module as the whole file declares it.
struct ModuleInfo {
    std::string_view name;
    uint32_t firstTok;        // where it first appears
    uint32_t decl = kNoNode;  // notation A: the declaration statement
    bool notationB = false;
    bool hasRules = false;
    std::vector<uint32_t> rules;     // statement indices, in file order (notation A: sorted)
    std::vector<uint32_t> formals;   // notation B: token indices of the first rule's formals
    uint32_t formalsRule = kNoNode;  // the rule statement they come from
    std::vector<Slot> formalSlots;   // filled in when the S-nodes are made
    NodeId node = kNone;             // its S-node, once made
};

struct Names {
    std::vector<ModuleInfo> modules;
    std::unordered_map<std::string_view, uint32_t> moduleByName;      // -> modules
    std::unordered_map<std::string_view, uint32_t> definitionByName;  // -> statement
    std::vector<uint32_t> definitionOrder;  // each definition after those it names
    std::unordered_set<uint32_t> cyclic;    // definitions on a reported cycle
    const Stmt* axiom = nullptr;

    std::unordered_map<std::string_view, uint32_t> materialByName;  // -> Graph::materials
    std::unordered_map<uint32_t, uint32_t> materialOfName;          // a material's name token -> it

    // Parameters that some C-node or formal assigns.
    std::unordered_set<std::string_view> assigned;
    // Names that a statement which failed to parse may have declared: errors about them
    // are echoes of the syntax error, and not reported.
    std::unordered_set<std::string_view> droppedNames;
    bool dropped(std::string_view name) const { return droppedNames.count(name) != 0; }
};

std::string argumentCount(uint32_t n);  // "1 argument", "3 arguments"

// The argument names of a primitive that takes arguments, for messages (the counts are
// in primitive_table.h).
inline const char* primitiveArgNames(PrimitiveKind k) {
    return k == PrimitiveKind::Torus ? "R, r" : "x1, y1, z1, x2, y2, z2, x3, y3, z3";
}

}  // namespace pcsg
