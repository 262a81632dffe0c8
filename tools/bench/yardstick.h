// What pcsg-embree (embree_bench.cpp) and pcsg-trace (trace_bench.cpp) share: they trace
// the same rays of a scene's image, each after its own build, --passes times, and report
// the median pass; so they take the same options and print the same figures of a trace.
#pragma once

#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_median.h"

namespace pcsg::yardstick {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

inline uint64_t peakRssBytes() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return uint64_t(u.ru_maxrss) * 1024;  // Linux: kilobytes
}

// The options of both programs.
struct TraceOptions {
    std::string scene;
    int width = 640, height = 480;
    int threads = 2;
    int passes = 5;  // the rays traced this many times after the build, the median pass timed
    bool json = false;
};

inline void addTraceOptions(CLI::App& app, TraceOptions& o) {
    app.add_option("scene", o.scene, "Scene file (.pcsg)")->required();
    app.add_option("--width", o.width, "Image width")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_option("--height", o.height, "Image height")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_option("--threads", o.threads, "Threads")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_option("--passes", o.passes,
                   "Trace the rays this many times after the build; the trace time is the "
                   "median pass's")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_flag("--json", o.json, "Print the figures as JSON");
}

// Parses the command line: -1 to go on, else the exit status (0 for --help, 2 for an error).
inline int parse(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    return -1;
}

// The timed passes of a trace: the rays of one pass and each pass's time.
struct Passes {
    uint64_t rays = 0;
    std::vector<double> seconds;
    double median() const { return tools::median(seconds); }
    double raysPerSecond() const { return median() > 0 ? double(rays) / median() : 0; }
};

// The figures both print in JSON (each adds its own).
inline nlohmann::json traceJson(const TraceOptions& o, const Passes& p, uint64_t peakRss) {
    return {{"scene", o.scene},
            {"width", o.width},
            {"height", o.height},
            {"threads", o.threads},
            {"passes", o.passes},
            {"pass_seconds", p.seconds},
            {"trace_seconds", p.median()},
            {"rays", p.rays},
            {"rays_per_second", p.raysPerSecond()},
            {"peak_rss_bytes", peakRss}};
}

}  // namespace pcsg::yardstick
