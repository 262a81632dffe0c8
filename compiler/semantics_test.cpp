// Semantics::enter: a forward-only T-step gives the walker's matrix and no inverse.
#include "semantics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "compile_test_util.h"
#include "step_memo.h"

namespace pcsg {
namespace {

using testing::compileUnfolded;

bool sameAffine(const Affine& a, const Affine& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// T-nodes whose matrices depend on parameters (a and b), one constant chain (scale, move).
constexpr const char* kScene = R"(
{a = 2; b = 3} S
S 1
1: S -> rotx(a*30) uscale(1 + b/10) sphere ∪ move(a, b, 1) scale(1, 2, 3) move(0, 1, 0) cube
)";

// The scene's graph with a = 2, b = 3 in the root frame, its semantics and a step memo.
struct Steps {
    explicit Steps(const Graph& g) : sem(g), plan(g), memo(g, plan), frame(g.slotCount(), 0.0) {
        for (size_t k = 0; k < g.slotCount(); ++k) frame[k] = g.slotNames[k] == "a" ? 2.0 : 3.0;
        s = PathState{frame.data(), kRootPath, 1, 0};
    }
    const Semantics sem;
    const StepMemoPlan plan;
    StepMemo memo;
    std::vector<double> frame;
    PathState s;
};

// Every T-step of the scene taken forward-only and in full, with and without a memo.
TEST(Semantics, AForwardOnlyStepSkipsTheInverseUnlessAMemoHasIt) {
    auto c = compileUnfolded(kScene);  // (folded, a and b would be constants)
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    Steps t(g);
    int computed = 0, fused = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Transform) continue;
        SCOPED_TRACE(::testing::Message() << "node " << n);
        StepScratch full, forward, remembered;
        forward.forwardOnly = remembered.forwardOnly = true;
        remembered.memo = &t.memo;
        const Step a = t.sem.enter(n, t.s, full), b = t.sem.enter(n, t.s, forward),
                   m = t.sem.enter(n, t.s, remembered);
        ASSERT_TRUE(a.forward && a.inverse && b.forward && m.forward && m.inverse);
        EXPECT_TRUE(sameAffine(*a.forward, *b.forward));
        EXPECT_TRUE(sameAffine(*a.forward, *m.forward));
        EXPECT_TRUE(sameAffine(*a.inverse, *m.inverse));
        EXPECT_EQ(a.child, b.child);
        if (g.transforms[g.nodes[n].payload].constant) {
            ++fused;  // a fused chain's inverse is computed once, up front: it stays
            EXPECT_TRUE(b.inverse && sameAffine(*a.inverse, *b.inverse));
        } else {
            ++computed;
            EXPECT_TRUE(sameAffine(*a.inverse, a.forward->inverse()));
            EXPECT_EQ(b.inverse, nullptr);
        }
    }
    EXPECT_EQ(computed, 3);
    EXPECT_EQ(fused, 2);
}

// StepScratch's room is left unwritten by emplace(): a T-step must write its matrices whole.
// The room is filled with NaNs first; every step, from the graph and from the memo (a miss,
// then a hit), gives exactly the matrices of the T-node.
TEST(Semantics, ATStepWritesItsMatricesWholeOverWhatTheRoomHeld) {
    auto c = compileUnfolded(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    Steps t(g);
    auto soiled = [](StepScratch& scratch) {
        StepScratch::Matrices& m = scratch.matrices.emplace();
        std::fill_n(&m.forward.l[0][0], 9, std::nan(""));
        std::fill_n(&m.inverse.l[0][0], 9, std::nan(""));
        m.forward.t = m.inverse.t = {std::nan(""), std::nan(""), std::nan("")};
    };
    int checked = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Transform || g.transforms[g.nodes[n].payload].constant)
            continue;
        SCOPED_TRACE(::testing::Message() << "node " << n);
        const Affine forward = transformMatrix(g, n, EvalState{t.frame.data(), kRootPath});
        const Affine inverse = forward.inverse();
        for (int pass = 0; pass < 3; ++pass) {  // the graph; the memo's miss; its hit
            StepScratch scratch;
            if (pass > 0) scratch.memo = &t.memo;
            soiled(scratch);
            const Step st = t.sem.enter(n, t.s, scratch);
            ASSERT_TRUE(st.forward && st.inverse);
            EXPECT_TRUE(sameAffine(*st.forward, forward));
            EXPECT_TRUE(sameAffine(*st.inverse, inverse));
            ++checked;
        }
    }
    EXPECT_EQ(checked, 9);
}

