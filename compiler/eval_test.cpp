// Tests of the shared evaluation code on hand-built graphs.
#include "eval.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "eval_core.h"
#include "raw_code_test_util.h"

namespace pcsg {
namespace {

using testing::addCode;

std::vector<double> frameOf(const Graph& g) {
    std::vector<double> f(g.slotCount());
    initFrame(g, f.data());
    return f;
}

TEST(Eval, ArithmeticPrecedenceIsTheCodeOrder) {
    Graph g;
    // (2 + 3) * 4 ^ 2 = 80
    const ExprId e = addCode(g,
                             {{Op::Const, 0, 0, 2},
                              {Op::Const, 0, 0, 3},
                              {Op::Add},
                              {Op::Const, 0, 0, 4},
                              {Op::Const, 0, 0, 2},
                              {Op::Pow},
                              {Op::Mul}},
                             3);
    EXPECT_DOUBLE_EQ(evalExpr(g, e, {nullptr, kRootPath}), 80.0);
}

TEST(Eval, TrigonometryIsInDegreesAndExactAtRightAngles) {
    Graph g;
    auto call = [&](Func f, std::vector<double> args) {
        std::vector<Instr> code;
        for (double a : args) code.push_back({Op::Const, 0, 0, a});
        code.push_back({Op::Call, static_cast<uint8_t>(args.size()), static_cast<uint32_t>(f), 0});
        return evalExpr(g, addCode(g, code, static_cast<uint32_t>(args.size())),
                        {nullptr, kRootPath});
    };
    EXPECT_EQ(call(Func::Sin, {90}), 1.0);
    EXPECT_EQ(call(Func::Cos, {90}), 0.0);
    EXPECT_EQ(call(Func::Sin, {180}), 0.0);
    EXPECT_NEAR(call(Func::Sin, {30}), 0.5, 1e-15);
    EXPECT_NEAR(call(Func::Atan2, {1, 1}), 45.0, 1e-12);
    EXPECT_NEAR(call(Func::Asin, {1}), 90.0, 1e-12);
    EXPECT_EQ(call(Func::Min, {3, -1, 2}), -1.0);
    EXPECT_EQ(call(Func::Max, {3, -1, 2}), 3.0);
    EXPECT_EQ(call(Func::Clamp, {5, 0, 2}), 2.0);
    EXPECT_TRUE(std::isnan(call(Func::Sqrt, {-1})));
}

// sinDegrees, powRecalled and lnRecalled recall the values they computed last (per thread,
// by the arguments' bits): every value must be the one computed for those arguments, also
// after other arguments took its slot.
TEST(Eval, RecalledValuesAreTheComputedOnesBitForBit) {
    auto computed = [](double a) {
        const double r = std::fmod(a, 360.0);
        if (r == 0 || r == 180 || r == -180) return 0.0;
        if (r == 90 || r == -270) return 1.0;
        if (r == -90 || r == 270) return -1.0;
        return std::sin(a * (3.14159265358979323846 / 180.0));
    };
    auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    // A terrain's corners (180 k / 512), more values than the memo has slots, -0, and
    // values that differ in their last bit.
    std::vector<double> angles;
    for (int k = 0; k <= 4096; ++k) angles.push_back(180.0 * (k / 512.0));
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1000.0, 1000.0);
    for (int k = 0; k < 3000; ++k) angles.push_back(u(rng));
    for (double a : {-0.0, 0.0, 90.0, std::nextafter(90.0, 100.0), -270.0, 1e300})
        angles.push_back(a);
    for (int round = 0; round < 3; ++round) {
        for (double a : angles) {
            ASSERT_TRUE(same(sinDegrees(a), computed(a))) << "angle " << a;
            ASSERT_TRUE(same(cosDegrees(a), computed(a + 90.0))) << "angle " << a;
            const double x = std::fabs(a) / 1000, y = a / 997;
            ASSERT_TRUE(same(powRecalled(x, 0.3), std::pow(x, 0.3))) << "pow " << x;
            ASSERT_TRUE(same(powRecalled(x, y), std::pow(x, y))) << "pow " << x << ", " << y;
            ASSERT_TRUE(same(powRecalled(y, 0.3), std::pow(y, 0.3))) << "pow " << y;  // NaN < 0
            ASSERT_TRUE(same(lnRecalled(x), std::log(x))) << "ln " << x;
            ASSERT_TRUE(same(lnRecalled(y), std::log(y))) << "ln " << y;
        }
        std::shuffle(angles.begin(), angles.end(), rng);
    }
    EXPECT_TRUE(same(powRecalled(0.0, 0.0), 1.0));  // the value every slot starts with
    EXPECT_TRUE(same(lnRecalled(0.0), -HUGE_VAL));
}

TEST(Eval, JumpsEvaluateOnlyTheBranchTaken) {
    Graph g;
    const Slot x = g.slot("x");  // never assigned: reading it would throw
    // if(0, x, 5)
    const ExprId e = addCode(g,
                             {{Op::Const, 0, 0, 0},
                              {Op::JumpIfZero, 0, 4, 0},
                              {Op::Load, 0, x, 0},
                              {Op::Jump, 0, 5, 0},
                              {Op::Const, 0, 0, 5}},
                             1);
    auto f = frameOf(g);
    EXPECT_EQ(evalExpr(g, e, {f.data(), kRootPath}), 5.0);
}

TEST(Eval, ReadingAnUnassignedParameterIsARuntimeError) {
    Graph g;
    const Slot c = g.slot("c");
    const ExprId e = g.addLoad(c, {0, 4, 9});
    auto f = frameOf(g);
    try {
        evalExpr(g, e, {f.data(), kRootPath});
        FAIL() << "expected a RuntimeError";
    } catch (const RuntimeError& err) {
        EXPECT_NE(err.message.find("'c'"), std::string::npos) << err.message;
        EXPECT_EQ(err.loc.line, 4u);
    }
    f[c] = 3;
    EXPECT_EQ(evalExpr(g, e, {f.data(), kRootPath}), 3.0);
}

// A one-module graph: S if(c > 0, 2, 1) with two sphere rules, for selection tests.
struct OneModule {
    Graph g;
    NodeId s;
    Slot c;
    OneModule(bool notationB) {
        c = g.slot("c");
        g.materials.push_back(Material{});
        Primitive sphere;
        sphere.kind = PrimitiveKind::Sphere;
        g.primitives.push_back(sphere);
        const NodeId leaf = g.addNode(NodeKind::Primitive, 0, {});
        Module m;
        m.name = "S";
        m.loc = {0, 2, 1};
        if (notationB) {
            m.notationB = true;
            // c > 0 , then c == 0
            m.conditions.push_back(
                addCode(g, {{Op::Load, 0, c, 0}, {Op::Const, 0, 0, 0}, {Op::Gt}}, 2));
            m.conditions.push_back(
                addCode(g, {{Op::Load, 0, c, 0}, {Op::Const, 0, 0, 0}, {Op::Eq}}, 2));
        } else {
            m.select = g.addLoad(c);  // the rule number is c itself
        }
        g.modules.push_back(m);
        s = g.addNode(NodeKind::Select, 0, {leaf, leaf});
        g.modules[0].node = s;
    }
};

TEST(Eval, NotationASelectsTheRoundedRuleNumber) {
    OneModule m(false);
    auto f = frameOf(m.g);
    f[m.c] = 1.2;
    EXPECT_EQ(selectRule(m.g, m.s, {f.data(), kRootPath}), 0u);
    f[m.c] = 1.6;
    EXPECT_EQ(selectRule(m.g, m.s, {f.data(), kRootPath}), 1u);
}

TEST(Eval, NotationASelectionOutOfRangeNamesModuleAndValue) {
    OneModule m(false);
    auto f = frameOf(m.g);
    f[m.c] = 3;
    try {
        selectRule(m.g, m.s, {f.data(), kRootPath});
        FAIL();
    } catch (const RuntimeError& e) {
        EXPECT_NE(e.message.find("module S gave rule 3"), std::string::npos) << e.message;
        EXPECT_NE(e.message.find("1..2"), std::string::npos) << e.message;
    }
    f[m.c] = std::nan("");
    EXPECT_THROW(selectRule(m.g, m.s, {f.data(), kRootPath}), RuntimeError);
}

TEST(Eval, NotationBTakesTheFirstRuleWhoseConditionHolds) {
    OneModule m(true);
    auto f = frameOf(m.g);
    f[m.c] = 2;
    EXPECT_EQ(selectRule(m.g, m.s, {f.data(), kRootPath}), 0u);
    f[m.c] = 0;
    EXPECT_EQ(selectRule(m.g, m.s, {f.data(), kRootPath}), 1u);
    f[m.c] = -1;
    try {
        selectRule(m.g, m.s, {f.data(), kRootPath});
        FAIL();
    } catch (const RuntimeError& e) {
        EXPECT_NE(e.message.find("no rule of module S applies"), std::string::npos);
        EXPECT_NE(e.message.find("c = -1"), std::string::npos) << e.message;
    }
}

TEST(Eval, OrderedCalcSeesEarlierAssignmentsSimultaneousDoesNot) {
    Graph g;
    const Slot a = g.slot("a"), b = g.slot("b");
    // {a = b + 1; b = a * 10}
    const ExprId e1 = addCode(g, {{Op::Load, 0, b, 0}, {Op::Const, 0, 0, 1}, {Op::Add}}, 2);
    const ExprId e2 = addCode(g, {{Op::Load, 0, a, 0}, {Op::Const, 0, 0, 10}, {Op::Mul}}, 2);
    g.assignments = {{a, e1}, {b, e2}};
    g.calcs.push_back(Calc{0, 2, false});
    g.calcs.push_back(Calc{0, 2, true});
    const NodeId ordered = g.addNode(NodeKind::Calc, 0, {});
    const NodeId together = g.addNode(NodeKind::Calc, 1, {});
    std::vector<double> in = {5, 1}, out(2);
    applyCalc(g, ordered, {in.data(), kRootPath}, out.data());
    EXPECT_EQ(out[a], 2.0);
    EXPECT_EQ(out[b], 20.0);
    applyCalc(g, together, {in.data(), kRootPath}, out.data());
    EXPECT_EQ(out[a], 2.0);
    EXPECT_EQ(out[b], 50.0);
    EXPECT_EQ(in[a], 5.0) << "the incoming frame is never changed";
}

// The bits of a matrix's twelve doubles (== would take -0 for +0).
std::vector<uint64_t> bitsOf(const Affine& m) {
    std::vector<uint64_t> b;
    for (const auto& row : m.l)
        for (double v : row) b.push_back(std::bit_cast<uint64_t>(v));
    for (double v : {m.t.x, m.t.y, m.t.z}) b.push_back(std::bit_cast<uint64_t>(v));
    return b;
}

TEST(Eval, MoveAndZShearInversesAreTheGeneralInversesBitForBit) {
    std::mt19937_64 rng(13);
    const double special[] = {0.0, -0.0, 1.0, -1.0, 0.5, -3.25, 1e-300, -4.9e-324, 1e300};
    std::uniform_real_distribution<double> wide(-1e3, 1e3);
    const auto arg = [&]() {
        const uint64_t pick = rng() % 4;
        if (pick == 0) return special[rng() % std::size(special)];
        if (pick == 1) return std::ldexp(wide(rng), static_cast<int>(rng() % 200) - 100);
        return wide(rng);
    };
    size_t signedZeros = 0;
    for (int i = 0; i < 20000; ++i) {
        const double a[3] = {arg(), arg(), arg()};
        for (TransformOp op : {TransformOp::Move, TransformOp::ZShear}) {
            const Affine m = makeTransform(op, a);
            const Affine direct = inverseOf(op, a, m);
            ASSERT_EQ(bitsOf(direct), bitsOf(m.inverse()))
                << "op " << static_cast<int>(op) << " args " << a[0] << " " << a[1] << " " << a[2];
            for (uint64_t b : bitsOf(direct)) signedZeros += b == (uint64_t{1} << 63);
        }
    }
    EXPECT_GT(signedZeros, 1000u) << "the arguments reach the inverses' negative zeros";
    const double rot[] = {30};
    const Affine r = makeTransform(TransformOp::RotZ, rot);
    EXPECT_EQ(bitsOf(inverseOf(TransformOp::RotZ, rot, r)), bitsOf(r.inverse()));
}

TEST(Eval, TransformsFollowTheLanguageTable) {
    const double ninety[] = {90};
    EXPECT_EQ(makeTransform(TransformOp::RotZ, ninety).point({1, 0, 0}), (Vec3{0, 1, 0}));
    EXPECT_EQ(makeTransform(TransformOp::RotX, ninety).point({0, 1, 0}), (Vec3{0, 0, 1}));
    EXPECT_EQ(makeTransform(TransformOp::RotY, ninety).point({0, 0, 1}), (Vec3{1, 0, 0}));
    const double shear[] = {2, 3};
    EXPECT_EQ(makeTransform(TransformOp::ZShear, shear).point({1, 1, 1}), (Vec3{1, 1, 6}));
    EXPECT_EQ(makeTransform(TransformOp::FlipXZ, nullptr).point({1, 2, 3}), (Vec3{1, -2, 3}));
    EXPECT_EQ(makeTransform(TransformOp::FlipYZ, nullptr).point({1, 2, 3}), (Vec3{-1, 2, 3}));
    EXPECT_EQ(makeTransform(TransformOp::FlipXY, nullptr).point({1, 2, 3}), (Vec3{1, 2, -3}));
    const double rot[] = {0, 0, 2, 90};
    const Vec3 p = makeTransform(TransformOp::Rot, rot).point({1, 0, 0});
    EXPECT_NEAR(p.x, 0, 1e-15);
    EXPECT_NEAR(p.y, 1, 1e-15);
    // matrix(): p·M + t with M's rows as written.
    const double m[] = {1, 2, 3, 4, 5, 6, 7, 8, 10, 0.5, 0.25, 0.125};
    const Vec3 q = makeTransform(TransformOp::Matrix, m).point({1, 1, 0});
    EXPECT_EQ(q, (Vec3{1 + 4 + 0.5, 2 + 5 + 0.25, 3 + 6 + 0.125}));
}

TEST(Eval, AffineInverseAndComposition) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-2, 2);
    for (int i = 0; i < 100; ++i) {
        Affine a;
        for (auto& row : a.l)
            for (double& v : row) v = u(rng);
        a.t = {u(rng), u(rng), u(rng)};
        if (std::fabs(a.determinant()) < 1e-3) continue;
        const Affine id = a * a.inverse();
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(id.l[r][c], r == c ? 1.0 : 0.0, 1e-9);
        EXPECT_NEAR(length(id.t), 0, 1e-9);
    }
}

