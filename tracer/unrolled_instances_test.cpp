// Expanded instances (unrolled_instances.h): a ray finds the same surface, bit for bit,
// through an expanded instance as through the walk of the graph; materials and ties
// depend on where an instance is used; the cache stays within its budget.
#include "unrolled_instances.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <thread>

#include "bounds.h"
#include "outward_float.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;
using testing::eagerExpansion;

const std::string kPlant = testing::branchingPlant(5);

// CSG around S-nodes: recursive operands of ∩ and \, a plane, triangles in unions.
const char* kCsg = R"(
material red { color <1,0,0> }
{k = 3} (A \ move(0.3,0,0) uscale(0.6) A) ∪ paint(red) B ∪ move(0,0,-2) plane
A if(k > 0, 2, 1)
1: A -> sphere ∩ uscale(0.9) cube
2: A -> {k = k-1} (move(0.5,0,0) uscale(0.6) A ∪ move(-0.5,0,0) uscale(0.6) A ∪ cone)
B if(k > 0, 2, 1)
1: B -> move(2,0,0) (tri1 ∪ tri2 ∪ triangle(0,0,1, 1,0,1, 0,1,1.5))
2: B -> {k = k-1} move(0,0,0.5) rotz(30) B ∪ move(2,1,0) uscale(0.3) sphere
)";

// Two surfaces at exactly the same distance everywhere: the same sphere twice, in
// different materials. The instance path decides, the same way both ways.
const char* kTies = R"(
material red { color <1,0,0> }
material blue { color <0,0,1> }
{n = 3} T
T if(n > 0, 2, 1)
1: T -> paint(red) sphere ∪ paint(blue) sphere
2: T -> {n = n-1} (move(1,0,0) uscale(0.5) T ∪ move(-1,0,0) uscale(0.5) T)
)";

// Unpainted primitives take the material of where the instance is used.
const char* kInherit = R"(
material red { color <1,0,0> }
material blue { color <0,0,1> }
{n = 2} (paint(red) move(-1.5,0,0) S ∪ paint(blue) move(1.5,0,0) S ∪ S)
S if(n > 0, 2, 1)
1: S -> sphere
2: S -> {n = n-1} (move(0.5,0,0) uscale(0.5) S ∪ move(-0.5,0,0) uscale(0.5) S)
)";

struct Rays {
    std::vector<Vec3> o, d;
};

Rays rays(int n, uint64_t seed, double spread) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    Rays r;
    for (int i = 0; i < n; ++i) {
        const Vec3 o{u(rng) * 5, -6 + u(rng), u(rng) * 5};
        const Vec3 target{u(rng) * spread, u(rng) * spread, u(rng) * spread + 0.5};
        r.o.push_back(o);
        r.d.push_back(normalize(target - o));
    }
    return r;
}

// Fires the rays twice (the second time through the expanded instances) and compares
// every hit with the walk of the graph, bit for bit. Returns the expansions made.
uint64_t compareWithGraphWalk(const char* text, const Rays& r, int minHits) {
    auto c = compile(text);
    EXPECT_TRUE(c->graph);
    if (!c->graph) return 0;
    const Graph& g = *c->graph;
    TraceScene plain(g, computeBounds(g), true, eagerExpansion());
    plain.expansionBytes = 0;
    TraceScene expanding(g, computeBounds(g), true, eagerExpansion());
    Tracer a(plain), b(expanding);
    int hits = 0;
    for (int round = 0; round < 2; ++round)
        for (size_t i = 0; i < r.o.size(); ++i) {
            SurfaceHit ha, hb;
            const bool fa = a.firstHit(r.o[i], r.d[i], 1e-4, 1e7, ha);
            const bool fb = b.firstHit(r.o[i], r.d[i], 1e-4, 1e7, hb);
            EXPECT_EQ(fa, fb) << "ray " << i;
            EXPECT_EQ(b.anyHit(r.o[i], r.d[i], 1e-4, 1e7), fa) << "ray " << i;
            if (!fa || !fb) continue;
            ++hits;
            EXPECT_EQ(ha.t, hb.t) << "ray " << i;
            EXPECT_EQ(ha.normal, hb.normal) << "ray " << i;
            EXPECT_EQ(ha.material, hb.material) << "ray " << i;
        }
    EXPECT_GT(hits, minHits);
    EXPECT_EQ(a.expansions(), 0u);
    return b.expansions();
}

