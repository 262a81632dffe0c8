// Running another program (POV-Ray, pcsg itself for a measured native render, or the
// pcsg-image helper) and measuring it: exit status, wall time and the child's peak
// resident set size. runChild() runs a program to its end; AsyncChild starts one now and
// feeds and waits for it later (pcsg render starts pcsg-image before it renders, so that
// the helper's start-up overlaps the render).
#pragma once

#include <sys/types.h>

#include <chrono>
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
    // The child's peak RSS as wait4 reports it (Linux): the largest of the child's own,
    // that of any descendant it waited for (a `pcsg render` that ran pcsg-image reports
    // the larger of the two; `pcsg render --json` prints its own as "peak_rss_bytes"),
    // and this process's RSS when the child started: posix_spawn's child runs in this
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
// it, closes the pipe, then waits (AsyncChild's feed() and wait()). A child that exits (or
// dies) before it has read everything ends the writing early (no SIGPIPE reaches this
// process); inputWritten says how far it got.
ChildResult runChild(const std::vector<std::string>& argv, std::span<const std::byte> input);

// A child process started now and finished later. Its standard input is a pipe from this
// process (or /dev/null), its standard output and error are pipes to this process, read
// whenever it writes to or waits for the child, so that neither side can block the other
// for good. The child starts with no blocked signals and SIGPIPE at its default.
//
// Every child is reaped: by wait(), by abandon(), or else by the destructor (which
// abandons it). This process never gets a SIGPIPE from a child that is gone.
class AsyncChild {
  public:
    enum class Input { Pipe, DevNull };

    // Starts argv[0] (searched in PATH) with the arguments; started() says whether it ran.
    explicit AsyncChild(const std::vector<std::string>& argv, Input input = Input::Pipe);
    ~AsyncChild();
    AsyncChild(const AsyncChild&) = delete;
    AsyncChild& operator=(const AsyncChild&) = delete;

    // Whether the program could be run (a missing one could not).
    bool started() const { return started_; }
    // The child's process id while it has not been reaped, else -1.
    pid_t pid() const { return pid_; }

    // Writes `data` to the child's standard input, reading its output meanwhile; returns
    // how many bytes it took. Fewer than all when the child has exited or closed its
    // standard input (the rest is not written, nor anything fed later), and nothing once
    // closeInput(), wait() or abandon() was called.
    size_t feed(std::span<const std::byte> data);

    // The end of the child's input.
    void closeInput();

    // Closes the child's input, reads its output to the end and reaps it. Once only: later
    // calls return what the first one did.
    ChildResult wait();

    // Gives up on the child: closes its input unwritten, kills it (SIGKILL) unless it has
    // already exited, discards its output and reaps it. A child that was never given its
    // input has nothing to finish, and waiting for it to notice the end of its input could
    // take as long as its start-up. Returns how it ended (the output left empty).
    ChildResult abandon();

  private:
    void readOutput(int& fd, std::string& into);
    bool pump(bool writing, std::span<const std::byte> data, size_t& written);
    ChildResult reap(bool keepOutput);

    bool started_ = false;
    std::string program_;
    pid_t pid_ = -1;
    int in_ = -1, out_ = -1, err_ = -1;  // this process's ends of the pipes
    std::chrono::steady_clock::time_point start_;
    ChildResult result_;
};

// The absolute path of the running executable (to run pcsg's own subcommands).
std::string selfExecutable();

// Whether a program is found in PATH.
bool inPath(const std::string& program);

}  // namespace pcsg::tools
