// pcsg: compile, render, export and verify PCSG scenes. See `pcsg --help`.
#include <iostream>

#include "commands.h"

int main(int argc, char** argv) {
    CLI::App app{
        "pcsg: a scene compiler, ray tracer and verifier for recursive natural objects.\n"
        "A .pcsg file (a parametric rewriting system whose rules are CSG expressions) is\n"
        "compiled into a small cyclic CSG graph, which is ray traced directly or unrolled\n"
        "into POV-Ray 3.7 scene text.",
        "pcsg"};
    app.require_subcommand(1);
    int status = 0;
    pcsg::tools::addCheckCommand(app, status);
    pcsg::tools::addGraphCommand(app, status);
    pcsg::tools::addRenderCommand(app, status);
    pcsg::tools::addExportCommand(app, status);
    pcsg::tools::addStatsCommand(app, status);
    pcsg::tools::addVerifyCommand(app, status);
    pcsg::tools::addBenchCommand(app, status);
    pcsg::tools::addFmtCommand(app, status);
    pcsg::tools::addFuzzCommand(app, status);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    return status;
}
