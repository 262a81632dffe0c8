// The fast form of the expression code (fast_code.h): each instruction form gives the
// double the plain code gives, bit for bit, on ordinary and extreme values (NaN, the
// infinities, -0), and errors still come out as the plain code words them.
#include "fast_code.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "compile_test_util.h"
#include "eval.h"
#include "eval_core.h"
#include "raw_code_test_util.h"

namespace pcsg {
namespace {

using testing::addCode;

// Scenes whose C-node assigns r1, r2, ... the expressions under test (the axiom's sets x, y,
// z so that they compile, unfolded, so that they stay parameters; w is assigned on
// another path only).
std::unique_ptr<testing::Compiled> withExprs(const std::vector<std::string>& exprs) {
    std::string text = "{x = 1; y = 2; z = 3} ({";
    for (size_t i = 0; i < exprs.size(); ++i)
        text += "r" + std::to_string(i + 1) + " = " + exprs[i] + "; ";
    text += "} sphere ∪ {w = 0} cube)\n";
    auto c = testing::compileUnfolded(text);
    if (!c->graph) ADD_FAILURE() << c->errors();
    return c;
}

// The C-node that assigns r1.
uint32_t calcUnderTest(const Graph& g) {
    for (uint32_t i = 0; i < g.calcs.size(); ++i) {
        const Assignment& a = g.assignments[g.calcs[i].first];
        if (g.calcs[i].count && g.slotNames[a.slot] == "r1") return i;
    }
    ADD_FAILURE() << "no C-node assigns r1";
    return 0;
}

// The graph without its fast form: everything runs the plain code.
Graph plainOf(const Graph& g) {
    Graph p = g;
    dropFastCode(p);
    return p;
}

const double kInf = std::numeric_limits<double>::infinity();
const double kValues[] = {0,   -0.0, 1,     -1,      0.5,  2.5,   90,           -270,
                          360, 3,    1e300, -1e-300, kInf, -kInf, std::nan(""), 7.25};

// Fills every slot but w with values drawn from kValues.
void randomFrame(const Graph& g, std::mt19937& rng, std::vector<double>& frame) {
    frame.assign(g.slotCount(), 0);
    initFrame(g, frame.data());
    std::uniform_int_distribution<size_t> pick(0, std::size(kValues) - 1);
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] != "w") frame[s] = kValues[pick(rng)];
}

// A value's bits, every NaN as one: the sign and payload of a NaN made by an operation
// depend on the order in which the compiler puts the operands of + and *, which differs
// between the release and the sanitizer builds, in either machine; rand(x) reads every
// NaN as the same argument (FastCode.RandReadsEveryNanAsOne).
uint64_t bits(double v) {
    if (std::isnan(v)) v = std::numeric_limits<double>::quiet_NaN();
    return std::bit_cast<uint64_t>(v);
}

NodeId calcNodeUnderTest(const Graph& g) {
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        if (g.nodes[n].kind == NodeKind::Calc && g.nodes[n].payload == calcUnderTest(g)) return n;
    ADD_FAILURE() << "no C-node";
    return 0;
}

// Every expression of the C-node under test, and the C-node as a whole, evaluated fast and
// plain on many frames.
void expectSameValues(const Graph& g, int frames = 400) {
    const Graph plain = plainOf(g);
    const Calc& c = g.calcs.at(calcUnderTest(g));
    const NodeId node = calcNodeUnderTest(g);
    ASSERT_NE(c.fast, kNoFast);
    std::mt19937 rng(7);
    std::vector<double> frame;
    for (int k = 0; k < frames; ++k) {
        randomFrame(g, rng, frame);
        const EvalState s{frame.data(), pathChild(kRootPath, k)};
        for (uint32_t i = 0; i < c.count; ++i) {
            const ExprId e = g.assignments[c.first + i].value;
            ASSERT_NE(g.exprs[e].fast, kNoFast) << g.exprs[e].text;
            EXPECT_EQ(bits(evalExpr(g, e, s)), bits(evalExpr(plain, e, s)))
                << g.exprs[e].text << " with " << describeFrame(g, frame.data());
        }
        std::vector<double> fast(g.slotCount()), slow(g.slotCount());
        applyCalc(g, node, s, fast.data());
        applyCalc(plain, node, s, slow.data());
        for (Slot i = 0; i < g.slotCount(); ++i)
            EXPECT_EQ(bits(fast[i]), bits(slow[i])) << g.slotNames[i];
    }
}

