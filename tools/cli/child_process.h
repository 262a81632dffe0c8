// Running another program (POV-Ray, pcsg itself for a measured native render, or the
// pcsg-image helper for EXR/TIFF files and image comparisons) to its end and measuring
// it: exit status, wall time and the peak resident set size of the whole command.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pcsg::tools {

struct ChildResult {
    bool started = false;  // false: the program could not be run at all
    int exitCode = -1;     // -1 when killed by a signal
    int signal = 0;
    double seconds = 0;  // wall time, from the start to the exit
    // The whole command's peak RSS as wait4 reports it (Linux), and as /usr/bin/time -v
    // prints it: the largest of the child's own, that of any descendant it waited for (a
    // `pcsg render` of an EXR that ran pcsg-image reports the larger of the two), and this
    // process's RSS when the child started: posix_spawn's child runs in this
    // process's memory until its exec, and exec records that memory's peak as the
    // child's. So a small parent matters for honest figures.
    uint64_t peakRssBytes = 0;
    std::string out, err;  // captured standard output and error
    // With input: how many of its bytes the child took before it exited or closed its
    // standard input (all of them unless it stopped reading early).
    size_t inputWritten = 0;
};

// Runs argv[0] (searched in PATH) with the arguments, standard input from /dev/null.
ChildResult runChild(const std::vector<std::string>& argv);

// Runs argv[0] likewise with `input` on its standard input, through a pipe: writes all of
// it while reading the child's output, closes the pipe, then waits. A child that exits (or
// dies) before it has read everything ends the writing early (no SIGPIPE reaches this
// process); inputWritten says how far it got. The child starts with no blocked signals
// and SIGPIPE at its default.
ChildResult runChild(const std::vector<std::string>& argv, std::span<const std::byte> input);

// The absolute path of the running executable (to run pcsg's own subcommands).
std::string selfExecutable();

// Whether a program is found in PATH.
bool inPath(const std::string& program);

}  // namespace pcsg::tools
