// Soundness of the hyper-bounding boxes: expand each system and check that every
// primitive instance lies inside the box of every node on its path (in that node's
// frame), and inside the per-depth box of every S-node on its path. Also: the boxes are
// tight where they can be (the Sierpinski tetrahedron), and the analysis gives up
// (infinite boxes) rather than guess.
#include "bounds.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "interval.h"
#include "primitives.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

using testing::compile;
using testing::Expander;

// The primitive's own box (the analysis bounds boxes of primitives, not their shapes).
Box instanceBox(const testing::Instance& inst) {
    return primitiveBox(inst.kind, inst.args.empty() ? nullptr : inst.args.data());
}

bool boxContainsWithTolerance(const Box& outer, const Vec3& p) {
    for (int i = 0; i < 3; ++i) {
        const double tol = 1e-9 * std::max({1.0, std::fabs(p[i])});
        if (!(p[i] >= outer.lo[i] - tol && p[i] <= outer.hi[i] + tol)) return false;
    }
    return true;
}

// Checks every instance against every node on its path; returns the number of checks.
// Below the last clipping node on the path (an intersection, or a difference entered
// through an operand it subtracts) the whole primitive must lie in each node's box;
// from there up, only what the clipping node keeps counts, so its box (mapped by the
// path's matrices) must lie in the boxes above it.
size_t checkSound(const Graph& g, const Bounds& b, const std::vector<testing::Instance>& insts) {
    size_t checks = 0;
    auto checkCorners = [&](const Box& inner, const Affine& innerToWorld,
                            const testing::PathNode& pn, const char* what) {
        const Affine toNode = pn.toWorld.inverse() * innerToWorld;
        const bool isSelect = g.nodes[pn.node].kind == NodeKind::Select;
        for (int corner = 0; corner < 8; ++corner) {
            Vec3 c;
            for (int i = 0; i < 3; ++i) c[i] = (corner >> i) & 1 ? inner.hi[i] : inner.lo[i];
            if (!isFinite(c)) continue;  // unbounded sides (plane) have no corners
            const Vec3 p = toNode.point(c);
            ++checks;
            if (!boxContainsWithTolerance(b.node[pn.node], p)) {
                ADD_FAILURE() << what << " outside the box of node " << pn.node << " at (" << p.x
                              << "," << p.y << "," << p.z << ")";
                return false;
            }
            if (isSelect && !boxContainsWithTolerance(b.select(g, pn.node, pn.depth), p)) {
                ADD_FAILURE() << what << " outside the depth-" << pn.depth << " box of S-node "
                              << pn.node;
                return false;
            }
        }
        return true;
    };
    for (const auto& inst : insts) {
        const Box pb = instanceBox(inst);
        if (pb.isEmpty()) continue;
        size_t clip = 0;
        bool clipped = false;
        for (size_t j = 0; j < inst.path.size(); ++j) {
            const Node& k = g.nodes[inst.path[j].node];
            if (k.is(CsgOp::Intersection) ||
                (k.is(CsgOp::Difference) && inst.path[j].childTaken > 0)) {
                clip = j;
                clipped = true;
            }
        }
        for (size_t j = clipped ? clip + 1 : 0; j < inst.path.size(); ++j)
            if (!checkCorners(pb, inst.toWorld, inst.path[j], "a primitive instance"))
                return checks;
        if (!clipped) continue;
        const auto& cn = inst.path[clip];
        const Box& cb = b.node[cn.node];
        if (cb.isEmpty()) continue;
        for (size_t j = 0; j < clip; ++j)
            if (!checkCorners(cb, cn.toWorld, inst.path[j], "a clipping node's box")) return checks;
    }
    return checks;
}

void checkScene(const char* text, BoundsOptions opt = {}, size_t minInstances = 1) {
    auto c = compile(text);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    opt.pad = false;  // check the raw analysis, not the safety margin
    const Bounds b = computeBounds(g, opt);
    const auto insts = Expander(g).run();
    ASSERT_GE(insts.size(), minInstances);
    EXPECT_GT(checkSound(g, b, insts), 0u);
}

