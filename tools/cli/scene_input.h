// Compiling the scene file a subcommand was given: one place for reading the file (or
// standard input for "-"), timing the compile and printing its diagnostics.
#pragma once

#include <CLI/CLI.hpp>
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

// Sets the time of the frame to render or export (compiler/scene_time.h: `clock`, `frame`
// and the directive values that read them). False, with the run-time error printed to
// `err`, when a directive value is bad at that time.
bool setSceneTime(Graph& g, Time t, std::ostream& err);

// Adds `--clock X` to a subcommand: the clock of the still (frame 1), a finite number.
CLI::Option* addClockOption(CLI::App* cmd, double& clock);

// --frame F: the frame number the still reads as `frame` (default 1), for one frame of a
// sequence rendered alone (`pcsg verify --frames` passes it on).
CLI::Option* addFrameOption(CLI::App* cmd, int& frame);

}  // namespace pcsg::tools
