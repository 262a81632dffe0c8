// pcsg_microbench: Google Benchmark microbenchmarks of the tracer's hot paths, so that a
// change to one of them can be measured on its own (docs/benchmarks.md). Compare
// figures from one run on one machine, never across machines.
//
//   build/tools/bench/pcsg_microbench [--benchmark_filter=REGEX]
//
//  - primitive intersection (each solid, the triangle);
//  - span-list combination (∪ ∩ \ of two lists);
//  - one selection and C-node step of the one semantics (Sierpinski, terrain);
//  - POV-Ray's noise, turbulence, a noise pattern and two normals (noise_bench.cpp);
//  - a whole first-hit walk of a camera ray through the cyclic graph (Sierpinski order 8,
//    with the static boxes alone and with the exact instance boxes).
#include <benchmark/benchmark.h>

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bounds.h"
#include "camera.h"
#include "compiler.h"
#include "eval.h"
#include "primitives.h"
#include "span_list.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

struct RayBatch {
    std::vector<Vec3> origins, dirs;
};

// Rays from a shell around the unit cube aimed at points inside it: most of them hit.
RayBatch rays(size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    RayBatch b;
    for (size_t i = 0; i < n; ++i) {
        Vec3 o{u(rng), u(rng), u(rng)};
        o = normalize(o) * 4.0;
        const Vec3 target{u(rng) * 0.8, u(rng) * 0.8, u(rng) * 0.8};
        b.origins.push_back(o);
        b.dirs.push_back(normalize(target - o));
    }
    return b;
}

Graph compileOrThrow(const std::string& text) {
    Diagnostics d;
    auto g = compileSource("bench.pcsg", text, d);
    if (!g) throw std::runtime_error("benchmark scene does not compile:\n" + d.format());
    return std::move(*g);
}

void intersectSolidBench(benchmark::State& state, PrimitiveKind kind) {
    const RayBatch b = rays(1024, 1);
    const double torus[2] = {0.7, 0.25};
    Span out[kMaxPrimitiveSpans];
    size_t i = 0;
    for (auto _ : state) {
        const int n = intersectSolid(kind, torus, b.origins[i], b.dirs[i], out);
        benchmark::DoNotOptimize(n);
        benchmark::DoNotOptimize(out);
        i = (i + 1) & 1023;
    }
    state.SetItemsProcessed(state.iterations());
}

BENCHMARK_CAPTURE(intersectSolidBench, sphere, PrimitiveKind::Sphere);
BENCHMARK_CAPTURE(intersectSolidBench, cube, PrimitiveKind::Cube);
BENCHMARK_CAPTURE(intersectSolidBench, cylinder, PrimitiveKind::Cylinder);
BENCHMARK_CAPTURE(intersectSolidBench, cone, PrimitiveKind::Cone);
BENCHMARK_CAPTURE(intersectSolidBench, tetrahedron, PrimitiveKind::Tetrahedron);
BENCHMARK_CAPTURE(intersectSolidBench, torus, PrimitiveKind::Torus);

void BM_IntersectTriangle(benchmark::State& state) {
    const RayBatch b = rays(1024, 2);
    const Vec3 a{0, 0, 0}, c1{1, 0, 0}, c2{0, 1, 0.3};
    Boundary hit;
    size_t i = 0;
    for (auto _ : state) {
        const bool h = intersectTriangle(a, c1, c2, b.origins[i], b.dirs[i], 1e-4, 1e7, hit);
        benchmark::DoNotOptimize(h);
        benchmark::DoNotOptimize(hit);
        i = (i + 1) & 1023;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_IntersectTriangle);

// Two sorted lists of `n` disjoint spans each, interleaved so that every merge step has
// work to do.
std::vector<Span> spanList(size_t n, double offset) {
    std::vector<Span> s(n);
    for (size_t i = 0; i < n; ++i) {
        s[i].in = Boundary{static_cast<double>(i) * 2 + offset, {-1, 0, 0}, 1};
        s[i].out = Boundary{static_cast<double>(i) * 2 + offset + 1.2, {1, 0, 0}, 1};
    }
    return s;
}

template <size_t (*Combine)(const Span*, size_t, const Span*, size_t, Span*)>
void spanBench(benchmark::State& state) {
    const size_t n = static_cast<size_t>(state.range(0));
    const std::vector<Span> a = spanList(n, 0), b = spanList(n, 0.5);
    std::vector<Span> out(2 * n);
    for (auto _ : state) {
        const size_t m = Combine(a.data(), n, b.data(), n, out.data());
        benchmark::DoNotOptimize(m);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(2 * n));
}
BENCHMARK(spanBench<uniteSpans>)->Name("BM_UniteSpans")->Arg(2)->Arg(16);
BENCHMARK(spanBench<intersectSpans>)->Name("BM_IntersectSpans")->Arg(2)->Arg(16);
BENCHMARK(spanBench<subtractSpans>)->Name("BM_SubtractSpans")->Arg(2)->Arg(16);

const char* kSierpinski8 = R"(
camera { location <2.6, -5.2, 2.6>  look_at <0, 0, -0.15>  sky <0, 0, 1>  angle 38 }
{c = 8} S
S if(c > 0, 2, 1)
1: S -> tetrahedron
2: S -> {c = c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪ move(-0.5,-0.5,0.5) uscale(0.5) S ∪
                    move(0.5,-0.5,-0.5) uscale(0.5) S ∪ move(-0.5,0.5,-0.5) uscale(0.5) S )
)";