TEST(Eval, ZeroScaleIsARuntimeError) {
    Graph g;
    const Slot f = g.slot("f");
    const ExprId e = g.addLoad(f);
    g.args = {e};
    g.transforms.push_back(Transform{TransformOp::UScale, 0, 1, false, {}});
    const NodeId t = g.addNode(NodeKind::Transform, 0, {});
    double frame[1] = {0};
    EXPECT_THROW(transformMatrix(g, t, {frame, kRootPath}), RuntimeError);
    frame[0] = 0.5;
    EXPECT_EQ(transformMatrix(g, t, {frame, kRootPath}).l[1][1], 0.5);
    frame[0] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(transformMatrix(g, t, {frame, kRootPath}), RuntimeError);
}

// move() and zshear() of parameters take their own path in transformMatrix and
// transformPair (no singularity test, no makeTransform call): the matrices must be the ones
// the language table gives, their inverses the general inverse's, bit for bit (signed
// zeros included), and a non-finite argument must still be the run-time error.
TEST(Eval, ParameterMoveAndZShearAreTheTablesMatricesBitForBit) {
    Graph g;
    const Slot x = g.slot("x"), y = g.slot("y"), z = g.slot("z");
    g.args = {g.addLoad(x), g.addLoad(y), g.addLoad(z)};
    g.transforms.push_back(Transform{TransformOp::Move, 0, 3, false, {}});
    g.transforms.push_back(Transform{TransformOp::ZShear, 1, 2, false, {}});
    const NodeId move = g.addNode(NodeKind::Transform, 0, {});
    const NodeId shear = g.addNode(NodeKind::Transform, 1, {});
    const double values[][3] = {{0.5, -2, 3}, {-0.0, 0.0, -0.0}, {1e300, -4.9e-324, 7}};
    for (const auto& v : values) {
        double frame[3] = {v[0], v[1], v[2]};
        Affine moved = Affine::identity(), sheared = Affine::identity();
        moved.t = {v[0], v[1], v[2]};
        sheared.l[2][0] = v[1], sheared.l[2][1] = v[2];
        for (const auto& [n, want] : {std::pair{move, moved}, std::pair{shear, sheared}}) {
            const EvalState s{frame, kRootPath};
            EXPECT_EQ(bitsOf(transformMatrix(g, n, s)), bitsOf(want)) << v[0] << " " << v[1];
            Affine forward, inverse;
            transformPair(g, n, s, forward, inverse);
            EXPECT_EQ(bitsOf(forward), bitsOf(want));
            EXPECT_EQ(bitsOf(inverse), bitsOf(want.inverse()));
        }
    }
    double frame[3] = {1, 2, std::numeric_limits<double>::infinity()};
    for (NodeId n : {move, shear}) {
        Affine forward, inverse;
        EXPECT_THROW(transformMatrix(g, n, {frame, kRootPath}), RuntimeError);
        EXPECT_THROW(transformPair(g, n, {frame, kRootPath}, forward, inverse), RuntimeError);
    }
}

