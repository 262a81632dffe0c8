// Placeholder until the exporter lands (issue 4): `pcsg export-pov` and `pcsg stats`.
#include <iostream>

#include "commands.h"

namespace pcsg::tools {
void addExportCommands(CLI::App& app, int& status) {
    for (const char* name : {"export-pov", "stats"}) {
        auto* cmd = app.add_subcommand(name, "(not yet available)");
        cmd->callback([&status, name] {
            std::cerr << "pcsg " << name << ": not available yet\n";
            status = 2;
        });
    }
}
}  // namespace pcsg::tools
