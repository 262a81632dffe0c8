// Running pcsg-embree: see embree_run.h.
#include "embree_run.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "child_process.h"

namespace pcsg::tools {

namespace {

// The program `name` beside this executable, if it is there and executable.
std::optional<std::string> findBeside(const char* name) {
    const std::filesystem::path self = selfExecutable();
    if (!self.has_parent_path()) return std::nullopt;
    const std::filesystem::path beside = self.parent_path() / name;
    if (access(beside.c_str(), X_OK) != 0) return std::nullopt;
    return beside.string();
}

// The program run to its end and its standard output read as a JSON object: nothing when
// it failed or printed no object.
std::optional<nlohmann::json> runForJson(const std::vector<std::string>& argv, ChildResult& c) {
    c = runChild(argv);
    if (c.exitCode != 0) return std::nullopt;
    auto j = nlohmann::json::parse(c.out, nullptr, false);
    if (!j.is_object()) return std::nullopt;
    return j;
}

int threadsOrCores(int threads) {
    if (threads <= 0) threads = static_cast<int>(std::thread::hardware_concurrency());
    return std::max(threads, 1);
}

}  // namespace

std::optional<std::string> findEmbree() {
    return findBeside("pcsg-embree");
}

std::optional<std::string> findNativeTrace() {
    return findBeside("pcsg-trace");
}

std::optional<EmbreeRun> runEmbree(const std::string& embree, const std::string& scene, int width,
                                   int height, int threads, uint64_t maxNodes) {
    ChildResult c;
    const auto j =
        runForJson({embree, scene, "--json", "--width", std::to_string(width), "--height",
                    std::to_string(height), "--threads", std::to_string(threadsOrCores(threads)),
                    "--max-nodes", std::to_string(maxNodes)},
                   c);
    if (!j) return std::nullopt;
    EmbreeRun e;
    e.triangles = j->value("triangles", uint64_t{0});
    e.buildSeconds = j->value("build_seconds", 0.0);
    e.traceSeconds = j->value("trace_seconds", 0.0);
    e.raysPerSecond = j->value("rays_per_second", 0.0);
    e.seconds = c.seconds;
    e.peakRss = c.peakRssBytes;
    return e;
}

std::optional<NativeTraceRun> runNativeTrace(const std::string& trace, const std::string& scene,
                                             int width, int height, int threads) {
    ChildResult c;
    const auto j =
        runForJson({trace, scene, "--json", "--width", std::to_string(width), "--height",
                    std::to_string(height), "--threads", std::to_string(threadsOrCores(threads))},
                   c);
    if (!j) return std::nullopt;
    NativeTraceRun n;
    n.buildSeconds = j->value("build_seconds", 0.0);
    n.traceSeconds = j->value("trace_seconds", 0.0);
    n.raysPerSecond = j->value("rays_per_second", 0.0);
    n.rays = j->value("rays", uint64_t{0});
    n.traceExpansions = j->value("trace_expansions", uint64_t{0});
    return n;
}

}  // namespace pcsg::tools