uint64_t compareWithGraphWalk(const char* text, double spread, int minHits = 200) {
    return compareWithGraphWalk(text, rays(1500, 7, spread), minHits);
}

TEST(ExpandedInstances, PlantsHitTheSameSurfacesBitForBit) {
    EXPECT_GT(compareWithGraphWalk(kPlant.c_str(), 1.5), 0u);
}

TEST(ExpandedInstances, CsgAroundSNodesHitsTheSameSurfacesBitForBit) {
    EXPECT_GT(compareWithGraphWalk(kCsg, 2.0), 0u);
}

TEST(ExpandedInstances, TiesGoTheSameWayBothWays) {
    EXPECT_GT(compareWithGraphWalk(kTies, 1.5, 100), 0u);
}

TEST(ExpandedInstances, UnpaintedPrimitivesTakeTheMaterialOfTheirUse) {
    EXPECT_GT(compareWithGraphWalk(kInherit, 2.5), 0u);
}

TEST(ExpandedInstances, SierpinskiHitsTheSameSurfacesBitForBit) {
    EXPECT_GT(compareWithGraphWalk(testing::kSierpinski, 1.0), 0u);
}

// Rays with zero components in their direction (the BVH's box tests take the careful
// path): along y, and in the plane x = const.
TEST(ExpandedInstances, AxisParallelRaysHitTheSameSurfacesBitForBit) {
    Rays r;
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 40; ++j) {
            const double x = -1.2 + i * 0.06, z = -1.2 + j * 0.06;
            r.o.push_back({x, -6, z});
            r.d.push_back({0, 1, 0});
            r.o.push_back({x, -6, z});
            r.d.push_back(normalize(Vec3{0, 6, 0.3 - z * 0.5}));
        }
    EXPECT_GT(compareWithGraphWalk(testing::kSierpinski, r, 400), 0u);
}

TEST(ExpandedInstances, AChainOfUnionsGetsAHierarchyAndTheSameHits) {
    EXPECT_GT(compareWithGraphWalk(testing::kFlower, 0.6, 100), 0u);
    auto c = compile(testing::kFlower);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g), true, eagerExpansion());
    UnrollCache cache(scene, 1u << 20);
    UnrollCache::Reader reader(cache);
    const UnrollCache::Pin pin(&reader);
    std::vector<double> root(g.slotCount()), frame(g.slotCount());
    initFrame(g, root.data());
    applyCalc(g, g.axiom, EvalState{root.data(), kRootPath}, frame.data());
    const NodeId s = g.child(g.axiom);
    EXPECT_EQ(reader.get(s, 1, frame.data(), kRootPath), nullptr);  // the first meeting: a note
    const UnrolledInstance* x = reader.get(s, 1, frame.data(), kRootPath);
    ASSERT_NE(x, nullptr);
    // 22 primitives under one hierarchy: at least 22 / 4 leaves.
    EXPECT_GE(x->bvhNodes(), 6u);
    EXPECT_EQ(cache.expansions(), 1u);
}

// Three operands per level (27 and 81 leaves): four-wide nodes with empty slots, whose
// float boxes are rounded outwards, around spheres placed by parameters 1000 units from
// the instance's origin (a float's step there is 6e-5) and 1e-3 in radius.
const char* kThrees = R"(
{n = 4; x = 0; y = 0; s = 1} move(0, 0, -1000) T
T if(n > 0, 2, 1)
1: T -> move(x, y, 1000) (uscale(0.08) sphere ∪ move(0.1, 0, 0) uscale(1e-3) sphere)
2: T -> {n = n-1; s = s*0.5} ({x = x+s} T ∪ {x = x-s; y = y+s*0.4} T ∪ {y = y-s*0.8} T)
)";

TEST(ExpandedInstances, FourWideHierarchiesWithEmptySlotsHitTheSameSurfaces) {
    EXPECT_GT(compareWithGraphWalk(kThrees, 0.6, 20), 0u);
}