TEST(FastCode, RandReadsEveryNanAsOne) {
    const double quiet = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const double made = inf - inf;  // on x86 the default NaN, with its sign bit set
    EXPECT_EQ(std::bit_cast<uint64_t>(randOf(7, -quiet)),
              std::bit_cast<uint64_t>(randOf(7, quiet)));
    EXPECT_EQ(std::bit_cast<uint64_t>(randOf(7, made)), std::bit_cast<uint64_t>(randOf(7, quiet)));
    EXPECT_NE(randOf(7, quiet), randOf(7, 1.0));
}

TEST(FastCode, EachBinaryFormGivesThePlainValue) {
    // For each operator: the left operand popped (both sides computed), a constant on the
    // right (left computed), a parameter on the right, and both leaves either way round.
    const char* ops[] = {"+", "-", "*", "/", "%", "^", "<", "<=", ">", ">=", "==", "!="};
    const char* names[] = {"Add", "Sub", "Mul", "Div", "Mod", "Pow",
                           "Lt",  "Le",  "Gt",  "Ge",  "Eq",  "Ne"};
    std::vector<std::string> exprs, forms;
    for (size_t i = 0; i < std::size(ops); ++i) {
        const std::string op = ops[i], name = names[i];
        exprs.insert(exprs.end(),
                     {"(x+y) " + op + " (y*z)", "(x*y) " + op + " 2", "(x*z) " + op + " y",
                      "2 " + op + " y", "y " + op + " 2", "z " + op + " x"});
        forms.insert(forms.end(), {"  " + name + "\n", "  " + name + "K 2\n", "  " + name + "L y\n",
                                   "  " + name + "KL 2 y\n", "  " + name + "LK y 2\n",
                                   "  " + name + "LL z x\n"});
    }
    const std::string last = "r" + std::to_string(exprs.size());
    exprs.push_back(last + " * 3");  // reads the slot the assignment before stored
    forms.push_back("StoreKeep " + last);
    auto c = withExprs(exprs);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    expectSameValues(g);
    const std::string dump = dumpFastCalc(g, calcUnderTest(g));
    for (const std::string& form : forms)
        EXPECT_NE(dump.find(form), std::string::npos) << form << " missing from\n" << dump;
}

TEST(FastCode, FunctionsBranchesAndTimeGiveThePlainValue) {
    const std::vector<std::string> exprs = {"sin(x)",
                                            "cos(x)",
                                            "tan(x)",
                                            "asin(x)",
                                            "acos(x)",
                                            "atan(x)",
                                            "sqrt(x)",
                                            "exp(x)",
                                            "ln(x)",
                                            "log10(x)",
                                            "abs(x)",
                                            "floor(x)",
                                            "ceil(x)",
                                            "rand(x)",
                                            "rand()",
                                            "atan2(x, y)",
                                            "pow(x, y)",
                                            "min(x, y, z)",
                                            "max(x, y)",
                                            "mod(x, y)",
                                            "clamp(x, y, z)",
                                            "if(x, y, z)",
                                            "x && y && z",
                                            "x || y || z",
                                            "!x",
                                            "-x",
                                            "clock + frame * x",
                                            "if(x > y, if(z, 1, y), -z) + 1",
                                            "((-ln(rand(x)*y+1.0))+z)*x",
                                            "choose(1, 2, 3)"};
    auto c = withExprs(exprs);
    ASSERT_TRUE(c->graph);
    expectSameValues(*c->graph);
    const std::string dump = dumpFastCalc(*c->graph, calcUnderTest(*c->graph));
    for (const char* form :
         {"Sin\n", "PowLL x y\n", "ModLL x y\n", "Ln\n", "Rand1\n", "PushRand0", "Call",
          "JumpIfZero", "Jump", "ToBool", "Not\n", "Neg\n", "PushClock", "PushFrame", "Choose"})
        EXPECT_NE(dump.find(form), std::string::npos) << form << " missing from\n" << dump;
}

TEST(FastCode, AnExpressionsFormIsLeafAndOperatorInOneInstruction) {
    auto c = withExprs({"((-ln(rand(x)*y+1.0))+z)*x"});
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const ExprId e = g.assignments[g.calcs[calcUnderTest(g)].first].value;
    EXPECT_EQ(dumpFastExpr(g, e),
              "   0  PushL x\n   1  Rand1\n   2  MulL y\n   3  AddK 1\n   4  Ln\n"
              "   5  Neg\n   6  AddL z\n   7  MulL x\n   8  End\n");
}

