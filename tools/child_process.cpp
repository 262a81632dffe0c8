#include "child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

extern char** environ;

namespace pcsg::tools {

namespace {
std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Writes all of `data` to the pipe `fd`, stopping early when the reader is gone. SIGPIPE
// is blocked in this thread while writing, and the one a failed write raises is taken
// back (unless one was pending before), so the child's early exit cannot kill this
// process. Returns how many bytes were written.
size_t writeAll(int fd, std::span<const std::byte> data) {
    sigset_t pipeSignal, oldMask, pending;
    sigemptyset(&pipeSignal);
    sigaddset(&pipeSignal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipeSignal, &oldMask);
    sigemptyset(&pending);
    sigpending(&pending);
    const bool pendingBefore = sigismember(&pending, SIGPIPE) == 1;
    size_t written = 0;
    bool brokenPipe = false;
    while (written < data.size()) {
        const ssize_t n = write(fd, data.data() + written, data.size() - written);
        if (n > 0) {
            written += static_cast<size_t>(n);
        } else if (n < 0 && errno == EINTR) {
            continue;
        } else {
            brokenPipe = n < 0 && errno == EPIPE;
            break;
        }
    }
    if (brokenPipe && !pendingBefore) {
        const timespec noWait{};
        while (sigtimedwait(&pipeSignal, nullptr, &noWait) < 0 && errno == EINTR) {
        }
    }
    pthread_sigmask(SIG_SETMASK, &oldMask, nullptr);
    return written;
}

// Runs the child with standard input from `stdinFd` (in the child) or /dev/null (-1);
// `feed`, when given, runs in this process after the child started.
ChildResult spawnAndWait(const std::vector<std::string>& argv, int stdinFd,
                         const std::function<void(ChildResult&)>& feed) {
    ChildResult r;
    if (argv.empty()) return r;
    namespace fs = std::filesystem;
    char tmpl[] = "/tmp/pcsg-child-XXXXXX";
    if (!mkdtemp(tmpl)) return r;
    const std::string dir = tmpl;
    const std::string outPath = dir + "/out", errPath = dir + "/err";

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (stdinFd >= 0)
        posix_spawn_file_actions_adddup2(&actions, stdinFd, 0);
    else
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);

    const auto start = std::chrono::steady_clock::now();
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc == 0) {
        if (feed) feed(r);
        int status = 0;
        rusage usage{};
        while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
        }
        r.started = true;
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        r.peakRssBytes = static_cast<uint64_t>(usage.ru_maxrss) * 1024;
        if (WIFEXITED(status)) {
            r.exitCode = WEXITSTATUS(status);
            // posix_spawnp reports a missing program as exit 127 from the child.
            if (r.exitCode == 127 && !inPath(argv[0]) && argv[0].find('/') == std::string::npos)
                r.started = false;
        } else if (WIFSIGNALED(status)) {
            r.signal = WTERMSIG(status);
        }
        r.out = slurp(outPath);
        r.err = slurp(errPath);
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    return r;
}

}  // namespace

ChildResult runChild(const std::vector<std::string>& argv) {
    return spawnAndWait(argv, -1, {});
}

ChildResult runChild(const std::vector<std::string>& argv, std::span<const std::byte> input) {
    // Both ends close on exec: the child gets the read end as its standard input (dup2
    // clears the flag on the copy), and neither it nor any other child holds the write
    // end, so closing ours is the end of its input.
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) return ChildResult{};
    ChildResult r = spawnAndWait(argv, fds[0], [&](ChildResult& result) {
        close(fds[0]);
        fds[0] = -1;
        result.inputWritten = writeAll(fds[1], input);
        close(fds[1]);
        fds[1] = -1;
    });
    for (int fd : fds)
        if (fd >= 0) close(fd);
    return r;
}

std::string selfExecutable() {
    std::error_code ec;
    const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::string("pcsg") : p.string();
}

bool inPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    if (!path) return false;
    std::stringstream dirs(path);
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        if (dir.empty()) continue;
        const std::string candidate = dir + "/" + program;
        if (access(candidate.c_str(), X_OK) == 0) return true;
    }
    return false;
}

}  // namespace pcsg::tools