// Eighteen constant chains of matrices under one rule, each met at every level of the
// recursion (the unroller looks a constant T-node's inverse up once per expansion, in a
// table by node with fewer slots than there are nodes: each must keep its own matrix).
const char* kManyConstants = R"(
{n = 2} T
T if(n > 0, 2, 1)
1: T -> sphere ∪ move(0,0,0.6) uscale(0.5) cube
2: T -> {n = n-1} (move(-1.25,0,-0.6) uscale(0.12) rotz(0) T ∪
    move(-0.75,0,-0.6) uscale(0.124) rotz(5) T ∪
    move(-0.25,0,-0.6) uscale(0.128) rotz(10) T ∪
    move(0.25,0,-0.6) uscale(0.132) rotz(15) T ∪
    move(0.75,0,-0.6) uscale(0.136) rotz(20) T ∪
    move(1.25,0,-0.6) uscale(0.14) rotz(25) T ∪
    move(-1.25,0,0.0) uscale(0.144) rotz(30) T ∪
    move(-0.75,0,0.0) uscale(0.148) rotz(35) T ∪
    move(-0.25,0,0.0) uscale(0.152) rotz(40) T ∪
    move(0.25,0,0.0) uscale(0.156) rotz(45) T ∪
    move(0.75,0,0.0) uscale(0.16) rotz(50) T ∪
    move(1.25,0,0.0) uscale(0.164) rotz(55) T ∪
    move(-1.25,0,0.6) uscale(0.168) rotz(60) T ∪
    move(-0.75,0,0.6) uscale(0.172) rotz(65) T ∪
    move(-0.25,0,0.6) uscale(0.176) rotz(70) T ∪
    move(0.25,0,0.6) uscale(0.18) rotz(75) T ∪
    move(0.75,0,0.6) uscale(0.184) rotz(80) T ∪
    move(1.25,0,0.6) uscale(0.188) rotz(85) T)
)";

TEST(ExpandedInstances, ManyConstantMatricesEachKeepTheirOwn) {
    EXPECT_GT(compareWithGraphWalk(kManyConstants, 1.5, 200), 0u);
}

TEST(ExpandedInstances, BoxesRoundOutwardsToFloats) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> mantissa(1, 2);
    std::uniform_int_distribution<int> exponent(-160, 160);
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> xs = {0.0,          -0.0,   1.0,     0.1,   -0.1,   1e-45, 1e-50, -1e-50,
                              3.4028234e38, 3.5e38, -3.5e38, 1e300, -1e300, inf,   -inf};
    for (int i = 0; i < 2000; ++i)
        xs.push_back((i % 2 ? -1 : 1) * std::ldexp(mantissa(rng), exponent(rng)));
    for (double x : xs) {
        const float lo = floatBelow(x), hi = floatAbove(x);
        EXPECT_LE(static_cast<double>(lo), x) << x;
        EXPECT_GE(static_cast<double>(hi), x) << x;
        // the nearest such floats: one step further is on the other side of x
        if (std::isfinite(x) && std::isfinite(lo)) {
            EXPECT_GT(static_cast<double>(std::nextafter(lo, INFINITY)), x) << x;
        }
        if (std::isfinite(x) && std::isfinite(hi)) {
            EXPECT_LT(static_cast<double>(std::nextafter(hi, -INFINITY)), x) << x;
        }
    }
    // the step down is libm's nextafter, bit for bit (zeros and subnormals included)
    const float kMax = std::numeric_limits<float>::max();
    for (double x : xs) {
        const float f = static_cast<float>(x);
        if (!std::isfinite(f) || f <= -kMax) continue;
        EXPECT_EQ(std::bit_cast<uint32_t>(floatStepDown(f)),
                  std::bit_cast<uint32_t>(std::nextafter(f, -kMax)))
            << f;
    }
    EXPECT_TRUE(std::isnan(floatBelow(std::nan(""))));
    EXPECT_TRUE(std::isnan(floatAbove(std::nan(""))));
}

