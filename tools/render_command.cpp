// Placeholder until the tracer lands (issue 3): `pcsg render` is not available yet.
#include <iostream>

#include "commands.h"

namespace pcsg::tools {
void addRenderCommand(CLI::App& app, int& status) {
    auto* cmd = app.add_subcommand("render", "Ray trace a scene's cyclic graph (not yet available)");
    cmd->callback([&status] {
        std::cerr << "pcsg render: not available yet\n";
        status = 2;
    });
}
}  // namespace pcsg::tools