// The fast form of the i-th expression of the C-node under test.
std::string fastFormOf(const Graph& g, uint32_t i) {
    return dumpFastExpr(g, g.assignments[g.calcs[calcUnderTest(g)].first + i].value);
}

TEST(FastCode, ALoneLeafGivesItsValueAsTheMachineWould) {
    auto c = withExprs({"x", "2.5", "z"});
    ASSERT_TRUE(c->graph);
    expectSameValues(*c->graph);
    EXPECT_EQ(fastFormOf(*c->graph, 0), "   0  PushL x\n   1  End\n");
    EXPECT_EQ(fastFormOf(*c->graph, 1), "   0  PushK 2.5\n   1  End\n");
}

TEST(FastCode, ASumOfProductsAddsEachProductInOneInstruction) {
    auto c = withExprs({"x + 2*y + 3*z", "2*x + y*3 - 4*z", "(x + 2*y) * (1 + 3*z)"});
    ASSERT_TRUE(c->graph);
    expectSameValues(*c->graph);
    EXPECT_EQ(fastFormOf(*c->graph, 0),
              "   0  PushL x\n   1  AddMulKL 2 y\n   2  AddMulKL 3 z\n   3  End\n");
}

// The error a call gives, as text ("" when it gives none).
template <class F>
std::string errorOf(const Graph& g, F f) {
    try {
        f();
    } catch (const RuntimeError& e) {
        return e.format(g);
    }
    return "";
}

// Each assignment of the C-node under test, expression exprs[i], with every parameter but
// w (unassigned) at `value`: the fast machine stops where the plain code reports w, in
// the same words.
void expectEachReportsW(const Graph& g, const std::vector<std::string>& exprs, double value) {
    const Graph plain = plainOf(g);
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] != "w") frame[s] = value;
    const Calc& calc = g.calcs[calcUnderTest(g)];
    ASSERT_EQ(calc.count, exprs.size());
    for (uint32_t i = 0; i < calc.count; ++i) {
        const ExprId e = g.assignments[calc.first + i].value;
        const std::string fast = errorOf(g, [&] { evalExpr(g, e, {frame.data(), kRootPath}); });
        EXPECT_NE(fast.find("parameter 'w' is read before it is assigned"), std::string::npos)
            << exprs[i] << ": " << fast;
        EXPECT_EQ(fast, errorOf(plain, [&] { evalExpr(plain, e, {frame.data(), kRootPath}); }));
    }
}

TEST(FastCode, UnassignedReadsAreReportedAsThePlainCodeReportsThem) {
    // w is assigned only on another path: reading it here is the run-time error.
    auto c = withExprs({"x + 1", "y * w", "w", "2 - w", "1 + (x * w)"});
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const Graph plain = plainOf(g);
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    for (const char* name : {"x", "y", "z"})
        for (Slot s = 0; s < g.slotCount(); ++s)
            if (g.slotNames[s] == name) frame[s] = 2;
    const Calc& calc = g.calcs[calcUnderTest(g)];
    for (uint32_t i = 1; i < calc.count; ++i) {
        const ExprId e = g.assignments[calc.first + i].value;
        const std::string fast = errorOf(g, [&] { evalExpr(g, e, {frame.data(), kRootPath}); });
        EXPECT_NE(fast.find("parameter 'w' is read before it is assigned"), std::string::npos)
            << fast;
        EXPECT_EQ(fast, errorOf(plain, [&] { evalExpr(plain, e, {frame.data(), kRootPath}); }));
    }
    // the C-node as a whole: the same error, and the frame it fills is not half-written
    NodeId calcNode = kNone;
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        if (g.nodes[n].kind == NodeKind::Calc && g.nodes[n].payload == calcUnderTest(g))
            calcNode = n;
    ASSERT_NE(calcNode, kNone);
    std::vector<double> out(g.slotCount());
    const auto apply = [&](const Graph& gr) {
        return errorOf(gr, [&] { applyCalc(gr, calcNode, {frame.data(), kRootPath}, out.data()); });
    };
    const std::string fast = apply(g);
    EXPECT_NE(fast.find("'w'"), std::string::npos) << fast;
    EXPECT_EQ(fast, apply(plain));
}

