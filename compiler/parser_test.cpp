// Tests of the parser through compileSource: statement kinds, the precedence of
// expression and CSG operators, the nesting limit and error recovery.
#include "parser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "compile_test_util.h"
#include "compiler.h"
#include "eval.h"

namespace pcsg {
namespace {

// The graph as the builder makes it: fold_constants_test.cpp tests the folding.
std::unique_ptr<testing::Compiled> compile(std::string text) {
    return testing::compileUnfolded(std::move(text));
}

// A compact picture of the graph below a node: U(..) I(..) D(..) for the operators,
// T/C/P prefixes for transform, calc and paint nodes, primitive names, and a module's
// name for an edge to its S-node.
std::string shape(const Graph& g, NodeId n) {
    const Node& node = g.nodes[n];
    auto kids = [&](const char* tag) {
        std::string s = tag;
        s += '(';
        for (uint32_t i = 0; i < node.childCount; ++i) {
            if (i) s += ',';
            s += shape(g, g.child(n, i));
        }
        return s + ')';
    };
    switch (node.kind) {
        case NodeKind::Select:
            return g.modules[node.payload].name;
        case NodeKind::Transform:
            return "T" + shape(g, g.child(n));
        case NodeKind::Calc:
            return "C" + shape(g, g.child(n));
        case NodeKind::Paint:
            return "P" + shape(g, g.child(n));
        case NodeKind::Operator:
            return kids(node.is(CsgOp::Union) ? "U" : node.is(CsgOp::Intersection) ? "I" : "D");
        case NodeKind::Primitive: {
            static const char* names[] = {"sphere",      "cube",  "cylinder", "cone",
                                          "tetrahedron", "torus", "plane",    "empty",
                                          "tri1",        "tri2",  "triangle"};
            return names[static_cast<int>(g.primitives[node.payload].kind)];
        }
    }
    return "?";
}

std::string axiomShape(const std::string& axiom) {
    auto c = compile(axiom);
    if (!c->graph) return "error: " + c->errors();
    return shape(*c->graph, c->graph->axiom);
}

// The value of an expression used as a module's selection function, with the given
// parameters assigned in the frame.
double value(const std::string& expr,
             const std::vector<std::pair<std::string, double>>& params = {}) {
    std::string text = "S " + expr + "\n1: S -> sphere\n{";
    for (const auto& [name, v] : params) text += name + " = 0;";
    text += "} S\n";
    auto c = compile(text);
    if (!c->graph) {
        ADD_FAILURE() << c->errors();
        return std::nan("");
    }
    const Graph& g = *c->graph;
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    for (const auto& [name, v] : params)
        for (Slot s = 0; s < g.slotCount(); ++s)
            if (g.slotNames[s] == name) frame[s] = v;
    return evalExpr(g, g.modules[0].select, EvalState{frame.data(), kRootPath});
}

TEST(ParserStatements, KindsAreDecidedByTheirFirstTokens) {
    auto c = compile(
        "camera { angle 30 }\n"
        "S if(c > 0, 2, 1)\n"  // module declaration
        "1: S -> d\n"          // rule, notation A
        "2: S -> {c = c - 1} S\n"
        "d = sphere ∪ cube\n"             // definition
        "p1: T(n) : n > 0 -> T(n - 1)\n"  // rule, notation B
        "p2: T(n) -> cone\n"
        "{c = 2} S ∪ T(3)\n");  // axiom, notation A
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    ASSERT_EQ(g.modules.size(), 2u);
    EXPECT_FALSE(g.modules[0].notationB);
    EXPECT_TRUE(g.modules[1].notationB);
    EXPECT_EQ(g.scene.camera.angle, 30);
    EXPECT_EQ(shape(g, g.axiom), "U(CS,CT)");
    EXPECT_EQ(shape(g, g.child(g.modules[0].node, 0)), "U(sphere,cube)");
    EXPECT_EQ(shape(g, g.child(g.modules[1].node, 0)), "CT");
}

TEST(ParserStatements, AxiomsTakeEveryForm) {
    const char* rules = "\nS 1\n1: S -> sphere\n";
    for (const char* axiom : {"S", "S ∪ S", "(S)", "{c=1} S", "move(1,2,3) S", "paint(default) S",
                              "flipxz S", "sphere", "w: S"}) {
        auto c = compile(std::string(axiom) + rules);
        EXPECT_TRUE(c->graph) << axiom << "\n" << c->errors();
    }
    // `S(6)` on its own is the declaration of module S with selection (6), as the table says.
    auto c = compile("S(2)\n1: S -> sphere\n2: S -> cube\nS\n");
    ASSERT_TRUE(c->graph) << c->errors();
    EXPECT_EQ(evalExpr(*c->graph, c->graph->modules[0].select, {nullptr, kRootPath}), 2);
}

TEST(ParserStatements, SemicolonsAlsoEndStatements) {
    auto c = compile("S 1; 1: S -> sphere; S");
    ASSERT_TRUE(c->graph) << c->errors();
    EXPECT_EQ(shape(*c->graph, c->graph->axiom), "S");
}

TEST(ExpressionPrecedence, FollowsTheTableOfSection3) {
    EXPECT_EQ(value("1 + 2 * 3"), 7);
    EXPECT_EQ(value("(1 + 2) * 3"), 9);
    EXPECT_EQ(value("10 - 4 - 3"), 3);  // left-associative
    EXPECT_EQ(value("64 / 4 / 2"), 8);
    EXPECT_EQ(value("7 % 4 * 2"), 6);
    EXPECT_EQ(value("2 ^ 3 ^ 2"), 512);  // right-associative
    EXPECT_EQ(value("-2 ^ 2"), -4);      // ^ binds tighter than unary minus
    EXPECT_EQ(value("2 ^ -1"), 0.5);
    EXPECT_EQ(value("--3"), 3);
    EXPECT_EQ(value("!0 + 1"), 2);
    EXPECT_EQ(value("1 + 2 < 4"), 1);
    EXPECT_EQ(value("1 < 2 == 1"), 1);   // comparisons bind tighter than equality
    EXPECT_EQ(value("2 == 2 < 3"), 0);   // 2 == (2 < 3)
    EXPECT_EQ(value("1 || 0 && 0"), 1);  // && binds tighter than ||
    EXPECT_EQ(value("(1 || 0) && 0"), 0);
    EXPECT_EQ(value("0 || 3"), 1);  // logical operators give 1 or 0
    EXPECT_EQ(value("2 && 3"), 1);
    EXPECT_EQ(value("1 != 2"), 1);
    EXPECT_EQ(value("3 >= 3"), 1);
    EXPECT_EQ(value("3 > 3"), 0);
    EXPECT_EQ(value("+4"), 4);
}

TEST(ExpressionPrecedence, FunctionsAndConstants) {
    EXPECT_DOUBLE_EQ(value("pi"), M_PI);
    EXPECT_DOUBLE_EQ(value("e"), M_E);
    EXPECT_EQ(value("sin(90)"), 1);
    EXPECT_EQ(value("min(3, 1, 2)"), 1);
    EXPECT_EQ(value("max(3, 1, 2, 5)"), 5);
    EXPECT_EQ(value("clamp(5, 0, 1)"), 1);
    EXPECT_EQ(value("mod(7, 4)"), 3);
    EXPECT_EQ(value("pow(2, 10)"), 1024);
    EXPECT_NEAR(value("atan2(1, 1)"), 45, 1e-12);
    EXPECT_EQ(value("if(1 > 0, 2, 3)"), 2);
    EXPECT_EQ(value("if(c > 0, 2, if(d > 0, 3, 1))", {{"c", 0}, {"d", 1}}), 3);
    const double r = value("rand(7)");
    EXPECT_GE(r, 0);
    EXPECT_LT(r, 1);
}

TEST(ExpressionPrecedence, LogicalOperatorsAndIfEvaluateOnlyWhatTheyNeed) {
    // x is never assigned on this path: reading it would be a run-time error.
    EXPECT_EQ(value("0 && x", {{"x", unassigned()}}), 0);
    EXPECT_EQ(value("1 || x", {{"x", unassigned()}}), 1);
    EXPECT_EQ(value("if(1, 2, x)", {{"x", unassigned()}}), 2);
    EXPECT_EQ(value("if(0, x, 3)", {{"x", unassigned()}}), 3);
    EXPECT_EQ(value("c > 0 && c < 2 || c == 5", {{"c", 5}}), 1);
    EXPECT_EQ(value("c > 0 && c < 2 || c == 5", {{"c", 3}}), 0);
    EXPECT_THROW(value("1 && x", {{"x", unassigned()}}), RuntimeError);
}

TEST(ExpressionPrecedence, ExpressionsKnowTheirTextAndPlace) {
    auto c = compile("S if(c  >  0 , 2, (1))\n1: S -> sphere\n2: S -> sphere\n{c=1} S\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Expr& e = c->graph->exprs[c->graph->modules[0].select];
    EXPECT_EQ(e.text, "if(c > 0 , 2, (1))");
    EXPECT_EQ(e.loc.line, 1u);
    EXPECT_EQ(e.loc.column, 3u);
    EXPECT_FALSE(e.constant);
    EXPECT_FALSE(e.usesPath);
    EXPECT_GE(e.maxStack, 2u);
}

TEST(ExpressionPrecedence, EqualsComparesOnlyInNotationBConditions) {
    auto ok = compile("w: S(2)\np1: S(c) : c=0 -> sphere\np2: S(c) : c = 1 || c=2 -> cube\n");
    ASSERT_TRUE(ok->graph) << ok->errors();
    const Graph& g = *ok->graph;
    std::vector<double> frame(g.slotCount());
    frame[g.modules[0].formals[0]] = 2;
    EXPECT_EQ(selectRule(g, g.modules[0].node, {frame.data(), kRootPath}), 1u);
    frame[g.modules[0].formals[0]] = 0;
    EXPECT_EQ(selectRule(g, g.modules[0].node, {frame.data(), kRootPath}), 0u);
    auto bad = compile("S if(c = 0, 1, 2)\n1: S -> sphere\n{c=1} S\n");
    EXPECT_FALSE(bad->graph);
    EXPECT_NE(bad->errors().find("1:8: error: '=' assigns only inside a C-node"), std::string::npos)
        << bad->errors();
}

TEST(ExpressionPrecedence, RandomCallSitesAreNumberedAcrossTheFile) {
    auto c = compile(
        "S choose(1, 2)\n1: S -> {a = rand()} sphere\n2: S -> {b = rand() + rand(3)} T\n"
        "T 1\n1: T -> cube\nS\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    EXPECT_EQ(g.randCallSites, 3u);
    std::vector<uint32_t> sites;
    int rand1 = 0;
    for (const Instr& in : g.code) {
        if (in.op == Op::Rand0 || in.op == Op::Choose) sites.push_back(in.a);
        if (in.op == Op::Call && in.a == static_cast<uint32_t>(Func::Rand1)) ++rand1;
    }
    std::sort(sites.begin(), sites.end());
    EXPECT_EQ(sites, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(rand1, 1);
    EXPECT_TRUE(g.exprs[g.modules[0].select].usesPath);
    EXPECT_FALSE(g.exprs[g.modules[0].select].constant);
}

TEST(CsgPrecedence, IntersectionAndDifferenceBindTighterThanUnion) {
    EXPECT_EQ(axiomShape("sphere ∪ cube ∩ cone"), "U(sphere,I(cube,cone))");
    EXPECT_EQ(axiomShape("sphere ∩ cube ∪ cone"), "U(I(sphere,cube),cone)");
    EXPECT_EQ(axiomShape("sphere | cube & cone \\ plane"), "U(sphere,D(I(cube,cone),plane))");
}

TEST(CsgPrecedence, ChainsAreLeftAssociativeAndFlat) {
    EXPECT_EQ(axiomShape("sphere ∪ cube ∪ cone"), "U(sphere,cube,cone)");
    EXPECT_EQ(axiomShape("sphere \\ cube \\ cone"), "D(sphere,cube,cone)");
    EXPECT_EQ(axiomShape("sphere ∩ cube \\ cone"), "D(I(sphere,cube),cone)");
    EXPECT_EQ(axiomShape("sphere \\ cube ∩ cone ∩ plane"), "I(D(sphere,cube),cone,plane)");
    EXPECT_EQ(axiomShape("sphere \\ (cube \\ cone)"), "D(sphere,D(cube,cone))");
    EXPECT_EQ(axiomShape("(sphere ∪ cube) ∪ cone"), "U(U(sphere,cube),cone)");
}

TEST(CsgPrecedence, UnaryPrefixesApplyToTheOneOperandAfterThem) {
    EXPECT_EQ(axiomShape("{c=1} sphere ∪ cube"), "U(Csphere,cube)");
    EXPECT_EQ(axiomShape("{c=1} (sphere ∪ cube)"), "CU(sphere,cube)");
    EXPECT_EQ(axiomShape("move(1,0,0) rotz(45) sphere ∩ cube"), "I(TTsphere,cube)");
    EXPECT_EQ(axiomShape("paint(default) {c=1} flipxz uscale(2) sphere"), "PCTTsphere");
    EXPECT_EQ(axiomShape("rotz(45)(sphere ∪ cube)"), "TU(sphere,cube)");
}

TEST(CsgPrecedence, TransformsReadAsInPovRay) {
    // `move(1,0,0) rotz(90) A`: A rotated, then moved.
    auto c = compile("move(1,0,0) rotz(90) sphere");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const NodeId outer = g.axiom;
    const NodeId inner = g.child(outer);
    ASSERT_EQ(g.nodes[outer].kind, NodeKind::Transform);
    EXPECT_EQ(g.transforms[g.nodes[outer].payload].op, TransformOp::Move);
    EXPECT_EQ(g.transforms[g.nodes[inner].payload].op, TransformOp::RotZ);
    const Affine m =
        g.transforms[g.nodes[outer].payload].matrix * g.transforms[g.nodes[inner].payload].matrix;
    const Vec3 p = m.point({1, 0, 0});
    EXPECT_NEAR(p.x, 1, 1e-15);
    EXPECT_NEAR(p.y, 1, 1e-15);
}

// --- the nesting limit: no input exhausts the stack ---

std::string repeat(const std::string& s, int n) {
    std::string out;
    out.reserve(s.size() * n);
    for (int i = 0; i < n; ++i) out += s;
    return out;
}

TEST(NestingLimit, DeepButReasonableNestingCompiles) {
    const int n = 400;
    EXPECT_EQ(compile(repeat("(", n) + "sphere" + repeat(")", n))->errors(), "");
    EXPECT_EQ(
        compile("S " + repeat("(", n) + "1" + repeat(")", n) + "\n1: S -> sphere\nS")->errors(),
        "");
    EXPECT_EQ(compile(repeat("move(1,0,0) ", n) + "sphere")->errors(), "");
}

TEST(NestingLimit, HundredThousandLevelsGetOneCleanError) {
    const int n = 100000;
    for (const std::string& text :
         {repeat("(", n) + "sphere" + repeat(")", n),                            // CSG parentheses
          "S " + repeat("(", n) + "1" + repeat(")", n) + "\n1: S -> sphere\nS",  // expression
          "S " + repeat("-", n) + "1\n1: S -> sphere\nS",                        // unary minus
          "S 2" + repeat("^2", n) + "\n1: S -> sphere\nS",   // right-associative ^
          repeat("{c=1} ", n) + "sphere",                    // C-nodes
          repeat("{c=1} (", n) + "sphere" + repeat(")", n),  // C-nodes and parentheses
          repeat("rotz(1) ", n) + "sphere",                  // transformations
          "S " + repeat("sin(", n) + "1" + repeat(")", n) + "\n1: S -> sphere\nS"}) {  // calls
        auto c = compile(text);
        EXPECT_FALSE(c->graph);
        ASSERT_EQ(c->diags.errors().size(), 1u) << c->errors().substr(0, 500);
        const std::string& m = c->diags.errors()[0].message;
        EXPECT_NE(m.find("nesting deeper than 500 levels"), std::string::npos) << m;
    }
}

TEST(NestingLimit, LongFlatChainsNeedNoDepth) {
    const int n = 200000;
    auto sum = compile("S 0" + repeat("+1", n) + "\n1: S -> sphere\nS");
    ASSERT_TRUE(sum->graph) << sum->errors().substr(0, 500);
    EXPECT_EQ(evalExpr(*sum->graph, sum->graph->modules[0].select, {nullptr, kRootPath}), n);
    auto un = compile("sphere" + repeat(" ∪ cube", n));
    ASSERT_TRUE(un->graph);
    EXPECT_EQ(un->graph->nodes[un->graph->axiom].childCount, static_cast<uint32_t>(n + 1));
    auto logic = compile("S 1" + repeat(" && 1", n) + "\n1: S -> sphere\nS");
    ASSERT_TRUE(logic->graph);
    EXPECT_EQ(evalExpr(*logic->graph, logic->graph->modules[0].select, {nullptr, kRootPath}), 1);
}

// --- recovery: several errors per run ---

TEST(Recovery, EachBadStatementIsReportedAndTheRestIsChecked) {
    auto c = compile(
        "S if(c > 0, 2, 1)\n"
        "1: S -> move(1,2,) sphere\n"  // syntax error
        "2: S -> {c = c - 1} S\n"
        "x = sphere ∪ ∪ cube\n"  // syntax error
        "T 1 +\n"                // syntax error at the end of the line... continues
        "1: T -> cone\n"
        "U 1\n"
        "1: U -> nothing\n"  // unknown name: a builder error
        "{c = 3} S ∪ U\n");
    EXPECT_FALSE(c->graph);
    const std::string e = c->errors();
    EXPECT_NE(e.find("t.pcsg:2:18: error: expected an expression, found ')'"), std::string::npos)
        << e;
    EXPECT_NE(e.find("t.pcsg:4:16: error: expected a primitive"), std::string::npos) << e;
    EXPECT_NE(e.find("t.pcsg:8:9: error: unknown module or definition 'nothing'"),
              std::string::npos)
        << e;
    // Echoes of the dropped statements are not reported: rule 1 of S is missing only
    // because its line failed to parse.
    EXPECT_EQ(e.find("has no rule 1"), std::string::npos) << e;
}

}  // namespace
}  // namespace pcsg