// The doubles where rounding outwards to floats can go wrong: every float of a stride
// through all bit patterns, the powers of two and the edges (zeros, subnormals, FLT_MIN,
// FLT_MAX, infinities, NaNs), each as a double, one double step either side of it, the
// midpoint to the next float (a tie) and one step either side of that; and doubles far
// beyond floats (subnormal and huge).
std::vector<double> roundingEdgeCases() {
    const float fmax = std::numeric_limits<float>::max();
    std::vector<float> fs = {0.0f,
                             -0.0f,
                             std::numeric_limits<float>::denorm_min(),
                             std::numeric_limits<float>::min(),
                             fmax,
                             1.0f,
                             0.1f};
    for (uint64_t bits = 0; bits < (1ull << 32); bits += 16411)
        fs.push_back(std::bit_cast<float>(static_cast<uint32_t>(bits)));
    for (int e = -150; e <= 128; ++e) fs.push_back(std::ldexp(1.0f, e));
    const size_t n = fs.size();
    for (size_t i = 0; i < n; ++i) fs.push_back(-fs[i]);
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> xs = {inf,
                              -inf,
                              std::nan(""),
                              -std::nan(""),
                              std::numeric_limits<double>::max(),
                              -1e300,
                              std::numeric_limits<double>::denorm_min(),
                              -1e-310,
                              1e-50};
    for (float f : fs) {
        const double d = f;
        const double next = std::isfinite(f) ? std::nextafter(f, INFINITY) : d;
        const double tie = std::isfinite(next) ? (d + next) / 2 : d + std::ldexp(1.0, 103);
        for (double x : {d, tie})
            xs.insert(xs.end(), {x, std::nextafter(x, -inf), std::nextafter(x, inf)});
    }
    return xs;
}

TEST(ExpandedInstances, FourBoundsRoundLikeOne) {
    const std::vector<double> xs = roundingEdgeCases();
    ASSERT_GT(xs.size(), 1'500'000u);
    size_t mismatches = 0;
    for (size_t shift = 0; shift < 4; ++shift) {  // (each value in each of the four lanes)
        for (size_t i = shift; i + 4 <= xs.size(); i += 4) {
            float below[4], above[4];
            floatsBelow(&xs[i], below);
            floatsAbove(&xs[i], above);
            for (int k = 0; k < 4; ++k) {
                const bool same = std::bit_cast<uint32_t>(below[k]) ==
                                      std::bit_cast<uint32_t>(floatBelow(xs[i + k])) &&
                                  std::bit_cast<uint32_t>(above[k]) ==
                                      std::bit_cast<uint32_t>(floatAbove(xs[i + k]));
                if (!same && ++mismatches < 10) ADD_FAILURE() << "x = " << xs[i + k];
            }
        }
    }
    EXPECT_EQ(mismatches, 0u);
    // and the one-at-a-time rounding is the outward one at the edges
    const float fmax = std::numeric_limits<float>::max();
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(floatBelow(inf), fmax);
    EXPECT_EQ(floatAbove(-inf), -fmax);
    EXPECT_EQ(floatBelow(-1e300), -inf);
    EXPECT_EQ(floatAbove(1e-310), std::numeric_limits<float>::denorm_min());
    EXPECT_EQ(std::bit_cast<uint32_t>(floatBelow(-1e-310)), 0x80000001u);
    EXPECT_EQ(std::bit_cast<uint32_t>(floatBelow(-0.0)), 0x80000000u);
    EXPECT_EQ(std::bit_cast<uint32_t>(floatAbove(0.0)), 0u);
}

TEST(ExpandedInstances, TheCacheStaysWithinItsBudget) {
    auto c = compile(kPlant);
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    scene.expansionBytes = 8 * 1024;
    Tracer t(scene);
    const Rays r = rays(2000, 11, 1.5);
    for (int round = 0; round < 2; ++round)
        for (size_t i = 0; i < r.o.size(); ++i) {
            SurfaceHit h;
            t.firstHit(r.o[i], r.d[i], 1e-4, 1e7, h);
        }
    EXPECT_GT(t.expansions(), 0u);
    EXPECT_GT(t.expansionCacheBytes(), 0u);
    // What stays in a tracer's cache fits its budget, unless it is the one entry in use.
    EXPECT_TRUE(t.expansionCacheBytes() <= scene.expansionBytes || t.expansionCacheEntries() == 1)
        << t.expansionCacheBytes() << " bytes in " << t.expansionCacheEntries() << " entries";
}

TEST(ExpandedInstances, MaxDepthIsStillReportedBelowAnExpandableDepth) {
    // The instances at depth 1 are small, but the chain goes on beyond max_depth 6: the
    // walk must still meet (and report) the error, expanded or not.
    auto c = compile(R"(
settings { max_depth 6 }
{n = 9} S
S if(n > 0, 2, 1)
1: S -> sphere
2: S -> {n = n-1} (uscale(0.9) S ∪ move(0,0,2) cube)
)");
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph), true, eagerExpansion());
    Tracer t(scene);
    const Rays r = rays(50, 5, 0.5);
    bool thrown = false;
    for (int round = 0; round < 2 && !thrown; ++round)
        for (size_t i = 0; i < r.o.size() && !thrown; ++i) {
            SurfaceHit h;
            try {
                t.firstHit(r.o[i], r.d[i], 1e-4, 1e7, h);
            } catch (const RuntimeError& e) {
                thrown = true;
                EXPECT_NE(e.message.find("max_depth"), std::string::npos) << e.message;
            }
        }
    EXPECT_TRUE(thrown);
}

