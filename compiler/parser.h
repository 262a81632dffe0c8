// The parser: tokens -> AST (docs/language.md sections 2-7), by recursive descent.
//
// Statement kinds are decided from their first tokens as in section 2's table. A syntax
// error reports the first problem of its statement and resumes at the next statement
// (panic mode), so that one run reports every independent error. Nesting (parentheses,
// braces, unary prefixes) is limited to kMaxNesting levels so that no input can exhaust
// the stack.
#pragma once

#include "ast.h"
#include "diagnostics.h"
#include "lexer.h"

namespace pcsg {

inline constexpr uint32_t kMaxNesting = 500;
inline constexpr uint32_t kMaxRuleNumber = 1000000;

// Parses a token stream. Statements with syntax errors are reported and left out of the
// AST.
Ast parse(const Source& src, const TokenStream& tokens, Diagnostics& diags);

// Binary operator precedence, loosest 1 to tightest 6; 0: not a binary operator. `=` is
// `==` in a notation-B condition (assignIsEq). ('^' and the unary operators have their
// own parse functions.) The formatter uses the same table to place parentheses.
int binaryPrecedence(Tok k, bool assignIsEq);

}  // namespace pcsg