TEST(FastCode, EachFormStopsAtAnUnassignedParameterWhateverItsOperatorGivesForIt) {
    // w (unassigned) in each leaf form of each operator: + - * / give a NaN for it and are
    // tested only when their value is one; the others can give a number (1 ^ w, w ^ 0,
    // w < x) and are tested always. Each must stop where the plain code reports w.
    const char* ops[] = {"+", "-", "*", "/", "%", "^", "<", "<=", ">", ">=", "==", "!="};
    std::vector<std::string> exprs;
    for (const std::string op : ops)
        exprs.insert(exprs.end(), {"(x*y) " + op + " w", "1 " + op + " w", "w " + op + " 0",
                                   "w " + op + " x", "x " + op + " w"});
    auto c = withExprs(exprs);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const std::string dump = dumpFastCalc(g, calcUnderTest(g));
    for (const char* form : {"PowL w\n", "PowKL 1 w\n", "PowLK w 0\n", "LtLL w x\n", "SubLL x w\n"})
        EXPECT_NE(dump.find(form), std::string::npos) << form << " missing from\n" << dump;
    expectEachReportsW(g, exprs, 1);
}

TEST(FastCode, ChooseWeightErrorsAreReportedAsThePlainCodeReportsThem) {
    auto c = withExprs({"choose(x, y)"});
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const Graph plain = plainOf(g);
    const ExprId e = g.assignments[g.calcs[calcUnderTest(g)].first].value;
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    const auto run = [&](const Graph& gr, double x, double y) {
        for (Slot s = 0; s < g.slotCount(); ++s) {
            if (g.slotNames[s] == "x") frame[s] = x;
            if (g.slotNames[s] == "y") frame[s] = y;
        }
        return errorOf(gr, [&] { evalExpr(gr, e, {frame.data(), kRootPath}); });
    };
    for (auto [x, y] : {std::pair{-1.0, 1.0}, {0.0, 0.0}, {kInf, 1.0}, {1.0, std::nan("")}}) {
        const std::string fast = run(g, x, y);
        EXPECT_NE(fast.find("choose() weight"), std::string::npos) << fast;
        EXPECT_EQ(fast, run(plain, x, y));
    }
    EXPECT_EQ(run(g, 1, 2), "");
}

TEST(FastCode, CodeTheMachineCannotRunStaysPlain) {
    Graph g;
    const ExprId two = addCode(g, {{Op::Const, 0, 0, 1}, {Op::Const, 0, 0, 2}}, 2);  // two values
    const ExprId none = addCode(g, {}, 0);
    const ExprId ok = addCode(g, {{Op::Const, 0, 0, 1}, {Op::Const, 0, 0, 2}, {Op::Sub}}, 2);
    buildFastCode(g);
    EXPECT_EQ(g.exprs[two].fast, kNoFast);
    EXPECT_EQ(g.exprs[none].fast, kNoFast);
    EXPECT_NE(g.exprs[ok].fast, kNoFast);
    EXPECT_EQ(evalExpr(g, two, {nullptr, kRootPath}), 2.0);
    EXPECT_TRUE(std::isnan(evalExpr(g, none, {nullptr, kRootPath})));
    EXPECT_EQ(evalExpr(g, ok, {nullptr, kRootPath}), -1.0);
    EXPECT_EQ(dumpFastExpr(g, two), "");
}

TEST(FastCode, SimultaneousCalcsReadTheIncomingFrame) {
    Graph g;
    const Slot a = g.slot("a"), b = g.slot("b");
    // {a = b + 1; b = a * 10}, in order and together
    const ExprId e1 = addCode(g, {{Op::Load, 0, b, 0}, {Op::Const, 0, 0, 1}, {Op::Add}}, 2);
    const ExprId e2 = addCode(g, {{Op::Load, 0, a, 0}, {Op::Const, 0, 0, 10}, {Op::Mul}}, 2);
    g.assignments = {{a, e1}, {b, e2}};
    g.calcs.push_back(Calc{0, 2, false});
    g.calcs.push_back(Calc{0, 2, true});
    const NodeId ordered = g.addNode(NodeKind::Calc, 0, {});
    const NodeId together = g.addNode(NodeKind::Calc, 1, {});
    buildFastCode(g);
    ASSERT_NE(g.calcs[0].fast, kNoFast);
    ASSERT_NE(g.calcs[1].fast, kNoFast);
    std::vector<double> in = {5, 1}, out(2);
    applyCalc(g, ordered, {in.data(), kRootPath}, out.data());
    EXPECT_EQ(out, (std::vector<double>{2, 20}));
    applyCalc(g, together, {in.data(), kRootPath}, out.data());
    EXPECT_EQ(out, (std::vector<double>{2, 50}));
    EXPECT_EQ(in, (std::vector<double>{5, 1}));
}