// A thread builds its expansions in arrays it keeps from one to the next (BuildArrays):
// each expansion still gets arrays of its own, at their final sizes, holding only what it
// holds: the same bytes and hits as the first expansion of a fresh thread, after a larger
// one, and after one given up half-built (too many visits).
TEST(ExpandedInstances, AnExpansionsArraysAreItsOwnWhateverTheThreadBuiltBefore) {
    auto c = compile(testing::kFlower);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g), true, eagerExpansion());
    auto [select, frame] = testing::axiomInstance(g);
    const auto petals = std::find(frame.begin(), frame.end(), 21.0);
    ASSERT_NE(petals, frame.end());
    auto expand = [&](double p, uint64_t maxVisits = 1u << 20) {
        *petals = p;
        return UnrolledInstance::expand(scene, select, 1, frame.data(), kRootPath, maxVisits);
    };
    auto hitOf = [](const UnrolledInstance& x) {
        UnrolledInstance::Scratch s;
        Hit h;
        double tmax = 1e9;
        x.first(LocalRay{{0.1, -5, 0.05}, Vec3{0, 1, 0}}, 1e-6, tmax, h, {kRootPath, 0, 0}, false,
                s);
        return std::make_pair(h.t, tmax);
    };
    std::unique_ptr<UnrolledInstance> fresh;
    std::thread([&] { fresh = expand(5); }).join();
    ASSERT_TRUE(fresh);
    const auto large = expand(21);
    ASSERT_TRUE(large);
    ASSERT_GT(large->bytes(), fresh->bytes());
    const auto after = expand(5);
    ASSERT_TRUE(after);
    EXPECT_EQ(after->bytes(), fresh->bytes());
    EXPECT_EQ(after->bvhNodes(), fresh->bvhNodes());
    EXPECT_EQ(hitOf(*after), hitOf(*fresh));
    EXPECT_FALSE(expand(21, 10));  // given up half-built
    const auto again = expand(5);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->bytes(), fresh->bytes());
    EXPECT_EQ(hitOf(*again), hitOf(*fresh));
}

// A binary tree of 2^n spheres: its expansions' arrays grow with n.
const char* kSphereTree = R"(
{n = 11} T
T if(n > 0, 2, 1)
1: T -> sphere
2: T -> {n = n-1} (move(1,0,0) uscale(0.5) T ∪ move(-1,0,0) uscale(0.5) T)
)";

// A thread keeps its build arrays from one expansion to the next, but not at the size of
// a far larger one-off (a larger level tried once, a build refused at its visit limit):
// after the large expansion, the next small one leaves the thread with small arrays.
TEST(ExpandedInstances, AThreadDoesNotKeepTheArraysOfAFarLargerExpansion) {
    auto c = compile(kSphereTree);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g), true, eagerExpansion());
    auto [select, frame] = testing::axiomInstance(g);
    const auto n = std::find(frame.begin(), frame.end(), 11.0);
    ASSERT_NE(n, frame.end());
    auto expand = [&](double levels) {
        *n = levels;
        return UnrolledInstance::expand(scene, select, 1, frame.data(), kRootPath, 1u << 20);
    };
    std::thread([&] {
        const auto large = expand(11);
        ASSERT_TRUE(large);
        const size_t keptAfterLarge = UnrolledInstance::keptBuildBytes();
        EXPECT_GE(keptAfterLarge, large->bytes() / 2);  // (the largest so far: kept)
        const auto small = expand(3);
        ASSERT_TRUE(small);
        EXPECT_LT(UnrolledInstance::keptBuildBytes(), keptAfterLarge / 4);
        const auto again = expand(3);
        ASSERT_TRUE(again);
        EXPECT_EQ(again->bytes(), small->bytes());
        EXPECT_LT(UnrolledInstance::keptBuildBytes(), keptAfterLarge / 4);
    }).join();
}

