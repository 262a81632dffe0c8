// The abstract syntax of a .pcsg file, as the parser leaves it for the builder.
//
// Nodes live in flat arrays and refer to each other by index (no pointers, nothing to
// free recursively); every node remembers its first token, from which the builder gets
// source locations and text. Chains of one operator are stored flat: `a + b - c` is one
// Chain node, `A ∪ B ∪ C` one Union node with three operands, so that a file of a
// million terms never needs a deep recursion to build or to destroy.
#pragma once

#include <cstdint>
#include <vector>

#include "graph.h"
#include "lexer.h"

namespace pcsg {

inline constexpr uint32_t kNoNode = UINT32_MAX;

// ---------------------------------------------------------------------------------------
// Arithmetic expressions (docs/language.md section 3).

enum class ExKind : uint8_t {
    Number,  // value
    Name,    // a parameter: the token `tok`
    Unary,   // op (Minus, Bang or Plus) applied to `a`
    Chain,   // a op1 x1 op2 x2 ...: left-associative operators of one precedence level;
             // items [first, first+count) of Ast::chainItems
    Power,   // a ^ b
    Call,    // the function (keyword or unknown identifier) at `tok`; arguments are
             // [first, first+count) of Ast::lists
    Time,    // `clock` or `frame`: the keyword at `tok`
};

struct ExNode {
    ExKind kind;
    Tok op = Tok::End;          // Unary's operator
    uint32_t tok = 0;           // the token that names it: the number, parameter, operator
                                // or function (Chain, Power: the first token)
    uint32_t from = 0, to = 0;  // its first and last token, parentheses included
    double value = 0;           // Number
    uint32_t a = kNoNode, b = kNoNode;
    uint32_t first = 0, count = 0;
};

struct ChainItem {
    Tok op;
    uint32_t tok;      // the operator's token
    uint32_t operand;  // ExNode index
};

// ---------------------------------------------------------------------------------------
// CSG expressions (section 5).

enum class CsgKind : uint8_t {
    Operator,   // `csgOp` on operands [first, first+count) of Ast::lists
    Transform,  // `op` on `child`; its arguments [first, first+count) of Ast::lists (ExNodes)
    Calc,       // a C-node { ... } on `child`; assignments [first, first+count) of Ast::assigns
    Paint,      // paint(name) on `child`; the material's name at `nameTok`
    Primitive,  // `prim`; arguments [first, first+count) of Ast::lists (ExNodes)
    Name,       // a module or definition name at `nameTok`
    Call,       // a notation-B call `S(e1, ...)`: S at `nameTok`, arguments as for Transform
};

struct CsgNode {
    CsgKind kind;
    CsgOp csgOp = CsgOp::Union;  // Operator
    TransformOp op = TransformOp::Move;
    PrimitiveKind prim = PrimitiveKind::Empty;
    uint32_t tok = 0;      // the first token (for operators: the first operator token)
    uint32_t nameTok = 0;  // Paint, Name, Call
    uint32_t child = kNoNode;
    uint32_t first = 0, count = 0;
};

struct Assign {
    uint32_t nameTok;
    uint32_t value;  // ExNode index
};

// ---------------------------------------------------------------------------------------
// Statements (section 2).

enum class StmtKind : uint8_t {
    Directive,   // camera/light/background/material/settings: items of Ast::items
    RuleA,       // number: module -> body
    RuleB,       // label: module(formals) : condition -> body
    AxiomB,      // label: body
    Definition,  // name = body
    Module,      // name selection-expression
    AxiomA,      // body
};

// One `name value` item of a directive; `background <...>` is one item with name the
// keyword itself. A vector has three components, a scalar one. A name alone (`spotlight`)
// is a flag. Values after a comma (`area_light <a1>, <a2>, 4, 4`) are the `more` items that
// follow this one in Ast::items, each with the same name token.
struct DirectiveItem {
    uint32_t nameTok;
    bool vector = false;
    bool flag = false;
    uint8_t more = 0;
    uint32_t e[3] = {kNoNode, kNoNode, kNoNode};
};

// One element of a material's body (docs/language.md sections 7 and 10), which follows
// POV-Ray's free syntax: a word (`pigment`, `rgb`, `fresnel`, `scale`), a number
// (an expression), a vector `<a, b, ...>` of 2 to 5 components (Ast::lists holds their
// expressions), a block `{ ... }` or a bracket `[ ... ]` (its atoms [first, first+count)
// of Ast::atoms). The builder reads the sequence; separators (`,` `;` line breaks) are
// not kept.
enum class AtomKind : uint8_t { Word, Number, Vector, Block, Bracket };
struct Atom {
    AtomKind kind;
    uint32_t tok = 0;               // the first token ('<', '{', '[' for the composites)
    uint32_t end = 0;               // the last token ('>', '}', ']'; else tok's last)
    uint32_t expr = kNoNode;        // Number
    uint32_t first = 0, count = 0;  // Vector: Ast::lists; Block, Bracket: Ast::atoms
};

struct Stmt {
    StmtKind kind;
    uint32_t tok = 0;               // the first token
    uint32_t nameTok = 0;           // module (rules, Module), definition or material name
    uint32_t labelTok = 0;          // RuleB / AxiomB label, RuleA number
    Kw directive = Kw::None;        // Directive: which one
    uint32_t number = 0;            // RuleA: the rule number
    uint32_t expr = kNoNode;        // Module: selection; RuleB: condition (kNoNode: none)
    uint32_t body = kNoNode;        // CsgNode index
    uint32_t first = 0, count = 0;  // RuleB formals (token indices in Ast::lists);
                                    // Directive items [first, first+count) of Ast::items;
                                    // a material's body: atoms of Ast::atoms
    uint32_t last = 0;              // a material: its closing '}'
    bool hasFormals = false;        // RuleB: `S(...)` rather than `S`
};

struct Ast {
    std::vector<Stmt> stmts;
    std::vector<ExNode> exprs;
    std::vector<ChainItem> chainItems;
    std::vector<CsgNode> csg;
    std::vector<Assign> assigns;
    std::vector<DirectiveItem> items;
    std::vector<Atom> atoms;
    std::vector<uint32_t> lists;  // operand, argument and formal lists

    // What syntax errors left out, so that the builder does not report their echoes:
    // the names that a dropped statement may have declared or defined (token indices),
    // and how many statements were dropped (any of them may have been the axiom or have
    // assigned a parameter).
    std::vector<uint32_t> droppedNames;
    uint32_t dropped = 0;
};

}  // namespace pcsg
