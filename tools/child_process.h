// Running another program (POV-Ray, or pcsg itself for a measured native render) and
// measuring it: exit status, wall time and the child's own peak resident set size.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pcsg::tools {

struct ChildResult {
    bool started = false;   // false: the program could not be run at all
    int exitCode = -1;      // -1 when killed by a signal
    int signal = 0;
    double seconds = 0;     // wall time
    uint64_t peakRssBytes = 0;
    std::string out, err;   // captured standard output and error
};

// Runs argv[0] (searched in PATH) with the arguments, standard input from /dev/null.
ChildResult runChild(const std::vector<std::string>& argv);

// The absolute path of the running executable (to run pcsg's own subcommands).
std::string selfExecutable();

// Whether a program is found in PATH.
bool inPath(const std::string& program);

}  // namespace pcsg::tools