// Sixteen spheres in a row, x = a + 4b: the derivation puts a's four (b = 0..3) in one
// union, four nested unions deep (balanced), or, as a chain of unions, one after the
// other (x = 5k mod 16 for the k-th), so that spatial neighbours are never siblings.
const char* kNestedRow = R"(
{n = 2; x = 0; s = 1} T
T if(n > 0, 2, 1)
1: T -> move(x, 0, 0) uscale(0.1) sphere
2: T -> {n = n-1; s = s*4} ({x = x} T ∪ {x = x + s/4} T ∪ {x = x + s/2} T ∪ {x = x + 3*s/4} T)
)";
const char* kChainRow = R"(
{k = 0} C
C if(k < 15, 2, 1)
1: C -> move(mod(k*5, 16), 0, 0) uscale(0.1) sphere
2: C -> move(mod(k*5, 16), 0, 0) uscale(0.1) sphere ∪ {k = k+1} C
)";

// The expansion of the axiom's S-node instance of `text` (at depth 1), or nullptr.
std::unique_ptr<UnrolledInstance> expandAxiom(const char* text) {
    auto c = compile(text);
    EXPECT_TRUE(c->graph);
    if (!c->graph) return nullptr;
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g), true, eagerExpansion());
    auto [select, frame] = testing::axiomInstance(g);
    auto x = UnrolledInstance::expand(scene, select, 1, frame.data(), kRootPath, 1u << 20);
    EXPECT_TRUE(x);
    return x;
}

// The widest spread of instance node indices among the operands of one hierarchy node
// (siblings in the derivation are built one after the other: a spread of 3 for four).
uint32_t widestGroup(const char* text) {
    const auto x = expandAxiom(text);
    if (!x) return 0;
    uint32_t widest = 0, leaves = 0;
    for (const std::vector<uint32_t>& group : x->bvhLeafGroups()) {
        leaves += static_cast<uint32_t>(group.size());
        if (group.empty()) continue;
        const auto [lo, hi] = std::minmax_element(group.begin(), group.end());
        widest = std::max(widest, *hi - *lo);
    }
    EXPECT_EQ(leaves, 16u);
    return widest;
}

// A balanced derivation is the hierarchy itself (no sorting: siblings stay together even
// where they lie far apart); a chain gets median splits (spatial neighbours together).
TEST(ExpandedInstances, ABalancedDerivationIsTheHierarchyAndAChainIsSplit) {
    EXPECT_EQ(widestGroup(kNestedRow), 3u);
    EXPECT_GT(widestGroup(kChainRow), 3u);
    Rays r;
    for (int i = 0; i < 64; ++i) {
        r.o.push_back({i * 0.25 + 0.02, -6, 0.03});
        r.d.push_back(normalize(Vec3{0.01 * (i % 3), 1, 0.002 * (i % 5)}));
    }
    EXPECT_GT(compareWithGraphWalk(kNestedRow, r, 15), 0u);
}

// A binary tree five levels deep whose every branch is entered through four matrices
// (parametric T-nodes: not fused), 20 in all from the root to a leaf, as a tree's crown.
const char* kDeepChains = R"(
{n = 5; s = 1; a = 50} T
T if(n > 0, 2, 1)
1: T -> uscale(0.6) sphere
2: T -> {n = n-1; s = s*0.8; a = a*0.8}
        (move(s, 0, 0.5) rotz(a) rotx(a*0.5) uscale(0.75) T ∪ move(-s, 0, 0.5) rotz(-a) roty(a*0.3) uscale(0.75) T)
)";

// Unions nested below chains of up to 20 matrices are one hierarchy over all 32 spheres
// (a limit of 12 matrices cut it: 16 spheres in hierarchies, the others in unions of
// their own), and hit the same surfaces as the walk.
TEST(ExpandedInstances, UnionsBelowLongChainsOfMatricesAreOneHierarchy) {
    const auto x = expandAxiom(kDeepChains);
    ASSERT_TRUE(x);
    size_t leaves = 0;
    for (const std::vector<uint32_t>& group : x->bvhLeafGroups()) leaves += group.size();
    EXPECT_EQ(leaves, 32u);
    EXPECT_GT(compareWithGraphWalk(kDeepChains, 1.5, 100), 0u);
}