TEST(Eval, RandomnessIsPureAndUniform) {
    EXPECT_EQ(randOf(1, 0.25), randOf(1, 0.25));
    EXPECT_EQ(randOf(1, 0.0), randOf(1, -0.0));
    EXPECT_NE(randOf(1, 0.25), randOf(2, 0.25)) << "the seed changes rand(x)";
    EXPECT_EQ(randAt(3, 99, 1), randAt(3, 99, 1));
    EXPECT_NE(randAt(3, 99, 1), randAt(3, 99, 2));
    // Distinct instance paths: child indices and rule indices never collide in practice.
    std::set<uint64_t> paths;
    uint64_t p = kRootPath;
    for (uint32_t depth = 0; depth < 8; ++depth) {
        for (uint32_t i = 0; i < 4; ++i) {
            paths.insert(pathChild(p, i));
            paths.insert(pathRule(p, i));
        }
        p = pathChild(pathRule(p, 1), depth % 4);
    }
    EXPECT_EQ(paths.size(), 64u);
    // Uniform in [0,1): mean and bounds over many draws.
    double sum = 0;
    for (int i = 0; i < 100000; ++i) {
        const double r = randAt(5, pathChild(kRootPath, i), 0);
        ASSERT_GE(r, 0.0);
        ASSERT_LT(r, 1.0);
        sum += r;
    }
    EXPECT_NEAR(sum / 100000, 0.5, 0.01);
}

