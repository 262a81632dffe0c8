// Running pcsg-embree (tools/bench/embree_bench.cpp, built when Embree 3 is found), the
// yardstick of pcsg bench: Embree tracing the expanded triangle mesh of a scene.
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

// Embree on the scene's expanded mesh at that size and thread count (0: all cores): one
// camera ray per pixel centre and a shadow ray per hit and light. Nothing when the scene
// is not triangle-only (exit status 2) or Embree could not trace it (over maxNodes, say).
std::optional<EmbreeRun> runEmbree(const std::string& embree, const std::string& scene, int width,
                                   int height, int threads, uint64_t maxNodes);

}  // namespace pcsg::tools