// fromIdentity is forwardThrough(identity) bit for bit, and the step's own matrix (no copy)
// where that is exact: at a parameter T-node, matrices with -0, an infinity or a NaN (whose
// products with the identity differ from them) are multiplied, a plain one is not; a fused
// chain's matrix is taken as it is.
TEST(Semantics, FromIdentityIsTheProductWithTheIdentityBitForBit) {
    auto c = compileUnfolded(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    Steps t(g);
    NodeId param = kNone, chain = kNone;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Transform) continue;
        NodeId& which = g.transforms[g.nodes[n].payload].constant ? chain : param;
        if (which == kNone) which = n;
    }
    ASSERT_NE(param, kNone);
    ASSERT_NE(chain, kNone);
    const double inf = std::numeric_limits<double>::infinity();
    const Affine minusZero = Affine::translate({-0.0, 1, 2}), infinite = Affine::scale({2, inf, 1}),
                 notANumber = Affine::translate({1, std::nan(""), 3}),
                 plain = Affine::translate({1, 2, 3}) * Affine::scale({2, -1, 0.5});
    const Affine* const differing[] = {&minusZero, &infinite, &notANumber};
    for (int k = 0; k < 3; ++k) {
        SCOPED_TRACE(::testing::Message() << "matrix " << k);
        const Affine* m = differing[k];
        Step st;
        st.forward = m;
        Affine room;
        const Affine& w = t.sem.fromIdentity(param, st, room);
        const Affine product = t.sem.forwardThrough(Affine::identity(), param, st);
        EXPECT_FALSE(sameAffine(product, *m));  // (the case is one where the product differs)
        EXPECT_TRUE(sameAffine(w, product));
        EXPECT_EQ(&w, &room);
    }
    Step st;
    st.forward = &plain;
    Affine room;
    EXPECT_EQ(&t.sem.fromIdentity(param, st, room), &plain);
    EXPECT_TRUE(sameAffine(plain, t.sem.forwardThrough(Affine::identity(), param, st)));
    StepScratch scratch;
    const Step fused = t.sem.enter(chain, t.s, scratch);
    EXPECT_EQ(&t.sem.fromIdentity(chain, fused, room), fused.forward);
    EXPECT_TRUE(sameAffine(*fused.forward, t.sem.forwardThrough(Affine::identity(), chain, fused)));
}

// identityTimesIsExact looks at every one of the twelve words: -0, an infinity or a NaN in
// any of them makes identity * m differ from m; +0, finite and subnormal values do not.
TEST(Semantics, IdentityTimesIsExactTestsEachOfTheTwelveWords) {
    const double inf = std::numeric_limits<double>::infinity();
    const double inexact[] = {-0.0, inf, -inf, std::nan(""), -std::nan("")};
    const double exact[] = {0.0, 1.0, -1.0, 4.9e-324, -4.9e-324, 1.7e308, -1.7e308};
    for (int w = 0; w < 12; ++w) {
        SCOPED_TRACE(::testing::Message() << "word " << w);
        auto with = [&](double x) {
            Affine m = Affine::translate({1, 2, 3}) * Affine::scale({2, -1, 0.5});
            if (w < 9)
                m.l[w / 3][w % 3] = x;
            else
                (w == 9 ? m.t.x : w == 10 ? m.t.y : m.t.z) = x;
            return m;
        };
        for (double x : inexact) {
            const Affine m = with(x);
            EXPECT_FALSE(Semantics::identityTimesIsExact(m)) << x;
            EXPECT_FALSE(sameAffine(Affine::identity() * m, m)) << x;
        }
        for (double x : exact) {
            const Affine m = with(x);
            EXPECT_TRUE(Semantics::identityTimesIsExact(m)) << x;
            EXPECT_TRUE(sameAffine(Affine::identity() * m, m)) << x;
        }
    }
}

}  // namespace
}  // namespace pcsg