// T-nodes whose arguments are sums, products, a rand() and lone leaves; w is unassigned.
constexpr const char* kTransforms =
    "{x = 1; y = 2; z = 3} (move(x-y, 2*z+x, y) zshear(x-z, y*z) rot(x+1, y, 0, x*y)"
    " scale(x, y+z, 2+rand()) move(x, 0, y) sphere ∪ {w = 0} move(x*2, y-w, x) cube)\n";

// The graph whose T-nodes evaluate each argument alone, as they did before their programs.
Graph argumentsAlone(const Graph& g) {
    Graph a = g;
    for (Transform& t : a.transforms) t.fast = kNoFast;
    return a;
}

// A T-node's two matrices as bits, or the error it reports.
std::pair<std::string, std::vector<uint64_t>> pairOf(const Graph& g, NodeId n, EvalState s) {
    Affine f, i;
    std::pair<std::string, std::vector<uint64_t>> r;
    r.first = errorOf(g, [&] { transformPair(g, n, s, f, i); });
    for (const Affine* m : {&f, &i}) {
        for (const auto& row : m->l)
            for (double v : row) r.second.push_back(std::bit_cast<uint64_t>(v));
        for (double v : {m->t.x, m->t.y, m->t.z}) r.second.push_back(std::bit_cast<uint64_t>(v));
    }
    if (!r.first.empty()) r.second.clear();
    return r;
}

// A random argument: finite (zeros of both signs, subnormals, wide exponents) or, in one
// frame of eight, NaN or an infinity.
double randomArgument(std::mt19937_64& rng, bool nonFinite) {
    const double special[] = {0.0, -0.0, 1.0, -1.0, 4.9e-324, -1e-310, 1e300, kInf, std::nan("")};
    std::uniform_real_distribution<double> wide(-1e3, 1e3);
    if (rng() % 4 == 0) return special[rng() % (std::size(special) - (nonFinite ? 0 : 2))];
    return std::ldexp(wide(rng), static_cast<int>(rng() % 80) - 40);
}

TEST(FastCode, ATNodesArgumentsAsOneProgramGiveEachArgumentsValueBitForBit) {
    auto c = testing::compileUnfolded(kTransforms);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const Graph alone = argumentsAlone(g), plain = plainOf(g);
    std::vector<NodeId> nodes;
    size_t programs = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Transform) continue;
        nodes.push_back(n);
        programs += g.transforms[g.nodes[n].payload].fast != kNoFast;
    }
    ASSERT_EQ(nodes.size(), 6u);
    EXPECT_EQ(programs, 5u) << "move(x, 0, y) reads its leaves without a program";
    std::mt19937_64 rng(29);
    std::vector<double> frame(g.slotCount());
    size_t errors = 0;
    for (int k = 0; k < 4000; ++k) {
        initFrame(g, frame.data());
        for (Slot s = 0; s < g.slotCount(); ++s)
            if (g.slotNames[s] != "w") frame[s] = randomArgument(rng, k % 8 == 0);
        const EvalState s{frame.data(), pathChild(kRootPath, k)};
        for (NodeId n : nodes) {
            const auto fast = pairOf(g, n, s);
            errors += !fast.first.empty();
            ASSERT_EQ(fast, pairOf(alone, n, s)) << describeFrame(g, frame.data());
            ASSERT_EQ(fast, pairOf(plain, n, s)) << describeFrame(g, frame.data());
        }
    }
    EXPECT_GT(errors, 500u) << "the non-finite and unassigned arguments' errors are compared";
}

