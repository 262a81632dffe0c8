// Tests of the expander and the counting pass on hand-built graphs.
#include "expander.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "eval.h"
#include "test_graphs.h"

namespace pcsg {
namespace {

using namespace testgraphs;

uint64_t pow4(int n) {
    return uint64_t{1} << (2 * n);
}

ExpandOptions budget(uint64_t maxNodes, uint64_t countVisits = 0) {
    ExpandOptions o;
    o.maxNodes = maxNodes;
    o.countVisits = countVisits;
    return o;
}

TEST(Expander, SierpinskiOrderNHasFourToTheNTetrahedra) {
    for (int n = 0; n <= 5; ++n) {
        const Graph g = sierpinski(n);
        const ExpandedTree t = expand(g);
        EXPECT_EQ(t.primitives.size(), pow4(n)) << "order " << n;
        // A tree of 4-ary unions: (4^n - 1) / 3 operators.
        EXPECT_EQ(t.nodes.size(), pow4(n) + (pow4(n) - 1) / 3) << "order " << n;
        ASSERT_NE(t.root, kNone);
        EXPECT_EQ(t.root, t.nodes.size() - 1);
        for (const TreePrimitive& p : t.primitives) {
            EXPECT_EQ(p.kind, PrimitiveKind::Tetrahedron);
            EXPECT_DOUBLE_EQ(p.toWorld.l[0][0], std::ldexp(1.0, -n));
            EXPECT_DOUBLE_EQ(p.toWorld.l[0][1], 0.0);
        }
        const ExpansionCount c = countExpansion(g);
        EXPECT_TRUE(c.complete);
        EXPECT_EQ(c.primitives, t.primitives.size());
        EXPECT_EQ(c.nodes, t.nodes.size());
        EXPECT_EQ(c.treeBytes(), t.bytes());
    }
}

TEST(Expander, SierpinskiCornersAreTheTetrahedronsVertices) {
    // Order 1: four tetrahedra of half size at the centres (±0.5, ...).
    const ExpandedTree t = expand(sierpinski(1));
    std::set<std::tuple<double, double, double>> centres;
    for (const TreePrimitive& p : t.primitives)
        centres.insert({p.toWorld.t.x, p.toWorld.t.y, p.toWorld.t.z});
    const std::set<std::tuple<double, double, double>> expected = {
        {0.5, 0.5, 0.5}, {-0.5, -0.5, 0.5}, {0.5, -0.5, -0.5}, {-0.5, 0.5, -0.5}};
    EXPECT_EQ(centres, expected);
    // The union keeps its four operands in the graph's order.
    const TreeNode& root = t.nodes[t.root];
    EXPECT_TRUE(root.is(CsgOp::Union));
    ASSERT_EQ(root.count, 4u);
    EXPECT_EQ(t.primitiveOf(t.childrenOf(t.root)[0]).toWorld.t, Vec3(0.5, 0.5, 0.5));
    EXPECT_EQ(t.primitiveOf(t.childrenOf(t.root)[3]).toWorld.t, Vec3(-0.5, 0.5, -0.5));
}

TEST(Expander, CountingIsMemoisedForDeterministicSystems) {
    const ExpansionCount c = countExpansion(sierpinski(12));
    EXPECT_TRUE(c.complete);
    EXPECT_EQ(c.primitives, pow4(12));
    EXPECT_EQ(c.nodes, pow4(12) + (pow4(12) - 1) / 3);
    // Each (S, c) pair is visited through its four corners once: a few hundred visits,
    // where the unmemoised walk would make tens of millions.
    EXPECT_LT(c.visits, 1000u);
    // Order 40 saturates instead of overflowing.
    const ExpansionCount big = countExpansion(sierpinski(40));
    EXPECT_TRUE(big.complete);
    EXPECT_EQ(big.primitives, UINT64_MAX);
}

TEST(Expander, StochasticSystemExpandsIdenticallyTwice) {
    const Graph g = stochastic(7);
    const ExpandedTree a = expand(g);
    const ExpandedTree b = expand(g);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.primitives.size(), b.primitives.size());
    ASSERT_GT(a.primitives.size(), 3u);
    for (size_t i = 0; i < a.primitives.size(); ++i) {
        EXPECT_EQ(a.primitives[i].kind, b.primitives[i].kind);
        EXPECT_EQ(a.primitives[i].toWorld, b.primitives[i].toWorld);
    }
    EXPECT_EQ(a.children, b.children);
    // The randomness is real: rand() gives the spheres different offsets, and both rules
    // of B are taken somewhere.
    std::set<double> offsets;
    size_t spheres = 0, cubes = 0;
    for (const TreePrimitive& p : a.primitives) {
        if (p.kind == PrimitiveKind::Sphere) ++spheres;
        if (p.kind == PrimitiveKind::Cube) ++cubes;
    }
    for (const TreePrimitive& p : a.primitives)
        if (p.kind == PrimitiveKind::Sphere) offsets.insert(p.toWorld.t.x + p.toWorld.t.y);
    EXPECT_GT(spheres, 1u);
    EXPECT_GT(cubes, 0u);
    EXPECT_GT(offsets.size(), 1u);
    // The count agrees and was not memoised (the sub-graph uses the instance path).
    const ExpansionCount c = countExpansion(g);
    EXPECT_EQ(c.primitives, a.primitives.size());
    EXPECT_EQ(c.nodes, a.nodes.size());
    // A different seed describes a different object.
    Graph g2 = g;
    g2.scene.settings.seed = 12345;
    const ExpandedTree other = expand(g2);
    bool differs = other.primitives.size() != a.primitives.size();
    for (size_t i = 0; !differs && i < a.primitives.size(); ++i)
        differs = !(other.primitives[i].toWorld == a.primitives[i].toWorld);
    EXPECT_TRUE(differs);
}

TEST(Expander, BudgetErrorSaysHowManyNodesItWouldNeed) {
    const Graph g = sierpinski(8);
    const uint64_t need = pow4(8) + (pow4(8) - 1) / 3;
    try {
        expand(g, budget(1000));
        FAIL() << "no budget error";
    } catch (const BudgetError& e) {
        EXPECT_EQ(e.limit, 1000u);
        ASSERT_TRUE(e.needed.has_value());
        EXPECT_EQ(*e.needed, need);
        EXPECT_NE(std::string(e.what()).find(std::to_string(need)), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--max-nodes"), std::string::npos) << e.what();
    }
    // Exactly at the budget it fits.
    EXPECT_EQ(expand(g, budget(need)).nodes.size(), need);
    // When the counting pass gives up, the builder's own check stops the expansion.
    try {
        expand(g, budget(1000, 10));
        FAIL() << "no budget error";
    } catch (const BudgetError& e) {
        EXPECT_FALSE(e.needed.has_value());
        EXPECT_NE(std::string(e.what()).find("more than"), std::string::npos) << e.what();
    }
}

TEST(Expander, CountStopsAtItsWorkLimit) {
    const ExpansionCount c = countExpansion(stochastic(12), CountOptions{50});
    EXPECT_FALSE(c.complete);
    EXPECT_LE(c.visits, 51u);
}

TEST(Expander, RuntimeErrorsCarryTheModulePath) {
    // S never terminates: 2: S -> uscale(.5) S (c is not counted down).
    Graph g;
    defaultScene(g);
    g.scene.settings.maxDepth = 10;
    const Slot c = g.slot("c");
    const NodeId s = module(g, "S", ifPositive(g, c, 2, 1), 2);
    const NodeId t = module(g, "T", g.addConstant(1), 1);
    setRule(g, s, 0, primitive(g, PrimitiveKind::Sphere));
    setRule(g, s, 1, transform(g, TransformOp::UScale, {0.5}, s));
    setRule(g, t, 0, g.addOperator(CsgOp::Union, {primitive(g, PrimitiveKind::Cube), s}));
    g.axiom = calc(g, {{c, g.addConstant(1)}}, t);
    for (int pass = 0; pass < 2; ++pass) {
        try {
            if (pass == 0)
                expand(g);
            else
                countExpansion(g);
            FAIL() << "no run-time error";
        } catch (const RuntimeError& e) {
            ASSERT_EQ(e.modulePath.size(), 11u);  // T, then S ten times (depths 2..11)
            EXPECT_EQ(e.modulePath.front(), "T");
            EXPECT_EQ(e.modulePath.back(), "S");
            EXPECT_NE(e.message.find("max_depth"), std::string::npos) << e.message;
            EXPECT_NE(e.format(g).find("T -> S (x10)"), std::string::npos) << e.format(g);
        }
    }
}

TEST(Expander, ReadingAnUnassignedParameterIsReportedWithItsPath) {
    Graph g;
    defaultScene(g);
    const Slot c = g.slot("c");
    const NodeId s = module(g, "S", ifPositive(g, c, 2, 1), 2);
    setRule(g, s, 0, primitive(g, PrimitiveKind::Sphere));
    setRule(g, s, 1, primitive(g, PrimitiveKind::Cube));
    g.axiom = s;  // c is never assigned
    try {
        expand(g);
        FAIL();
    } catch (const RuntimeError& e) {
        EXPECT_EQ(e.modulePath, std::vector<std::string>{"S"});
        EXPECT_NE(e.message.find("'c'"), std::string::npos) << e.message;
    }
}

TEST(Expander, TransformsComposeInTextOrderAndTheInnermostPaintWins) {
    // paint(1) move(1,0,0) paint(2) uscale(2) sphere
    Graph g;
    defaultScene(g);
    g.materials.push_back(Material{.name = "one"});
    g.materials.push_back(Material{.name = "two"});
    const NodeId sph = primitive(g, PrimitiveKind::Sphere);
    g.axiom = paint(g, 1,
                    transform(g, TransformOp::Move, {1, 0, 0},
                              paint(g, 2, transform(g, TransformOp::UScale, {2}, sph))));
    const ExpandedTree t = expand(g);
    ASSERT_EQ(t.primitives.size(), 1u);
    const TreePrimitive& p = t.primitives[0];
    EXPECT_EQ(p.material, 2u);
    EXPECT_EQ(p.toWorld.point({0, 0, 0}), Vec3(1, 0, 0));
    EXPECT_EQ(p.toWorld.point({1, 0, 0}), Vec3(3, 0, 0));
}

TEST(Expander, SiblingsDoNotSeeEachOthersAssignments) {
    // {c = 1} ( {c = 5} move(c,0,0) sphere ∪ move(c,0,0) cube )
    Graph g;
    defaultScene(g);
    const Slot c = g.slot("c");
    const NodeId a =
        calc(g, {{c, g.addConstant(5)}},
             transformOf(g, TransformOp::Move, {g.addLoad(c), g.addConstant(0), g.addConstant(0)},
                         primitive(g, PrimitiveKind::Sphere)));
    const NodeId b =
        transformOf(g, TransformOp::Move, {g.addLoad(c), g.addConstant(0), g.addConstant(0)},
                    primitive(g, PrimitiveKind::Cube));
    g.axiom = calc(g, {{c, g.addConstant(1)}}, g.addOperator(CsgOp::Union, {a, b}));
    const ExpandedTree t = expand(g);
    ASSERT_EQ(t.primitives.size(), 2u);
    EXPECT_EQ(t.primitives[0].toWorld.t.x, 5.0);
    EXPECT_EQ(t.primitives[1].toWorld.t.x, 1.0);
}

TEST(Expander, EmptyFoldsAwayAndCountsAgree) {
    struct Case {
        const char* name;
        CsgOp op;
        std::vector<PrimitiveKind> operands;
        size_t prims, nodes;
    };
    using P = PrimitiveKind;
    const std::vector<Case> cases = {
        {"sphere ∪ empty", CsgOp::Union, {P::Sphere, P::Empty}, 1, 1},
        {"empty ∪ empty", CsgOp::Union, {P::Empty, P::Empty}, 0, 0},
        {"sphere ∪ empty ∪ cube", CsgOp::Union, {P::Sphere, P::Empty, P::Cube}, 2, 3},
        {"sphere ∩ cube ∩ empty", CsgOp::Intersection, {P::Sphere, P::Cube, P::Empty}, 0, 0},
        {"sphere ∩ cube", CsgOp::Intersection, {P::Sphere, P::Cube}, 2, 3},
        {"sphere \\ empty", CsgOp::Difference, {P::Sphere, P::Empty}, 1, 1},
        {"sphere \\ empty \\ cube", CsgOp::Difference, {P::Sphere, P::Empty, P::Cube}, 2, 3},
        {"empty \\ sphere", CsgOp::Difference, {P::Empty, P::Sphere}, 0, 0},
    };
    for (const Case& k : cases) {
        Graph g;
        defaultScene(g);
        std::vector<NodeId> ops;
        for (P p : k.operands) ops.push_back(primitive(g, p));
        // Wrapped in a union with a torus, so that discarded operands must leave no trace.
        const NodeId inner = g.addOperator(k.op, ops);
        g.axiom = g.addOperator(CsgOp::Union, {inner, primitive(g, P::Torus, {2, 0.5})});
        const ExpandedTree t = expand(g);
        const size_t outer =
            k.prims > 0 ? 1 : 0;  // the outer union survives only with two operands
        EXPECT_EQ(t.primitives.size(), k.prims + 1) << k.name;
        EXPECT_EQ(t.nodes.size(), k.nodes + 1 + outer) << k.name;
        EXPECT_EQ(t.args.size(), 2u) << k.name;
        const ExpansionCount c = countExpansion(g);
        EXPECT_EQ(c.primitives, t.primitives.size()) << k.name;
        EXPECT_EQ(c.nodes, t.nodes.size()) << k.name;
        EXPECT_EQ(c.treeBytes(), t.bytes()) << k.name;
        // Children precede parents; every non-root node is exactly one child.
        std::vector<int> parents(t.nodes.size(), 0);
        for (uint32_t n = 0; n < t.nodes.size(); ++n)
            for (uint32_t i = 0; i < t.nodes[n].count; ++i) {
                EXPECT_LT(t.childrenOf(n)[i], n) << k.name;
                ++parents[t.childrenOf(n)[i]];
            }
        for (uint32_t n = 0; n < t.nodes.size(); ++n)
            EXPECT_EQ(parents[n], n == t.root ? 0 : 1) << k.name;
    }
}

TEST(Expander, TorusAndTriangleArgumentsAreEvaluatedPerInstance) {
    // {r = 0.25} torus(1, r) ∪ triangle(0,0,0, 1,0,0, 0,1,r)
    Graph g;
    defaultScene(g);
    const Slot r = g.slot("r");
    std::vector<ExprId> tri;
    for (double v : {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) tri.push_back(g.addConstant(v));
    tri.push_back(g.addLoad(r));
    const NodeId u = g.addOperator(
        CsgOp::Union, {primitiveOf(g, PrimitiveKind::Torus, {g.addConstant(1), g.addLoad(r)}),
                       primitiveOf(g, PrimitiveKind::Triangle, tri)});
    g.axiom = calc(g, {{r, g.addConstant(0.25)}}, u);
    const ExpandedTree t = expand(g);
    ASSERT_EQ(t.primitives.size(), 2u);
    ASSERT_EQ(t.args.size(), 11u);
    EXPECT_EQ(t.args[t.primitives[0].firstArg + 1], 0.25);
    EXPECT_EQ(t.args[t.primitives[1].firstArg + 8], 0.25);
}

TEST(Expander, DeepGraphsNeedNoDeepCStack) {
    // 50,000 nested transformations over one sphere, and 50,000 nested unions.
    Graph g;
    defaultScene(g);
    NodeId n = primitive(g, PrimitiveKind::Sphere);
    for (int i = 0; i < 50000; ++i) n = transform(g, TransformOp::Move, {1e-6, 0, 0}, n);
    for (int i = 0; i < 50000; ++i)
        n = g.addOperator(CsgOp::Union, {n, primitive(g, PrimitiveKind::Cube)});
    g.axiom = n;
    const ExpandedTree t = expand(g);
    EXPECT_EQ(t.primitives.size(), 50001u);
    EXPECT_EQ(t.nodes.size(), 100001u);
    EXPECT_NEAR(t.primitives[0].toWorld.t.x, 0.05, 1e-9);
    EXPECT_EQ(countExpansion(g).nodes, t.nodes.size());
}

TEST(Expander, AnEmptySceneExpandsToNothing) {
    Graph g;
    defaultScene(g);
    g.axiom = primitive(g, PrimitiveKind::Empty);
    const ExpandedTree t = expand(g);
    EXPECT_TRUE(t.empty());
    EXPECT_EQ(t.nodes.size(), 0u);
    EXPECT_EQ(countExpansion(g).nodes, 0u);
}

}  // namespace
}  // namespace pcsg
