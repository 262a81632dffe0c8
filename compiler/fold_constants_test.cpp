// Constant parameters (fold_constants.h): which slots fold, which must not, and that
// folding never changes what a graph means.
#include "fold_constants.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "compile_test_util.h"
#include "compiler.h"
#include "eval.h"
#include "walk.h"

namespace pcsg {
namespace {

std::unique_ptr<testing::Compiled> compile(std::string text, bool fold = true) {
    auto c = testing::compile(std::move(text), CompileOptions{.foldConstants = fold});
    if (!c->graph) ADD_FAILURE() << c->errors();
    return c;
}

// How many instructions of the graph load the slot.
size_t loadsOf(const Graph& g, const std::string& name) {
    size_t n = 0;
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] == name)
            for (const Expr& e : g.exprs)
                for (uint32_t pc = e.begin; pc < e.end; ++pc)
                    n += g.code[pc].op == Op::Load && g.code[pc].a == s;
    return n;
}

size_t constantTransforms(const Graph& g) {
    size_t n = 0;
    for (const Transform& t : g.transforms) n += t.constant;
    return n;
}

TEST(FoldConstants, ParametersSetOnceInTheAxiomBecomeConstants) {
    // Figure 5a's pattern: angles and factors set in the axiom's C-node, never changed.
    auto c = compile(R"(
{ n = 4; alpha = -60; f = 0.73; d = 1/2 } T
T if(n > 0, 2, 1)
1: T -> scale(0.1, 0.1, d) cylinder
2: T -> cylinder ∪ {n = n-1} move(0,0,1) rotx(alpha) uscale(f) T
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    EXPECT_EQ(loadsOf(g, "alpha"), 0u);
    EXPECT_EQ(loadsOf(g, "f"), 0u);
    EXPECT_EQ(loadsOf(g, "d"), 0u);
    EXPECT_GT(loadsOf(g, "n"), 0u);  // n changes: it stays a parameter
    // scale(0.1,0.1,d), move, rotx(alpha) and uscale(f) are all constant now.
    EXPECT_EQ(constantTransforms(g), g.transforms.size());
    const auto unfolded = compile(c->text, false);
    EXPECT_LT(constantTransforms(*unfolded->graph), g.transforms.size());
}

TEST(FoldConstants, AChainOfConstantsFoldsInTurn) {
    auto c = compile(R"(
{ a = 3; b = a*2; n = 2 } {c = b + 1} S
S if(n > 0, 2, 1)
1: S -> uscale(c) sphere
2: S -> {n = n-1} move(b, 0, 0) S
)");
    ASSERT_TRUE(c->graph);
    EXPECT_EQ(loadsOf(*c->graph, "a"), 0u);
    EXPECT_EQ(loadsOf(*c->graph, "b"), 0u);
    EXPECT_EQ(loadsOf(*c->graph, "c"), 0u);
}

TEST(FoldConstants, WhatMustStayAParameterStaysOne) {
    // r: assigned two different constants. p: one of its assignments is not constant.
    // q: read on a path where it is never assigned (a run-time error that folding must not
    // hide). u: read before its only assignment, in the same C-node.
    auto c = compile(R"(
{ r = 1; p = 2 } (A ∪ {r = 2} A) ∪ {p = p + 1} uscale(p) sphere ∪
    {t = u + 1; u = 5} uscale(t) sphere ∪ B
A 1
1: A -> uscale(r) sphere
B 1
1: B -> move(q, 0, 0) sphere ∪ {q = 1} sphere
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    EXPECT_GT(loadsOf(g, "r"), 0u);
    EXPECT_GT(loadsOf(g, "p"), 0u);
    EXPECT_GT(loadsOf(g, "q"), 0u);
    EXPECT_GT(loadsOf(g, "u"), 0u);
}

// Expanding a graph with and without folding gives the same primitives, matrices, materials
// and arguments, bit for bit: folding evaluates the same expressions by the same code.
struct Flat {
    std::vector<std::pair<PrimitiveKind, std::vector<double>>> prims;
};

struct FlatSink {
    using Result = int;
    Flat& out;
    int nothing() const { return 0; }
    void visit() {}
    bool lookup(NodeId, uint32_t, const double*, uint64_t, int&) { return false; }
    void store(NodeId, uint32_t, const double*, uint64_t, int) {}
    int primitive(PrimitiveKind k, const Affine& w, uint32_t material, const double* args,
                  uint32_t argc) {
        std::vector<double> v;
        for (const auto& row : w.l) v.insert(v.end(), row, row + 3);
        v.insert(v.end(), {w.t.x, w.t.y, w.t.z, static_cast<double>(material)});
        v.insert(v.end(), args, args + argc);
        out.prims.emplace_back(k, std::move(v));
        return 0;
    }
    void beginOperator(WalkEntry&) {}
    int endOperator(CsgOp, const int*, uint32_t, const WalkEntry&) { return 0; }
};

Flat flatten(const Graph& g) {
    Flat f;
    FlatSink sink{f};
    const Semantics sem(g);
    Walker<FlatSink> walker(sem, sink);
    walker.run();
    return f;
}

TEST(FoldConstants, AnUnassignedReadIsStillAnError) {
    // x is only ever set to 1, but the axiom reads it before any C-node sets it.
    auto c = compile(R"(
S
S if(x > 0, 2, 1)
1: S -> sphere
2: S -> {x = 0} S
)");
    ASSERT_TRUE(c->graph);
    EXPECT_GT(loadsOf(*c->graph, "x"), 0u);
    EXPECT_THROW(flatten(*c->graph), RuntimeError);
}

TEST(FoldConstants, ScenesMeanTheSameWithAndWithoutFolding) {
    size_t foldedSomewhere = 0;
    for (const char* name : {"sympodial_tree", "seed001_tree", "palm", "conifer", "flower",
                             "stochastic_plant", "sierpinski", "sierpinski_pl"}) {
        std::ifstream in(std::string(PCSG_SCENES_DIR) + "/" + name + ".pcsg");
        std::stringstream text;
        text << in.rdbuf();
        auto folded = compile(text.str()), plain = compile(text.str(), false);
        ASSERT_TRUE(folded->graph && plain->graph) << name;
        const Flat a = flatten(*folded->graph), b = flatten(*plain->graph);
        ASSERT_EQ(a.prims.size(), b.prims.size()) << name;
        for (size_t i = 0; i < a.prims.size(); ++i) {
            ASSERT_EQ(a.prims[i].first, b.prims[i].first) << name << " primitive " << i;
            ASSERT_EQ(a.prims[i].second, b.prims[i].second) << name << " primitive " << i;
        }
        foldedSomewhere += constantTransforms(*folded->graph) > constantTransforms(*plain->graph);
    }
    EXPECT_GE(foldedSomewhere, 3u);  // the plants set their angles once
}

}  // namespace
}  // namespace pcsg