// A T-node of lone leaves has no program: its arguments are read without a call, and an
// unassigned or non-finite one is reported as the plain code reports it.
TEST(FastCode, ATNodesLoneLeavesAreReadOrReportedAsThePlainCodeDoes) {
    auto c = testing::compileUnfolded("{x = 1; y = 2} (move(x, w, 0) sphere ∪ {w = 0} cube)\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const Graph plain = plainOf(g);
    NodeId move = kNone;
    for (NodeId n = 0; n < g.nodes.size(); ++n)
        if (g.nodes[n].kind == NodeKind::Transform) move = n;
    ASSERT_NE(move, kNone);
    ASSERT_EQ(g.transforms[g.nodes[move].payload].fast, kNoFast);
    std::vector<double> frame(g.slotCount());
    const auto at = [&](const char* name) -> double& {
        return frame[std::find(g.slotNames.begin(), g.slotNames.end(), name) - g.slotNames.begin()];
    };
    size_t errors = 0;
    for (double x : {1.5, -0.0, kInf, -kInf, std::nan("")}) {
        for (bool assigned : {false, true}) {
            initFrame(g, frame.data());
            at("x") = x;
            if (assigned) at("w") = -2;
            const EvalState s{frame.data(), kRootPath};
            const auto got = pairOf(g, move, s);
            errors += !got.first.empty();
            EXPECT_EQ(got, pairOf(plain, move, s)) << x << " " << assigned;
            if (std::isfinite(x) && assigned) {
                EXPECT_EQ(got.second[9], std::bit_cast<uint64_t>(x));
            }
        }
    }
    EXPECT_EQ(errors, 8u) << "w unassigned, or x not finite";
}

TEST(FastCode, ATNodesProgramStoresEveryArgument) {
    auto c = testing::compileUnfolded(kTransforms);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    std::vector<double> frame(g.slotCount());
    initFrame(g, frame.data());
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] != "w") frame[s] = 1.5 + s;
    const EvalState s{frame.data(), kRootPath};
    size_t run = 0, stopped = 0;
    for (const Transform& t : g.transforms) {
        if (t.fast == kNoFast) continue;
        std::vector<double> out(t.argCount, std::nan("7"));
        double unused;
        if (!runFast(g, t.fast, frame.data(), out.data(), kRootPath, unused)) {
            ++stopped;  // move(x*2, y-w, x) reads the unassigned w
            continue;
        }
        ++run;
        for (uint32_t i = 0; i < t.argCount; ++i) {
            const ExprId e = g.args[t.firstArg + i];
            EXPECT_EQ(std::bit_cast<uint64_t>(out[i]), std::bit_cast<uint64_t>(evalExpr(g, e, s)))
                << "argument " << i << " '" << g.exprs[e].text << "' not stored";
        }
    }
    EXPECT_EQ(run, 4u);
    EXPECT_EQ(stopped, 1u);
}

// The graph with each fused instruction (fast_instr.h) back to the first of its run: the
// run's instructions one by one.
Graph unfusedOf(const Graph& g) {
    Graph u = g;
    for (FastInstr& f : u.fastCode) {
        if (f.op == FastOp::SumMulKL4) f.op = FastOp::MulKL;
        if (f.op == FastOp::RandLnChain) f.op = FastOp::Rand1;
        if (f.op == FastOp::MeanAddL) f.op = FastOp::AddLL;
    }
    return u;
}

TEST(FastCode, FusedRunsGiveTheBitsOfTheirInstructionsOneByOne) {
    // The terrain's C-node: a seed, the rnd of its rand() (reading the seed just stored),
    // a mean height plus rnd; then a mean that a jump enters after its first instruction.
    auto c =
        withExprs({"2.5*x + 3*y + 0.5*z + 7*x", "((-ln(rand(r1)*0.75+1.0))+0.125)*z",
                   "(x+y)/2.0 + r2", "(if(x, y+z, z+y))/2.0 + x", "((-ln(rand(x)*y+1.0))+0.5)*x"});
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    expectSameValues(g, 2000);  // the plain code's values
    const std::string dump = dumpFastCalc(g, calcUnderTest(g));
    for (const char* form : {"SumMulKL4 2.5 x\n", "RandLnChain\n", "MeanAddL x y\n",
                             "MeanAddL z y\n", "StoreKeep r1\n"})
        EXPECT_NE(dump.find(form), std::string::npos) << form << " missing from\n" << dump;
    EXPECT_EQ(dump.find("RandLnChain", dump.find("RandLnChain") + 1), std::string::npos)
        << "rand(x)*y is not the run's MulK\n"
        << dump;
    // the unfused instructions' bits, NaNs' signs and payloads included
    const Graph unfused = unfusedOf(g);
    const NodeId node = calcNodeUnderTest(g);
    std::mt19937 rng(11);
    std::vector<double> frame, fused(g.slotCount()), oneByOne(g.slotCount());
    for (int k = 0; k < 4000; ++k) {
        randomFrame(g, rng, frame);
        const EvalState s{frame.data(), pathChild(kRootPath, k)};
        applyCalc(g, node, s, fused.data());
        applyCalc(unfused, node, s, oneByOne.data());
        for (Slot i = 0; i < g.slotCount(); ++i)
            ASSERT_EQ(std::bit_cast<uint64_t>(fused[i]), std::bit_cast<uint64_t>(oneByOne[i]))
                << g.slotNames[i] << " with " << describeFrame(g, frame.data()) << "\n"
                << dump;
    }
}

