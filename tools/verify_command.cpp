// Placeholder until verify lands (issue 5): `pcsg verify` is not available yet.
#include <iostream>

#include "commands.h"

namespace pcsg::tools {
void addVerifyCommand(CLI::App& app, int& status) {
    auto* cmd = app.add_subcommand("verify", "Render a scene natively and with POV-Ray and compare (not yet available)");
    cmd->callback([&status] {
        std::cerr << "pcsg verify: not available yet\n";
        status = 2;
    });
}
}  // namespace pcsg::tools