// growBox by its rule, computed here side by side: each finite end moves out by
// rel * (finite extent) + abs * max(|ends|, 1), an infinite end stays. The boxes: bounded
// (the inline path, ends on either side of 1 and of 0), one or both ends infinite on an
// axis, and an extent that overflows though both ends are finite.
TEST(Bounds, GrowBoxMovesEachFiniteSideByItsRule) {
    const double inf = std::numeric_limits<double>::infinity(), rel = 1e-7, abs = 1e-9;
    auto byRule = [&](const Box& b) {
        Box r = b;
        for (int i = 0; i < 3; ++i) {
            const double lo = b.lo[i], hi = b.hi[i];
            const double extent = std::isfinite(hi - lo) ? hi - lo : 0.0;
            const double big = std::max({1.0, std::isfinite(lo) ? std::fabs(lo) : 0.0,
                                         std::isfinite(hi) ? std::fabs(hi) : 0.0});
            const double m = rel * extent + abs * big;
            r.lo[i] = lo - m, r.hi[i] = hi + m;
        }
        return r;
    };
    const Box boxes[] = {
        {{-3.5, 0.25, -0.5}, {2, 0.75, 0.5}}, {{-1e300, 1, 2}, {1e300, 5, 3}},
        {{-1.5e308, 1, 2}, {1.5e308, 5, 3}},  {{-inf, 1, 2}, {4, 5, 3}},
        {{-inf, -inf, 2}, {inf, 5, inf}},     {{0, 0, 0}, {0, 0, 0}},
    };
    for (const Box& b : boxes) {
        const Box grown = growBox(b, rel, abs), expected = byRule(b);
        for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(std::bit_cast<uint64_t>(grown.lo[i]),
                      std::bit_cast<uint64_t>(expected.lo[i]));
            EXPECT_EQ(std::bit_cast<uint64_t>(grown.hi[i]),
                      std::bit_cast<uint64_t>(expected.hi[i]));
        }
    }
    EXPECT_TRUE(growBox(Box::empty(), rel, abs).isEmpty());
}

// tri1's and tri2's boxes, written out in primitiveBox, are the boxes of their corners
// (triangleCorners) bit for bit.
TEST(Bounds, TheUnitTrianglesBoxesAreTheirCornersBoxes) {
    for (PrimitiveKind kind : {PrimitiveKind::Tri1, PrimitiveKind::Tri2}) {
        Vec3 c[3];
        triangleCorners(kind, nullptr, c);
        Box corners;
        for (const Vec3& p : c) corners.extend(p);
        const Box b = primitiveBox(kind, nullptr);
        for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(std::bit_cast<uint64_t>(b.lo[i]), std::bit_cast<uint64_t>(corners.lo[i]));
            EXPECT_EQ(std::bit_cast<uint64_t>(b.hi[i]), std::bit_cast<uint64_t>(corners.hi[i]));
        }
    }
}

TEST(Bounds, SierpinskiIsSoundAndTight) {
    auto c = compile(testing::kSierpinski);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    BoundsOptions opt;
    opt.pad = false;
    const Bounds b = computeBounds(g, opt);
    const auto insts = Expander(g).run();
    ASSERT_EQ(insts.size(), 256u);
    EXPECT_GT(checkSound(g, b, insts), 0u);
    // The S-node's hyper-bounding box is the tetrahedron's cube [-1,1]^3 exactly: the
    // system is contractive and every part is as tight as the whole.
    const NodeId s = g.modules[0].node;
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(b.node[s].lo[i], -1, 1e-12);
        EXPECT_NEAR(b.node[s].hi[i], 1, 1e-12);
    }
    EXPECT_EQ(b.infiniteNodes, 0u);
}

TEST(Bounds, ParameterDependentTransformsAreBoundedSoundly) {
    checkScene(R"(
{n = 12} S
S if(n > 0, 2, 1)
1: S -> sphere
2: S -> move(0,0,0.3) cylinder ∪ {n = n-1} rotz(n*25) move(1.2 - 0.05*n,0,0.2) uscale(0.6 + 0.02*n) S ∪
        {n = n-2} roty(-n*7) move(0, 0.1*n, 1) scale(0.5, 0.7, 0.4) S
)");
}

TEST(Bounds, SummaryFixpointIsSound) {
    // Force the summary states for most depths with a tiny state budget.
    BoundsOptions opt;
    opt.maxStates = 8;
    checkScene(R"(
settings { max_depth 40 }
{n = 9} S
S if(n > 0, 2, 1)
1: S -> cone
2: S -> move(0,0,1) rotz(30) uscale(0.8) {n = n-1} S ∪ rotx(90) cube
)",
               opt);
}

TEST(Bounds, NonContractiveSystemFallsBackToInfiniteBoxes) {
    // Growing copies: the summary iteration cannot converge, so the analysis must give
    // up (infinite boxes), never guess.
    auto c = compile(R"(
settings { max_depth 60 }
{n = 30} S
S if(n > 0, 2, 1)
1: S -> sphere
2: S -> sphere ∪ {n = n-1} move(1,0,0) uscale(1.1) S
)");
    ASSERT_TRUE(c->graph);
    BoundsOptions opt;
    opt.maxStates = 8;
    opt.pad = false;
    const Bounds b = computeBounds(*c->graph, opt);
    EXPECT_GT(b.infiniteNodes, 0u);
    const auto insts = Expander(*c->graph).run();
    EXPECT_GT(checkSound(*c->graph, b, insts), 0u);
    // With exact depths (the default budget) the same system gets finite boxes.
    opt.maxStates = 400000;
    const Bounds exact = computeBounds(*c->graph, opt);
    EXPECT_EQ(exact.infiniteNodes, 0u);
    EXPECT_GT(checkSound(*c->graph, exact, insts), 0u);
}

