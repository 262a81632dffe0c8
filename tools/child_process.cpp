#include "child_process.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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
}  // namespace

ChildResult runChild(const std::vector<std::string>& argv) {
    ChildResult r;
    if (argv.empty()) return r;
    namespace fs = std::filesystem;
    char tmpl[] = "/tmp/pcsg-child-XXXXXX";
    if (!mkdtemp(tmpl)) return r;
    const std::string dir = tmpl;
    const std::string outPath = dir + "/out", errPath = dir + "/err";

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
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