// A chain of unions 14 levels deep, each level four small spheres and, first, the next
// level entered through four matrices (parametric: not fused): 56 matrices from the root
// to the deepest, so the root's hierarchy takes levels 0 to 8 (32 matrices: 36 spheres
// and the union of level 9 as one operand) and the union of level 9 gets a hierarchy of
// its own (levels 9 to 13: 20 spheres and the last level's one), built while the root's
// operands are still being gone through (the unroller keeps them all on one stack).
const char* kLongChain = R"(
{n = 14; a = 20} T
T if(n > 0, 2, 1)
1: T -> uscale(0.3) sphere
2: T -> {n = n-1; a = a*0.9}
        (move(0.3, 0, 0.4) rotz(a) rotx(a*0.5) uscale(0.9) T ∪ move(0.5, 0, 0) uscale(0.2) sphere
         ∪ move(0, 0.5, 0) uscale(0.2) sphere ∪ move(-0.5, 0, 0) uscale(0.2) sphere
         ∪ move(0, -0.5, 0) uscale(0.2) sphere)
)";

TEST(ExpandedInstances, AUnionBeyondTheChainLimitGetsAHierarchyOfItsOwn) {
    const auto x = expandAxiom(kLongChain);
    ASSERT_TRUE(x);
    size_t all = 0;
    for (const std::vector<uint32_t>& group : x->bvhLeafGroups()) all += group.size();
    EXPECT_EQ(all, 37u + 21u);
    EXPECT_GT(compareWithGraphWalk(kLongChain, 1.5, 100), 0u);
}

// Operands of a hierarchy whose box there is a box of their box through rotations test
// their own box before they are entered (the spheres below kDeepChains' rotations);
// below moves and scales (Sierpinski) the two are the same box, and none does.
TEST(ExpandedInstances, OperandsBelowRotationsTestTheirOwnBoxes) {
    const auto rotated = expandAxiom(kDeepChains);
    ASSERT_TRUE(rotated);
    EXPECT_EQ(rotated->looseOperands(), 32u);
    const auto straight = expandAxiom(testing::kSierpinski);
    ASSERT_TRUE(straight);
    EXPECT_GT(straight->bvhNodes(), 0u);
    EXPECT_EQ(straight->looseOperands(), 0u);
}

// A terrain patch in small (scenes/terrain.pcsg's shape without its random numbers): four
// operands a level, each through a constant scale and move, and per triangle the two
// parameter T-nodes move(0,0,z1) zshear(...) whose inverses the expansion stores once each.
const char* kPatch = R"(
{n = 3; z1 = 0; z2 = 0.5; z3 = 0.25; k = 1} T
T if(n > 0, 2, 1)
1: T -> move(0,0,z1) zshear(z2-z1,z3-z1) tri1
2: T -> {n = n-1; k = k/2} (
        {z2 = (z1+z2)/2; z3 = (z1+z3)/2 + k/8} scale(0.5,0.5,1) T ∪
        {z1 = (z1+z2)/2 - k/16; z3 = (z2+z3)/2} move(0.5,0,0) scale(0.5,0.5,1) T ∪
        {z1 = (z1+z3)/2; z2 = (z2+z3)/2 + k/4} move(0,0.5,0) scale(0.5,0.5,1) T ∪
        {z1 = (z2+z3)/2; z2 = z3 - k/8; z3 = z2 + k/16} move(0.5,0.5,0) rotz(180) scale(0.5,0.5,1) T)
)";

// What an expansion builds, its arrays bit for bit, as the unroller of main at 7577474
// built them (the hashes below are of its expansions): a change that makes a build cheaper
// must leave them all the same (nodes and boxes, matrices stored once in the same order,
// their references, the hierarchy's float boxes and links).
TEST(ExpandedInstances, ExpansionsHoldWhatTheUnrollerBuiltBefore) {
    struct Held {
        const char* text;
        uint64_t digest;
    };
    for (const Held& h :
         {Held{kPatch, 6458956179079065779u}, Held{kDeepChains, 12547906493058260917u},
          Held{testing::kSierpinski, 2105740141657389315u}}) {
        const auto x = expandAxiom(h.text);
        ASSERT_TRUE(x);
        EXPECT_EQ(x->digest(), h.digest) << h.text;
    }
    EXPECT_EQ(expandAxiom(kPatch)->bvhNodes(), 64u + 21u);
    EXPECT_GT(compareWithGraphWalk(kPatch, 1.0, 100), 0u);
}

}  // namespace
}  // namespace pcsg::tracer