TEST(FastCode, FusedRunsGiveTheBitsOfTheirInstructionsWithNansOfEverySignAndPayload) {
    // The fused runs compute their value plainly and only a NaN again with each
    // instruction's fix: operands that are NaNs of other signs and payloads, two or more in
    // one run, give the bits of the runs' instructions one by one.
    auto c = withExprs({"2.5*x + 3*y + 0.5*z + 7*x", "((-ln(rand(x)*0.75+1.0))+0.125)*y",
                        "(x+y)/2.0 + z", "(z+x)/2.0 + y"});
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const Graph unfused = unfusedOf(g);
    const std::string dump = dumpFastCalc(g, calcUnderTest(g));
    for (const char* form : {"SumMulKL4", "RandLnChain", "MeanAddL x y", "MeanAddL z x"})
        EXPECT_NE(dump.find(form), std::string::npos) << form << " missing from\n" << dump;
    const double nans[] = {std::bit_cast<double>(0x7ff8000000000001ull),
                           std::bit_cast<double>(0xfff8000000000002ull),
                           std::bit_cast<double>(0x7ff0000000000003ull),  // signalling
                           std::bit_cast<double>(0xfff800000000abcdull)};
    const double values[] = {nans[0], nans[1], nans[2], nans[3], 1.5, -2, kInf, -kInf, 0};
    const NodeId node = calcNodeUnderTest(g);
    std::vector<double> frame, fused(g.slotCount()), oneByOne(g.slotCount());
    int nanValues = 0;
    for (double x : values)
        for (double y : values)
            for (double z : values) {
                frame.assign(g.slotCount(), 0);
                initFrame(g, frame.data());
                for (Slot s = 0; s < g.slotCount(); ++s)
                    if (g.slotNames[s] == "x" || g.slotNames[s] == "y" || g.slotNames[s] == "z")
                        frame[s] = g.slotNames[s] == "x" ? x : g.slotNames[s] == "y" ? y : z;
                const EvalState s{frame.data(), kRootPath};
                applyCalc(g, node, s, fused.data());
                applyCalc(unfused, node, s, oneByOne.data());
                for (Slot i = 0; i < g.slotCount(); ++i) {
                    ASSERT_EQ(std::bit_cast<uint64_t>(fused[i]),
                              std::bit_cast<uint64_t>(oneByOne[i]))
                        << g.slotNames[i] << " with " << describeFrame(g, frame.data()) << "\n"
                        << dump;
                    nanValues += std::isnan(fused[i]);
                }
            }
    EXPECT_GT(nanValues, 1000);
}

TEST(FastCode, FusedRunsReportUnassignedReadsAsThePlainCodeDoes) {
    // w (assigned on another path only) read at each place of each run
    const std::vector<std::string> exprs = {"2*w + 3*y + 4*z + 5*x",
                                            "2*x + 3*w + 4*z + 5*x",
                                            "2*x + 3*y + 4*w + 5*x",
                                            "2*x + 3*y + 4*z + 5*w",
                                            "((-ln(rand(x)*2+1.0))+0.5)*w",
                                            "(w+y)/2.0 + z",
                                            "(x+w)/2.0 + z",
                                            "(x+y)/2.0 + w"};
    auto c = withExprs(exprs);
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    EXPECT_NE(dumpFastCalc(g, calcUnderTest(g)).find("SumMulKL4"), std::string::npos);
    expectEachReportsW(g, exprs, 0.25);
}

