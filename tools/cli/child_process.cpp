#include "child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <sstream>

extern char** environ;

namespace pcsg::tools {

namespace {

void closeFd(int& fd) {
    if (fd >= 0) close(fd);
    fd = -1;
}

// A pipe whose ends close on exec and are not 0, 1 or 2 (were this process's standard
// streams closed, a pipe could get their numbers, and the child's dup2 onto 0, 1 and 2
// would mix them up).
bool makePipe(int fds[2]) {
    if (pipe2(fds, O_CLOEXEC) != 0) return false;
    for (int i = 0; i < 2; ++i) {
        if (fds[i] > 2) continue;
        const int moved = fcntl(fds[i], F_DUPFD_CLOEXEC, 3);
        close(fds[i]);
        fds[i] = moved;
    }
    if (fds[0] < 0 || fds[1] < 0) {
        closeFd(fds[0]);
        closeFd(fds[1]);
        return false;
    }
    return true;
}

void setNonBlocking(int fd) {
    const int flags = fcntl(fd, F_GETFL);
    if (flags >= 0) fcntl(fd, F_SETFL, flags | O_NONBLOCK);
}

// Blocks SIGPIPE in this thread while it writes to a child's pipe, and takes back the one
// a write to a closed pipe raises (unless one was pending before), so a child's early exit
// cannot kill this process. SIGPIPE from write() goes to the writing thread, so other
// threads (the render's) are not involved.
class SigpipeBlock {
  public:
    SigpipeBlock() {
        sigemptyset(&pipeSignal_);
        sigaddset(&pipeSignal_, SIGPIPE);
        pthread_sigmask(SIG_BLOCK, &pipeSignal_, &oldMask_);
        sigset_t pending;
        sigemptyset(&pending);
        sigpending(&pending);
        pendingBefore_ = sigismember(&pending, SIGPIPE) == 1;
    }
    ~SigpipeBlock() {
        if (raised_ && !pendingBefore_) {
            const timespec noWait{};
            while (sigtimedwait(&pipeSignal_, nullptr, &noWait) < 0 && errno == EINTR) {
            }
        }
        pthread_sigmask(SIG_SETMASK, &oldMask_, nullptr);
    }
    SigpipeBlock(const SigpipeBlock&) = delete;
    SigpipeBlock& operator=(const SigpipeBlock&) = delete;

    void raised() { raised_ = true; }

  private:
    sigset_t pipeSignal_, oldMask_;
    bool pendingBefore_ = false, raised_ = false;
};

// A child process with pipes to its standard streams (its input a pipe, or /dev/null),
// run to its end by runChild(): started, fed while its output is read (so that neither
// side can block the other for good), then reaped.
class Child {
  public:
    Child(const std::vector<std::string>& argv, bool withInput);
    ~Child();
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    // Writes `data` to the child's standard input, reading its output meanwhile, until all
    // of it is written or the child takes no more; then closes its input.
    void feed(std::span<const std::byte> data);
    // Reads the child's output to its end and reaps it.
    ChildResult wait();

  private:
    void readOutput(int& fd, std::string& into);
    bool pump(bool writing, std::span<const std::byte> data, size_t& written);
    ChildResult reap();

    std::string program_;
    pid_t pid_ = -1;
    int in_ = -1, out_ = -1, err_ = -1;  // this process's ends of the pipes
    std::chrono::steady_clock::time_point start_;
    ChildResult result_;
};

Child::Child(const std::vector<std::string>& argv, bool withInput) {
    start_ = std::chrono::steady_clock::now();
    if (argv.empty()) return;
    program_ = argv[0];
    int inPipe[2] = {-1, -1}, outPipe[2] = {-1, -1}, errPipe[2] = {-1, -1};
    auto closeAll = [&] {
        for (int* p : {inPipe, outPipe, errPipe}) {
            closeFd(p[0]);
            closeFd(p[1]);
        }
    };
    if ((withInput && !makePipe(inPipe)) || !makePipe(outPipe) || !makePipe(errPipe)) {
        closeAll();
        return;
    }

    // The child's ends become its 0, 1 and 2 (dup2 clears close-on-exec on the copies);
    // every other end closes on exec, so the child and any other child hold none of ours,
    // and closing ours is the end of the child's input.
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (withInput)
        posix_spawn_file_actions_adddup2(&actions, inPipe[0], 0);
    else
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, outPipe[1], 1);
    posix_spawn_file_actions_adddup2(&actions, errPipe[1], 2);
    // The child inherits neither this thread's signal mask (which may be blocking SIGPIPE
    // while another child is fed) nor an ignored SIGPIPE.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none, pipeSignal;
    sigemptyset(&none);
    sigemptyset(&pipeSignal);
    sigaddset(&pipeSignal, SIGPIPE);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &pipeSignal);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);

    start_ = std::chrono::steady_clock::now();
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, args[0], &actions, &attr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    closeFd(inPipe[0]);
    closeFd(outPipe[1]);
    closeFd(errPipe[1]);
    if (rc != 0) {
        closeAll();
        return;
    }
    result_.started = true;
    pid_ = pid;
    in_ = inPipe[1];
    out_ = outPipe[0];
    err_ = errPipe[0];
    for (int fd : {in_, out_, err_})
        if (fd >= 0) setNonBlocking(fd);
}

