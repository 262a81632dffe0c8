// pcsg-trace: the native side of `pcsg bench`'s trace rate against Embree. pcsg-embree
// builds its BVH first and then times the rays alone: one camera ray per pixel centre and
// one shadow ray per hit toward each light. This program times the same rays through
// pcsg's own tracer, after its own build, so that the two rates compare like with like:
//
//  - build: the graph's hyper-bounding boxes, and one render of the image's pixel centres
//    (no anti-aliasing), which fills what pcsg builds as rays ask for it (the exact boxes
//    of S-node instances, the expanded instances, the two-level structure);
//  - trace: the same render again on the same renderer (tracer/render.h's RegionRenderer,
//    whose caches persist from region to region), timed alone, --passes times (5), the
//    trace time the median pass's (as pcsg-embree's). Whatever the caches' budgets evicted
//    is built again in it, and counted: pcsg's memory bounds are part of its trace rate.
//
// The render shades each hit as `pcsg render` does (shadow rays toward each light that
// the surface faces, and the colour), work that Embree's loop does not do; so the rate is
// if anything lower than the tracer's alone. It prints the build and trace times, the rays
// of the trace, rays per second and its own peak RSS; `--json` prints them as JSON.
//
// Exit status: 0 done; 1 the scene did not compile or its render met a run-time error;
// 2 a bad command line.
#include <fmt/format.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_median.h"
#include "render.h"
#include "scene_input.h"

namespace pcsg::trace_bench {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Options {
    std::string scene;
    int width = 640, height = 480;
    int threads = 2;
    bool json = false;
    int passes = 5;
};

struct Figures {
    double compileSeconds = 0, buildSeconds = 0;
    double traceSeconds = 0;  // the median timed pass's
    std::vector<double> passSeconds;
    uint64_t buildRays = 0, rays = 0;  // the build render's, a timed pass's
    // Instances expanded in the build render, and again in the timed passes (their median).
    uint64_t buildExpansions = 0, traceExpansions = 0;
    uint64_t peakRssBytes = 0;
};

uint64_t peakRssBytes() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return uint64_t(u.ru_maxrss) * 1024;  // Linux: kilobytes
}

void print(const Options& o, const Figures& f) {
    const double raysPerSecond = f.traceSeconds > 0 ? f.rays / f.traceSeconds : 0;
    if (o.json) {
        const nlohmann::json j = {{"scene", o.scene},
                                  {"width", o.width},
                                  {"height", o.height},
                                  {"threads", o.threads},
                                  {"compile_seconds", f.compileSeconds},
                                  {"build_seconds", f.buildSeconds},
                                  {"build_rays", f.buildRays},
                                  {"build_expansions", f.buildExpansions},
                                  {"trace_seconds", f.traceSeconds},
                                  {"passes", o.passes},
                                  {"pass_seconds", f.passSeconds},
                                  {"trace_expansions", f.traceExpansions},
                                  {"rays", f.rays},
                                  {"rays_per_second", raysPerSecond},
                                  {"peak_rss_bytes", f.peakRssBytes}};
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::cout << fmt::format(
        "scene:           {}\nimage:           {}x{}, {} threads\n"
        "compile time:    {:.3f} s\nbuild time:      {:.3f} s ({} instances expanded)\n"
        "trace time:      {:.3f} s, the median of {} passes ({} instances expanded again each)\n"
        "rays:            {}\nrays/s:          {:.0f}\npeak RSS:        {:.1f} MB\n",
        o.scene, o.width, o.height, o.threads, f.compileSeconds, f.buildSeconds, f.buildExpansions,
        f.traceSeconds, o.passes, f.traceExpansions, f.rays, raysPerSecond, f.peakRssBytes / 1e6);
}

// The build render and the timed passes over the image's pixel centres.
void traceTimed(const Graph& g, const Options& o, Figures& f) {
    tracer::RenderOptions ro;
    ro.width = o.width, ro.height = o.height, ro.threads = o.threads;
    const tracer::Region image{0, 0, o.width, o.height};
    const tracer::RowSink discard = [](int, std::span<const float>) {};
    Clock::time_point start = Clock::now();
    tracer::RegionRenderer renderer(g, ro);
    renderer.render(image, discard);
    f.buildSeconds = secondsSince(start);
    tracer::RenderResult before = renderer.figures();
    f.buildRays = before.rays, f.buildExpansions = before.expansions;
    std::vector<double> expansions;
    for (int pass = 0; pass < o.passes; ++pass) {
        start = Clock::now();
        renderer.render(image, discard);
        f.passSeconds.push_back(secondsSince(start));
        const tracer::RenderResult after = renderer.figures();
        f.rays = after.rays - before.rays;
        expansions.push_back(double(after.expansions - before.expansions));
        before = after;
    }
    f.traceSeconds = tools::median(f.passSeconds);
    f.traceExpansions = static_cast<uint64_t>(tools::median(expansions));
}

int run(const Options& o) {
    tools::CompiledScene compiled = tools::compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    // (as `pcsg render` without --clock: clock 0, frame 1)
    if (!tools::setSceneTime(*compiled.graph, Time{}, std::cerr)) return 1;
    Figures f;
    f.compileSeconds = compiled.seconds;
    try {
        traceTimed(*compiled.graph, o, f);
    } catch (const std::exception& e) {
        std::cerr << "pcsg-trace: " << o.scene << ": " << e.what() << "\n";
        return 1;
    }
    f.peakRssBytes = peakRssBytes();
    print(o, f);
    return 0;
}

}  // namespace
}  // namespace pcsg::trace_bench

int main(int argc, char** argv) {
    pcsg::trace_bench::Options o;
    CLI::App app{
        "Trace a pcsg scene's pixel centres with pcsg's own tracer, once to build what it "
        "builds as rays ask, then --passes times, timed (the native side of `pcsg "
        "bench`'s trace rate against pcsg-embree): one camera ray per pixel centre and a "
        "shadow ray per hit and light."};
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
                   "Timed renders after the build; the trace time is the median one's")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_flag("--json", o.json, "Print the figures as JSON");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    return pcsg::trace_bench::run(o);
}
