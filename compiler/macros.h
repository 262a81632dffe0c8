// The lexer's second step, the macro processor: `#define NAME body` and the expansion of
// each use of NAME as tokens (docs/language.md section 1, "#define"). Between the scanner
// and the newline rule of lexer.cpp; the parser never sees a '#'.
#pragma once

#include <vector>

#include "diagnostics.h"
#include "lexer.h"

namespace pcsg {

// Reads the #define lines of `raw` (the scanner's tokens, ending with End) and writes
// the other tokens to `out` with every macro use replaced by its body, and the End.
// Returns false when it stopped early (an unclosed block, too many tokens): `out` is
// then only a prefix of the file.
// With `origins`, its defines, its uses and its useOf (one entry per token of `out`) are
// filled too.
bool expandMacros(const Source& src, Diagnostics& diags, const std::vector<Token>& raw,
                  std::vector<Token>& out, MacroOrigins* origins = nullptr);

}  // namespace pcsg
