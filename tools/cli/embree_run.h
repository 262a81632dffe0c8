// Running pcsg-embree (tools/bench/embree_bench.cpp, built when Embree 3 is found), the
// yardstick of pcsg bench: Embree tracing the expanded triangle mesh of a scene; and its
// native twin pcsg-trace (tools/bench/trace_bench.cpp), the same rays through pcsg's own
// tracer after its own build, for the trace rates compared like with like.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace pcsg::tools {

// What pcsg-embree measured on a triangle-only scene: its own build and trace times and
// rays per second, and the whole command's wall time and peak RSS (wait4).
struct EmbreeRun {
    uint64_t triangles = 0;
    double buildSeconds = 0, traceSeconds = 0, raysPerSecond = 0;
    double seconds = 0;  // the whole command: compiling, expanding, building and tracing
    uint64_t peakRss = 0;
};

// pcsg-embree beside this executable, or nothing (then bench has no Embree figures).
std::optional<std::string> findEmbree();
// pcsg-trace beside this executable, or nothing.
std::optional<std::string> findNativeTrace();

// Embree on the scene's expanded mesh at that size and thread count (0: all cores): one
// camera ray per pixel centre and a shadow ray per hit and light. Nothing when the scene
// is not triangle-only (exit status 2) or Embree could not trace it (over maxNodes, say).
std::optional<EmbreeRun> runEmbree(const std::string& embree, const std::string& scene, int width,
                                   int height, int threads, uint64_t maxNodes);

// What pcsg-trace measured: the rays pcsg-embree traces (pixel centres, shadow rays toward
// the lights), rendered once to build what pcsg builds as rays ask for it, then timed on
// further renders with what the first left, the median one's (whatever the caches' budgets
// evicted is built again, and counted in the trace time).
struct NativeTraceRun {
    double buildSeconds = 0, traceSeconds = 0, raysPerSecond = 0;
    uint64_t rays = 0;
    uint64_t traceExpansions = 0;  // instances expanded again in a timed render
};

// pcsg-trace on the scene at that size and thread count (0: all cores); nothing when it
// failed.
std::optional<NativeTraceRun> runNativeTrace(const std::string& trace, const std::string& scene,
                                             int width, int height, int threads);

}  // namespace pcsg::tools