TEST(Eval, ChooseFollowsTheWeights) {
    Graph g;
    // choose(0.6, 0.4), call site 0
    const ExprId e =
        addCode(g, {{Op::Const, 0, 0, 0.6}, {Op::Const, 0, 0, 0.4}, {Op::Choose, 2, 0, 0}}, 2);
    int first = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        const double r = evalExpr(g, e, {nullptr, pathChild(kRootPath, i)});
        ASSERT_TRUE(r == 1 || r == 2);
        first += r == 1;
    }
    EXPECT_NEAR(first / double(n), 0.6, 0.02);
}

TEST(Eval, MaxDepthIsReportedWithTheModuleAndDepth) {
    OneModule m(false);
    m.g.scene.settings.maxDepth = 10;
    auto f = frameOf(m.g);
    f[m.c] = 2;
    EXPECT_NO_THROW(checkDepth(m.g, m.s, 10, {f.data(), kRootPath}));
    try {
        checkDepth(m.g, m.s, 11, {f.data(), kRootPath});
        FAIL();
    } catch (RuntimeError& e) {
        EXPECT_NE(e.message.find("module S reached depth 11"), std::string::npos) << e.message;
        EXPECT_NE(e.message.find("c = 2"), std::string::npos) << e.message;
        e.enterModule("S");
        e.enterModule("S");
        e.enterModule("T");
        m.g.files.push_back("x.pcsg");
        EXPECT_EQ(e.format(m.g),
                  "x.pcsg:2:1: error: " + e.message + "\n  module path: T -> S (x2)");
    }
}

}  // namespace
}  // namespace pcsg
