// `clock` and `frame` (docs/language.md section 11): read-only values in every expression,
// never constant, never folded, and never part of the instance path.
#include <gtest/gtest.h>

#include <string>

#include "compile_test_util.h"
#include "eval.h"
#include "walk.h"

namespace pcsg {
namespace {

using testing::compile;

// The first module's selection at the axiom's S-node, at the given time.
uint32_t ruleAt(Graph& g, double clock, int frame = 1) {
    g.time = Time{clock, frame};
    std::vector<double> f(g.slotCount());
    initFrame(g, f.data());
    return selectRule(g, g.modules[0].node, EvalState{f.data(), kRootPath});
}

TEST(Clock, AStillHasClockZeroAndFrameOne) {
    const Time t;
    EXPECT_EQ(t.clock, 0);
    EXPECT_EQ(t.frame, 1);
}

TEST(Clock, ReadInASelectionFunction) {
    auto c = compile("S\nS if(clock < 0.5, 1, 2)\n1: S -> sphere\n2: S -> cube\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    EXPECT_EQ(ruleAt(g, 0), 0u);
    EXPECT_EQ(ruleAt(g, 0.25), 0u);
    EXPECT_EQ(ruleAt(g, 0.75), 1u);
}

TEST(Clock, FrameReadInASelectionFunction) {
    auto c = compile("S\nS if(frame == 1, 1, 2)\n1: S -> sphere\n2: S -> cube\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    EXPECT_EQ(ruleAt(g, 0, 1), 0u);
    EXPECT_EQ(ruleAt(g, 0, 2), 1u);
}

TEST(Clock, ReadInARuleAndATransformArgumentIsNotConstant) {
    // In a C-node of a rule and in a T-node's argument: the T-node is not folded.
    auto c = compile("{c = 2} S\nS 1\n1: S -> {d = clock * c} move(d, clock * 10, 0) sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    ASSERT_EQ(g.transforms.size(), 1u);
    EXPECT_FALSE(g.transforms[0].constant);
    NodeId t = kNone;
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        if (g.nodes[n].kind == NodeKind::Transform) t = n;
    ASSERT_NE(t, kNone);
    std::vector<double> f(g.slotCount());
    initFrame(g, f.data());
    f[g.slot("d")] = 1.5;
    g.time.clock = 0.5;
    const Affine m = transformMatrix(g, t, EvalState{f.data(), kRootPath});
    EXPECT_EQ(m.t.x, 1.5);
    EXPECT_EQ(m.t.y, 5.0);
    // And the C-node's assignment reads the clock.
    bool readsClock = false;
    for (const Assignment& a : g.assignments)
        if (g.slotNames[a.slot] == "d") readsClock = g.exprs[a.value].usesTime;
    EXPECT_TRUE(readsClock);
}

TEST(Clock, AClockExpressionIsNeitherConstantNorFolded) {
    // c = clock is the only assignment of c: a constant-looking parameter, not folded.
    auto c = compile("{c = clock * 2} S\nS 1\n1: S -> uscale(1 + c) sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    for (const Expr& e : g.exprs) {
        if (e.usesTime) {
            EXPECT_FALSE(e.constant) << e.text;
        }
    }
    ASSERT_EQ(g.transforms.size(), 1u);
    EXPECT_FALSE(g.transforms[0].constant);
}

TEST(Clock, ReadInAPrimitiveArgument) {
    auto c = compile("torus(1, 0.1 + clock)\n");
    ASSERT_TRUE(c->graph) << c->errors();
    ASSERT_EQ(c->graph->primitives.size(), 1u);
    EXPECT_FALSE(c->graph->primitives[0].constant);
}

TEST(Clock, EvaluatesToTheGraphsTime) {
    auto c = compile(
        "{c = clock * 10 + frame} S\nS if(c > 20, 2, 1)\n1: S -> sphere\n"
        "2: S -> cube\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    ExprId e = kNone;
    for (const Assignment& a : g.assignments) e = a.value;
    ASSERT_NE(e, kNone);
    g.time = Time{0.25, 3};
    EXPECT_DOUBLE_EQ(evalExpr(g, e, EvalState{nullptr, kRootPath}), 5.5);
    g.time = Time{};
    EXPECT_DOUBLE_EQ(evalExpr(g, e, EvalState{nullptr, kRootPath}), 1.0);
}

TEST(Clock, AssigningToItIsAnErrorNamingIt) {
    for (const char* word : {"clock", "frame"}) {
        auto c = compile(std::string("{") + word + " = 1} sphere\n");
        EXPECT_FALSE(c->graph);
        EXPECT_NE(c->errors().find(std::string("'") + word + "'"), std::string::npos)
            << c->errors();
        EXPECT_NE(c->errors().find("read-only"), std::string::npos) << c->errors();
    }
    auto d = compile("w: S(3)\np1: S(clock) -> sphere\n");
    EXPECT_FALSE(d->graph);
    EXPECT_NE(d->errors().find("'clock'"), std::string::npos) << d->errors();
}

TEST(Clock, RandomChoicesDoNotDependOnTheClock) {
    auto c = compile("S\nS choose(1, 1, 1)\n1: S -> sphere\n2: S -> cube\n3: S -> cone\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    const uint32_t atZero = ruleAt(g, 0);
    for (double clock : {0.1, 0.5, 1.0, 17.0}) EXPECT_EQ(ruleAt(g, clock), atZero);
    // rand() in a C-node: the same value at every clock.
    auto r = compile("{x = rand()} S\nS 1\n1: S -> uscale(1 + x) sphere\n");
    ASSERT_TRUE(r->graph) << r->errors();
    Graph& h = *r->graph;
    const ExprId e = h.assignments[0].value;
    const double v0 = evalExpr(h, e, EvalState{nullptr, kRootPath});
    h.time = Time{0.7, 8};
    EXPECT_EQ(evalExpr(h, e, EvalState{nullptr, kRootPath}), v0);
}

// Which modules' instances change with the time (walk.h's ModuleDependencies::usesTime):
// a module whose own rules read neither `clock` nor `frame` but that reaches one that does
// changes too; a module that reaches none does not, whatever reads the time above it.
TEST(Clock, ModuleDependenciesKnowWhichSubGraphsReadTheTime) {
    auto c = compile(
        "move(clock, 0, 0) A ∪ B ∪ C\n"
        "A 1\n1: A -> uscale(2) D\n"
        "B 1\n1: B -> sphere\n"
        "C if(frame > 2, 1, 2)\n1: C -> cube\n2: C -> sphere\n"
        "D 1\n1: D -> {r = 1 + clock} torus(r, 0.1)\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const std::vector<ModuleDependencies> deps = moduleDependencies(g);
    auto usesTime = [&](const std::string& name) {
        for (size_t m = 0; m < g.modules.size(); ++m)
            if (g.modules[m].name == name) return deps[m].analysed && deps[m].usesTime;
        ADD_FAILURE() << "no module " << name;
        return false;
    };
    EXPECT_TRUE(usesTime("A"));  // through D
    EXPECT_FALSE(usesTime("B"));
    EXPECT_TRUE(usesTime("C"));  // its selection reads frame
    EXPECT_TRUE(usesTime("D"));
}

}  // namespace
}  // namespace pcsg
