// pcsg: compile, render, export and verify PCSG scenes. See `pcsg --help`.
#include <iostream>
#include <sstream>

#include "commands.h"
#include "mpi_session.h"
#include "process_memory.h"

int main(int argc, char** argv) {
#ifdef PCSG_STATIC
    if (pcsg::tools::launchedAsRanks()) return pcsg::tools::execDynamicTwin(argv);
#endif
    pcsg::tools::fixMallocThresholds();
    CLI::App app{
        "pcsg: a scene compiler, ray tracer and verifier for recursive natural objects.\n"
        "A .pcsg file (a parametric rewriting system whose rules are CSG expressions) is\n"
        "compiled into a small cyclic CSG graph, which is ray traced directly or unrolled\n"
        "into POV-Ray 3.7 scene text.",
        "pcsg"};
    app.set_version_flag("--version", "pcsg " PCSG_VERSION);
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
        // Under mpirun every rank parses the same command line: rank 0 alone prints.
        std::ostringstream elsewhere;
        const bool print = pcsg::tools::launcherRank() == 0;
        return app.exit(e, print ? std::cout : elsewhere, print ? std::cerr : elsewhere) == 0 ? 0
                                                                                              : 2;
    }
    return status;
}