Child::~Child() {
    closeFd(in_);
    closeFd(out_);
    closeFd(err_);
    if (pid_ > 0) reap();  // a child is never left unreaped
}

void Child::readOutput(int& fd, std::string& into) {
    char buffer[65536];
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n > 0)
        into.append(buffer, static_cast<size_t>(n));
    else if (n == 0 || (errno != EINTR && errno != EAGAIN))
        closeFd(fd);  // the end of the output (or an error reading it)
}

// With `writing`: writes the rest of `data` (from `written` on) to the child's input until
// all of it is written or the child takes no more. Without: reads the child's output to
// its end. Either way it reads whatever output comes meanwhile, so a child blocked on a
// full output pipe cannot block the writing. Returns whether a write hit a closed pipe.
bool Child::pump(bool writing, std::span<const std::byte> data, size_t& written) {
    bool brokenPipe = false;
    for (;;) {
        const bool wantWrite = writing && in_ >= 0 && written < data.size();
        if (writing ? !wantWrite : (out_ < 0 && err_ < 0)) break;
        pollfd fds[3];
        nfds_t n = 0;
        int inAt = -1, outAt = -1, errAt = -1;
        if (wantWrite) {
            inAt = static_cast<int>(n);
            fds[n++] = {in_, POLLOUT, 0};
        }
        if (out_ >= 0) {
            outAt = static_cast<int>(n);
            fds[n++] = {out_, POLLIN, 0};
        }
        if (err_ >= 0) {
            errAt = static_cast<int>(n);
            fds[n++] = {err_, POLLIN, 0};
        }
        if (poll(fds, n, -1) < 0) {
            if (errno == EINTR) continue;
            // Only with bad descriptors, which these are not; give up rather than spin.
            closeFd(in_);
            closeFd(out_);
            closeFd(err_);
            break;
        }
        if (outAt >= 0 && fds[outAt].revents != 0) readOutput(out_, result_.out);
        if (errAt >= 0 && fds[errAt].revents != 0) readOutput(err_, result_.err);
        if (inAt >= 0 && fds[inAt].revents != 0) {
            const ssize_t k = write(in_, data.data() + written, data.size() - written);
            if (k > 0) {
                written += static_cast<size_t>(k);
            } else if (k < 0 && (errno == EINTR || errno == EAGAIN)) {
                continue;
            } else {
                // EPIPE: the child has exited or closed its input; it takes no more.
                brokenPipe = brokenPipe || (k < 0 && errno == EPIPE);
                closeFd(in_);
            }
        }
    }
    return brokenPipe;
}

void Child::feed(std::span<const std::byte> data) {
    if (in_ >= 0 && !data.empty()) {
        SigpipeBlock block;
        size_t written = 0;
        if (pump(true, data, written)) block.raised();
        result_.inputWritten += written;
    }
    closeFd(in_);
}

ChildResult Child::wait() {
    closeFd(in_);
    size_t none = 0;
    pump(false, {}, none);
    return reap();
}

ChildResult Child::reap() {
    if (pid_ <= 0) return result_;  // never started, or reaped already
    int status = 0;
    rusage usage{};
    pid_t got;
    while ((got = wait4(pid_, &status, 0, &usage)) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    result_.started = true;
    result_.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (got < 0) return result_;  // someone else reaped it (SIGCHLD ignored): status unknown
    result_.peakRssBytes = static_cast<uint64_t>(usage.ru_maxrss) * 1024;
    if (WIFEXITED(status)) {
        result_.exitCode = WEXITSTATUS(status);
        // An old posix_spawnp reports a missing program as exit 127 from the child.
        if (result_.exitCode == 127 && program_.find('/') == std::string::npos && !inPath(program_))
            result_.started = false;
    } else if (WIFSIGNALED(status)) {
        result_.signal = WTERMSIG(status);
    }
    return result_;
}

}  // namespace

ChildResult runChild(const std::vector<std::string>& argv) {
    Child child(argv, false);
    return child.wait();
}

ChildResult runChild(const std::vector<std::string>& argv, std::span<const std::byte> input) {
    Child child(argv, true);
    child.feed(input);
    return child.wait();
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