TEST(FastCode, RecalledRandLnChainsAreKeyedByTheirSeedAndConstants) {
    // Three rnd chains of the same sd with other constants, in a graph and in its copy with
    // another seed: each run recalls (a few values of x, many times) only what the same
    // seed and constants gave, bit for bit the plain code's value.
    auto c = withExprs({"((-ln(rand(x)*0.75+1.0))+0.125)*z", "((-ln(rand(x)*0.5+1.0))+0.125)*z",
                        "((-ln(rand(x)*0.75+2.0))+0.125)*z"});
    ASSERT_TRUE(c->graph);
    Graph other = *c->graph;
    other.scene.settings.seed = c->graph->scene.settings.seed + 1;
    const Graph* graphs[] = {&*c->graph, &other};
    const Graph plains[] = {plainOf(*c->graph), plainOf(other)};
    const NodeId node = calcNodeUnderTest(other);
    const auto slotOf = [&](const char* name) {
        return static_cast<Slot>(std::find(other.slotNames.begin(), other.slotNames.end(), name) -
                                 other.slotNames.begin());
    };
    const Slot x = slotOf("x"), z = slotOf("z");
    std::vector<double> frame, fast(other.slotCount()), slow(other.slotCount());
    std::set<uint64_t> values;
    for (int k = 0; k < 600; ++k) {
        const Graph& g = *graphs[k % 2];
        frame.assign(g.slotCount(), 0);
        initFrame(g, frame.data());
        frame[x] = 0.5 * (k / 2 % 5) - 1, frame[z] = 1.5;
        const EvalState s{frame.data(), kRootPath};
        applyCalc(g, node, s, fast.data());
        applyCalc(plains[k % 2], node, s, slow.data());
        for (Slot i = 0; i < g.slotCount(); ++i)
            ASSERT_EQ(std::bit_cast<uint64_t>(fast[i]), std::bit_cast<uint64_t>(slow[i]))
                << g.slotNames[i] << " of graph " << k % 2 << " with x = " << frame[x];
        for (const char* r : {"r1", "r2", "r3"})
            values.insert(std::bit_cast<uint64_t>(fast[slotOf(r)]));
    }
    EXPECT_EQ(values.size(), 2u * 5u * 3u);  // each seed, x and chain its own value
}

TEST(FastCode, TwoLeavesAndTheirOperatorStoreWithoutTheStoresDispatch) {
    // Each form that spills acc, then a Store (done by the form); a jump that lands on the
    // Store after a SubLL (if's else branch), and a value read from the slot just stored.
    auto c = withExprs({"x-y", "2*z", "y/4", "if(x, z, y-z)", "x-z", "r5+y", "x<z", "x^y", "3%z"});
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    const std::string dump = dumpFastCalc(g, calcUnderTest(g));
    for (const char* form : {"SubLL x y\n   1  Store r1\n", "MulKL 2 z\n   3  Store r2\n",
                             "DivLK y 4\n   5  Store r3\n", "SubLL y z\n  11  Store r4\n",
                             "SubLL x z\n  13  StoreKeep r5\n"})
        EXPECT_NE(dump.find(form), std::string::npos) << form << " missing from\n" << dump;
    expectSameValues(g, 2000);
    // each slot stored once, with its own value
    std::vector<double> frame(g.slotCount()), out(g.slotCount(), std::nan("5"));
    initFrame(g, frame.data());
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] != "w") frame[s] = 1.5 + s;
    double unused;
    ASSERT_TRUE(
        runFast(g, g.calcs[calcUnderTest(g)].fast, frame.data(), out.data(), kRootPath, unused));
    const EvalState s{frame.data(), kRootPath};
    for (uint32_t i = 0; i < 9; ++i) {
        const Assignment& as = g.assignments[g.calcs[calcUnderTest(g)].first + i];
        if (i == 5) continue;  // r5+y reads r5 as stored, not from `frame`
        EXPECT_EQ(std::bit_cast<uint64_t>(out[as.slot]),
                  std::bit_cast<uint64_t>(evalExpr(g, as.value, s)))
            << g.slotNames[as.slot] << "\n"
            << dump;
    }
}

TEST(FastCode, ChangingTheCodeDropsTheFastForm) {
    auto c = withExprs({"x + 1"});
    ASSERT_TRUE(c->graph);
    Graph g = *c->graph;
    EXPECT_FALSE(g.fastCode.empty());
    dropFastCode(g);
    EXPECT_TRUE(g.fastCode.empty());
    for (const Expr& e : g.exprs) EXPECT_EQ(e.fast, kNoFast);
    for (const Calc& k : g.calcs) EXPECT_EQ(k.fast, kNoFast);
    for (const Transform& t : g.transforms) EXPECT_EQ(t.fast, kNoFast);
}

}  // namespace
}  // namespace pcsg
