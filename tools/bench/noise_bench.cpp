// Microbenchmarks of POV-Ray's noise (tracer/noise.h) and the patterns and normals built on
// it, on the shading hot path: one call per iteration over 1024 fixed points. Part of
// pcsg_microbench (microbench.cpp has the main).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "noise.h"
#include "noise_patterns.h"
#include "normal_patterns.h"

namespace pcsg {
namespace {

const std::vector<Vec3>& points() {
    static const std::vector<Vec3> pts = [] {
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u(-20, 20);
        std::vector<Vec3> p(1024);
        for (Vec3& v : p) v = Vec3{u(rng), u(rng), u(rng)};
        return p;
    }();
    return pts;
}

template <class F>
void run(benchmark::State& state, F f) {
    const std::vector<Vec3>& p = points();
    size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(f(p[i]));
        i = (i + 1) & 1023;
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_Noise(benchmark::State& s) {
    run(s, [](const Vec3& p) { return noise(p); });
}
void BM_DNoise(benchmark::State& s) {
    run(s, [](const Vec3& p) { return dnoise(p); });
}
void BM_Turbulence6Octaves(benchmark::State& s) {
    const Turbulence t;
    run(s, [&t](const Vec3& p) { return turbulence(p, t); });
}
void BM_TurbulenceWarp6Octaves(benchmark::State& s) {
    Turbulence t;
    t.amount = {0.5, 0.5, 0.5};
    run(s, [&t](const Vec3& p) { return turbulenceWarp(t, p); });
}
void BM_GranitePattern(benchmark::State& s) {
    PatternSpec spec;
    spec.kind = PatternKind::Granite;
    run(s, [&spec](const Vec3& p) { return noisePatternValue(spec, p); });
}
void BM_BumpsNormal(benchmark::State& s) {
    NormalSpec spec;
    spec.kind = NormalKind::Bumps;
    run(s, [&spec](const Vec3& p) { return perturbNormal(spec, p, Vec3{0, 0, 1}); });
}
void BM_RipplesNormal(benchmark::State& s) {
    NormalSpec spec;
    spec.kind = NormalKind::Ripples;
    run(s, [&spec](const Vec3& p) { return perturbNormal(spec, p, Vec3{0, 0, 1}); });
}
BENCHMARK(BM_Noise);
BENCHMARK(BM_DNoise);
BENCHMARK(BM_Turbulence6Octaves);
BENCHMARK(BM_TurbulenceWarp6Octaves);
BENCHMARK(BM_GranitePattern);
BENCHMARK(BM_BumpsNormal);
BENCHMARK(BM_RipplesNormal);

}  // namespace
}  // namespace pcsg
