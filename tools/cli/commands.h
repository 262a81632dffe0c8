// The subcommands of `pcsg`, one file each in tools/cli/: check_command.cpp,
// graph_command.cpp, render_command.cpp, export_command.cpp (export-pov),
// stats_command.cpp, verify_command.cpp, bench_command.cpp, fmt_command.cpp, fuzz_command.cpp. Each
// adds its subcommand to the app and runs it when selected.
#pragma once

#include <CLI/CLI.hpp>

namespace pcsg::tools {

// Each function registers one or more subcommands. A subcommand's callback stores its
// exit status in `status` (0 success, 1 failure of the input, 2 could not run).
void addCheckCommand(CLI::App& app, int& status);   // check
void addGraphCommand(CLI::App& app, int& status);   // graph
void addRenderCommand(CLI::App& app, int& status);  // render
void addExportCommand(CLI::App& app, int& status);  // export-pov
void addStatsCommand(CLI::App& app, int& status);   // stats
void addVerifyCommand(CLI::App& app, int& status);  // verify
void addBenchCommand(CLI::App& app, int& status);   // bench
void addFmtCommand(CLI::App& app, int& status);     // fmt
void addFuzzCommand(CLI::App& app, int& status);    // fuzz

}  // namespace pcsg::tools
