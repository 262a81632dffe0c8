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

#include <iostream>
#include <string>
#include <vector>

#include "render.h"
#include "scene_input.h"
#include "yardstick.h"

namespace pcsg::trace_bench {
namespace {

using yardstick::Clock;
using yardstick::secondsSince;

struct Figures {
    double compileSeconds = 0, buildSeconds = 0;
    uint64_t buildRays = 0;
    yardstick::Passes passes;
    // Instances expanded in the build render, and again in a timed pass (their median).
    uint64_t buildExpansions = 0, traceExpansions = 0;
    size_t expansionBudgetBytes = 0;  // the budget the expansion cache reached
    uint64_t peakRssBytes = 0;
};

struct Options : yardstick::TraceOptions {
    size_t expansionCacheMb = 16;  // pcsg render's --expansion-cache-mb
    size_t expansionStartMb = 2;   // where its budget starts, as pcsg render's
};

void print(const Options& o, const Figures& f) {
    if (o.json) {
        nlohmann::json j = yardstick::traceJson(o, f.passes, f.peakRssBytes);
        j["compile_seconds"] = f.compileSeconds;
        j["build_seconds"] = f.buildSeconds;
        j["build_rays"] = f.buildRays;
        j["build_expansions"] = f.buildExpansions;
        j["trace_expansions"] = f.traceExpansions;
        j["expansion_cache_mb"] = o.expansionCacheMb;
        j["expansion_start_mb"] = o.expansionStartMb;
        j["expansion_budget_bytes"] = f.expansionBudgetBytes;
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::cout << fmt::format(
        "scene:           {}\nimage:           {}x{}, {} threads\n"
        "compile time:    {:.3f} s\nbuild time:      {:.3f} s ({} instances expanded)\n"
        "trace time:      {:.3f} s, the median of {} passes ({} instances expanded again "
        "each)\nrays:            {}\nrays/s:          {:.0f}\nexpansion cache: {:.1f} MB "
        "budget reached\npeak RSS:        {:.1f} MB\n",
        o.scene, o.width, o.height, o.threads, f.compileSeconds, f.buildSeconds, f.buildExpansions,
        f.passes.median(), o.passes, f.traceExpansions, f.passes.rays, f.passes.raysPerSecond(),
        f.expansionBudgetBytes / 1e6, f.peakRssBytes / 1e6);
}

// The build render and the timed passes over the image's pixel centres.
void traceTimed(const Graph& g, const Options& o, Figures& f) {
    tracer::RenderOptions ro;
    ro.width = o.width, ro.height = o.height, ro.threads = o.threads;
    ro.expansionBytes = o.expansionCacheMb << 20;
    ro.expansionStartBytes = o.expansionStartMb << 20;
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
        f.passes.seconds.push_back(secondsSince(start));
        const tracer::RenderResult after = renderer.figures();
        f.passes.rays = after.rays - before.rays;
        expansions.push_back(double(after.expansions - before.expansions));
        before = after;
    }
    f.traceExpansions = static_cast<uint64_t>(tools::median(expansions));
    f.expansionBudgetBytes = before.expansionBudget;
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
    f.peakRssBytes = yardstick::peakRssBytes();
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
    pcsg::yardstick::addTraceOptions(app, o);
    app.add_option("--expansion-cache-mb", o.expansionCacheMb,
                   "Memory limit in MB of the cache of expanded sub-graph instances, as for pcsg "
                   "render (0: none)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    app.add_option("--expansion-start-mb", o.expansionStartMb,
                   "Where that cache's budget starts, in MB (at most --expansion-cache-mb), as for "
                   "pcsg render; it grows toward the limit where a larger one saves expansions. At "
                   "the limit, every expansion that fits is kept from the first ray: with a large "
                   "limit, the rate of pcsg's expanded representation held whole")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    if (const int status = pcsg::yardstick::parse(app, argc, argv); status >= 0) return status;
    return pcsg::trace_bench::run(o);
}
