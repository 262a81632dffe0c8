// Placeholder until the benchmarks land (issue 6): `pcsg bench` is not available yet.
#include <iostream>

#include "commands.h"

namespace pcsg::tools {
void addBenchCommand(CLI::App& app, int& status) {
    auto* cmd = app.add_subcommand("bench", "Benchmark native rendering against POV-Ray (not yet available)");
    cmd->callback([&status] {
        std::cerr << "pcsg bench: not available yet\n";
        status = 2;
    });
}
}  // namespace pcsg::tools
