// pcsg fmt: prints a scene in one canonical layout from its syntax tree (ast.h).
//
// Statements keep their order, one per line; operators, C-nodes and directives get one
// spacing; numbers, names and keywords keep their source text (so no value changes);
// `|` `&` `→` become `∪` `∩` `->`; a statement wider than kFormatWidth columns is broken
// after `∪` (or `∩`, `\`) before an operand that does not fit, and at a C-node's `;`
// only inside an operand too long for a line; continuation lines are indented by
// kFormatIndent spaces, and a directive too wide for one line gets one item per line.
// Parentheses are printed where the grammar needs them to give the same tree back.
//
// Comments (which the lexer drops) are found by position in the text and kept: a comment
// before a statement stays on its own line(s) before it, one after a statement's end on
// the same line stays there, one inside the braces of a C-node or a directive puts it
// over several lines (one assignment or item a line, the comment after its item or on a
// line of its own before the next), and any other inside a statement's text moves to a
// line of its own just before that statement. One blank line is kept where the text had one or
// more.
//
// Macros: the lexer expands them before the parser, so the tree shows their bodies. The
// lexer says where each token came from (MacroOrigins), and a construct made of exactly
// one use's tokens (a C-node's block, as in the paper's figure 8, an expression, a CSG
// term, a single token) is printed as the macro's name; each #define is printed as
// written, in its place. A use that is only part of a construct (`#define PART
// move(1,0,0)` in `PART sphere`), one that expands to nothing, and a #define inside a
// statement cannot be kept so: the file is refused, with the place.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "ast.h"
#include "diagnostics.h"
#include "lexer.h"

namespace pcsg {

inline constexpr size_t kFormatWidth = 100;
inline constexpr size_t kFormatIndent = 4;

// The canonical text of a scene, or nothing with the errors in `diags` when the scene
// does not compile, or has a macro that cannot be kept (above). `text` must outlive `diags`.
std::optional<std::string> formatScene(std::string_view fileName, std::string_view text,
                                       Diagnostics& diags);

// The statements of a syntax tree printed as formatScene prints them, one a line, without
// comments: for tools that edit a parsed tree and print it back (pcsg fuzz's shrinker).
// `src` and `tokens` are those the tree's token indices refer to; an edited tree may use
// tokens of its own appended after the End token, whose text lies in `src`.
std::string printSyntaxTree(const Source& src, const std::vector<Token>& tokens, const Ast& ast);

}  // namespace pcsg
