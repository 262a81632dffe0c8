// The compiler's entry points: from .pcsg text to the cyclic CSG graph.
// Phases: lexer.cpp (tokens; #define in macros.cpp) -> parser.cpp (AST, ast.h) ->
// builder.cpp (names, scene directives, expressions, CSG lowering and checks, in the
// build_*.cpp files: the Graph of graph.h) -> fold_constants.cpp (parameters that are
// constants become constants).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "diagnostics.h"
#include "graph.h"

namespace pcsg {

struct CompileOptions {
    // Fold parameters that are constants (fold_constants.h). Off only for tests that
    // check the folding changes nothing.
    bool foldConstants = true;
};

// Compiles source text. Returns the graph, or nothing with the errors in `diags`.
// `text` must outlive `diags` (diagnostics quote source lines).
std::optional<Graph> compileSource(std::string_view fileName, std::string_view text,
                                   Diagnostics& diags, const CompileOptions& options = {});

// Reads and compiles a file. An unreadable file is a diagnostic too. The file's text is
// kept alive by `diags`' owner through `storage`.
std::optional<Graph> compileFile(const std::string& path, std::string& storage, Diagnostics& diags);

}  // namespace pcsg
