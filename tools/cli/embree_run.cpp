// Running pcsg-embree: see embree_run.h.
#include "embree_run.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "child_process.h"

namespace pcsg::tools {

std::optional<std::string> findEmbree() {
    const std::filesystem::path self = selfExecutable();
    if (!self.has_parent_path()) return std::nullopt;
    const std::filesystem::path beside = self.parent_path() / "pcsg-embree";
    if (access(beside.c_str(), X_OK) != 0) return std::nullopt;
    return beside.string();
}

std::optional<EmbreeRun> runEmbree(const std::string& embree, const std::string& scene, int width,
                                   int height, int threads, uint64_t maxNodes) {
    if (threads <= 0) threads = static_cast<int>(std::thread::hardware_concurrency());
    const ChildResult c =
        runChild({embree, scene, "--json", "--width", std::to_string(width), "--height",
                  std::to_string(height), "--threads", std::to_string(std::max(threads, 1)),
                  "--max-nodes", std::to_string(maxNodes)});
    if (c.exitCode != 0) return std::nullopt;
    const auto j = nlohmann::json::parse(c.out, nullptr, false);
    if (!j.is_object()) return std::nullopt;
    EmbreeRun e;
    e.triangles = j.value("triangles", uint64_t{0});
    e.buildSeconds = j.value("build_seconds", 0.0);
    e.traceSeconds = j.value("trace_seconds", 0.0);
    e.raysPerSecond = j.value("rays_per_second", 0.0);
    e.seconds = c.seconds;
    e.peakRss = c.peakRssBytes;
    return e;
}

}  // namespace pcsg::tools
