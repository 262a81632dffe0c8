// Compiling scene text in the compiler's tests: the text, its diagnostics and the graph
// kept together (diagnostics quote the text).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "compiler.h"

namespace pcsg::testing {

struct Compiled {
    std::string text;
    Diagnostics diags;
    std::optional<Graph> graph;
    std::string errors() const { return diags.format(); }
};

inline std::unique_ptr<Compiled> compile(std::string text, const CompileOptions& options = {}) {
    auto c = std::make_unique<Compiled>();
    c->text = std::move(text);
    c->graph = compileSource("t.pcsg", c->text, c->diags, options);
    return c;
}

// The graph as the builder makes it, before fold_constants.cpp folds constant parameters
// (fold_constants_test.cpp tests the folding).
inline std::unique_ptr<Compiled> compileUnfolded(std::string text) {
    return compile(std::move(text), CompileOptions{.foldConstants = false});
}

}  // namespace pcsg::testing