// The paper's figure 8 C-node calcT1_1, with its parameters initialised as printed.
const char* kTerrainStep = R"(
{ cnt = 10; frc = 0.47; delta = 1.0; add = 0.6; ex = exp(1.0)-1.0; kl = 1.0;
  a = 255; b = pow(255,2); c = pow(255,3); d = pow(255,4);
  x1 = 1; y1 = 1; z1 = 0; x2 = 0; y2 = 1; z2 = 0; x3 = 1; y3 = 0; z3 = 0 } T
T if(cnt > 0, 2, 1)
1: T -> tri1
2: T -> { cnt = cnt-1; delta = delta*frc; kl = kl/2.0; sd = a*x2 + b*x1 + c*y2 + d*y1;
          rnd = ((-ln(rand(sd)*ex+1.0))+add)*delta; z2 = (z1+z2)/2.0 + rnd;
          sd = a*x3 + b*x1 + c*y3 + d*y1; rnd = ((-ln(rand(sd)*ex+1.0))+add)*delta;
          z3 = (z1+z3)/2.0 + rnd; x2 = x1-kl; y3 = y1-kl } scale(0.5,0.5,1) T
)";

// One selection and the C-node under the chosen rule, from the axiom's frame.
void selectAndCalcBench(benchmark::State& state, const char* text) {
    const Graph g = compileOrThrow(text);
    std::vector<double> root(g.slotCount()), frame(g.slotCount()), next(g.slotCount());
    initFrame(g, root.data());
    applyCalc(g, g.axiom, EvalState{root.data(), kRootPath}, frame.data());
    const NodeId s = g.child(g.axiom);
    for (auto _ : state) {
        const EvalState st{frame.data(), kRootPath};
        const uint32_t rule = selectRule(g, s, st);
        NodeId n = g.child(s, rule);
        while (g.nodes[n].kind != NodeKind::Calc) n = g.child(n);  // through the union
        applyCalc(g, n, st, next.data());
        benchmark::DoNotOptimize(next.data());
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(selectAndCalcBench, sierpinski, kSierpinski8);
BENCHMARK_CAPTURE(selectAndCalcBench, terrain_calcT1_1, kTerrainStep);

// First hits of the camera rays of a 64 x 48 image, one ray per iteration.
void firstHitBench(benchmark::State& state, bool instanceBoxes) {
    const Graph g = compileOrThrow(kSierpinski8);
    TraceScene scene(g, computeBounds(g), instanceBoxes);
    Tracer tracer(scene);
    const PinholeCamera camera(g.scene.camera, 64, 48);
    std::vector<Ray> camRays;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) camRays.push_back(camera.ray(x + 0.5, y + 0.5));
    size_t i = 0;
    SurfaceHit hit;
    for (auto _ : state) {
        const Ray& r = camRays[i];
        benchmark::DoNotOptimize(tracer.firstHit(r.origin, r.dir, 1e-4, 1e7, hit));
        i = (i + 1) % camRays.size();
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["visits/ray"] = benchmark::Counter(static_cast<double>(tracer.nodeVisits()) /
                                                      static_cast<double>(state.iterations()));
}
BENCHMARK_CAPTURE(firstHitBench, sierpinski8_static_boxes, false);
BENCHMARK_CAPTURE(firstHitBench, sierpinski8_instance_boxes, true);

}  // namespace
}  // namespace pcsg::tracer

BENCHMARK_MAIN();