TEST(Bounds, CsgAndPaintAndTorus) {
    checkScene(R"(
material red { color <1,0,0> }
{k = 3; r = 0.2} A
A if(k > 0, 2, 1)
1: A -> paint(red) (sphere \ move(0.5,0,0) uscale(0.7) cube)
2: A -> torus(1, r) ∪ (cylinder ∩ move(0,0,0.5) sphere) ∪ {k = k-1; r = r*0.8} move(0,0,1) uscale(0.7) A
)");
}

TEST(Bounds, StochasticTerrainWithShearsAndTriangles) {
    // A small version of the paper's figure 8: random displacements through rand(sd),
    // z-shears of triangles.
    checkScene(R"(
{ cnt = 3; delta = 0.5; kl = 1; x1 = 0; y1 = 0; z1 = 0; z2 = 0.1; z3 = -0.1 } T
T if(cnt > 0, 2, 1)
1: T -> move(0,0,z1) zshear(z2-z1, z3-z1) tri1
2: T -> {cnt = cnt-1; z2 = (z1+z2)/2 + (rand(x1*7+y1*3) - 0.5)*delta; delta = delta*0.5; kl = kl/2}
          scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; z3 = (z1+z3)/2 + (rand(x1*5+y1*11) - 0.5)*delta; delta = delta*0.5}
          move(0.5,0,0) scale(0.5,0.5,1) T ∪
        {cnt = cnt-1; z1 = z1 + rand()*delta; delta = delta*0.5}
          move(0,0.5,0) scale(0.5,0.5,1) T
)");
}

TEST(Bounds, ChooseAndRandomRules) {
    checkScene(R"(
{n = 6} P
P if(n > 0, choose(0.5, 0.3, 0.2) + 1, 1)
1: P -> sphere
2: P -> cylinder ∪ {n = n-1} move(0,0,1) rotz(rand()*360) roty(20) uscale(0.8) P
3: P -> cone ∪ {n = n-1} move(0,0,1) roty(-30) uscale(0.7) P ∪ {n = n-1} move(0,0,1) roty(30) uscale(0.6) P
4: P -> {n = n-1} move(0,0,1) uscale(0.9) P
)");
}

TEST(Interval, AmbiguousConditionsForkAndJoin) {
    // Every function on wide intervals, in a condition that may be true or false: both
    // branches run and their (equal) results join to exactly 1.
    auto c = compile(R"(
{a = 1; b = 2} S
S if(sin(a*b) + cos(a) - tan(a) + sqrt(abs(b)) + exp(a) + ln(b) + pow(a, 3) + min(a,b) + max(a,b) + mod(b*7, 3) + floor(a*2.5) + atan2(a,b) > 100, 1, 1)
1: S -> sphere
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    AbstractFrame f(g.slotCount());
    const Slot a = g.slotNames[0] == "a" ? 0 : 1, b = 1 - a;
    f[a] = AbstractSlot{Interval::of(-30, 200), false};
    f[b] = AbstractSlot{Interval::of(0.5, 3), false};
    const ExprId sel = g.modules[0].select;
    const Interval r = evalInterval(g, sel, f);
    EXPECT_TRUE(r.isPoint());
    EXPECT_EQ(r.lo, 1);
}

TEST(Interval, SampledExpressionsStayInside) {
    // Random concrete evaluations of a messy expression must fall inside its interval.
    auto c = compile(R"(
{x = 0; y = 0} S
S 1
1: S -> move(sin(x*37) * y - cos(y) / (x + 5.5), pow(abs(x), 1.5) - atan(y*x) + mod(x, 2.5), if(x > y, x*y, -x + rand(y)) + min(x, y, 0.3) * clamp(y, -1, 1)) sphere
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    NodeId t = kNone;
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        if (g.nodes[n].kind == NodeKind::Transform) t = n;
    ASSERT_NE(t, kNone);
    const Transform& tr = g.transforms[g.nodes[t].payload];
    AbstractFrame f(g.slotCount());
    f[0] = AbstractSlot{Interval::of(-4, 3), false};
    f[1] = AbstractSlot{Interval::of(-2, 6), false};
    std::vector<double> frame(g.slotCount());
    for (uint32_t k = 0; k < tr.argCount; ++k) {
        const ExprId e = g.args[tr.firstArg + k];
        const Interval iv = evalInterval(g, e, f);
        for (int i = 0; i <= 200; ++i)
            for (int j = 0; j <= 50; ++j) {
                frame[0] = -4 + 7.0 * i / 200;
                frame[1] = -2 + 8.0 * j / 50;
                const double v = evalExpr(g, e, EvalState{frame.data(), kRootPath});
                ASSERT_TRUE(iv.contains(v))
                    << "arg " << k << " value " << v << " not in [" << iv.lo << ", " << iv.hi
                    << "] at x=" << frame[0] << " y=" << frame[1];
            }
    }
}

}  // namespace
}  // namespace pcsg::tracer
