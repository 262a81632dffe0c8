// Compiling the scene file a subcommand was given: one place for reading the file (or
// standard input for "-"), timing the compile and printing its diagnostics.
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "graph.h"

namespace pcsg::tools {

struct CompiledScene {
    std::optional<Graph> graph;  // nothing when the scene did not compile
    double seconds = 0;          // the compile's wall time
};

// Compiles `path` ("-" reads standard input). Diagnostics (a missing file, a directory,
// every compile error) go to `err` as docs/language.md section 8 prints them.
CompiledScene compileScene(const std::string& path, std::ostream& err);

}  // namespace pcsg::tools
