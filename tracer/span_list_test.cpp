// Span-list algebra against a brute-force inside test: random sorted lists, combined by
// each operator, must contain exactly the points the operator's truth table says.
#include "span_list.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace pcsg::tracer {
namespace {

std::vector<Span> randomList(std::mt19937_64& gen, uint32_t material) {
    std::uniform_int_distribution<int> count(0, 6);
    std::uniform_real_distribution<double> pos(-10, 10);
    std::vector<double> ends(2 * count(gen));
    // Integers half the time, so that touching and equal ends are exercised.
    const bool grid = gen() & 1;
    for (double& e : ends) e = grid ? std::round(pos(gen)) : pos(gen);
    std::sort(ends.begin(), ends.end());
    std::vector<Span> out;
    for (size_t i = 0; i + 1 < ends.size(); i += 2) {
        if (!(ends[i] < ends[i + 1])) continue;
        if (!out.empty() && out.back().out.t >= ends[i]) continue;  // keep them disjoint
        out.push_back(Span{Boundary{ends[i], {0, 0, -1}, material},
                           Boundary{ends[i + 1], {0, 0, 1}, material}});
    }
    if ((gen() & 7) == 0) {  // an unbounded span now and then
        if (out.empty())
            out.push_back(
                Span{Boundary{-INFINITY, {}, material}, Boundary{INFINITY, {}, material}});
        else
            out.back().out = Boundary{INFINITY, {}, material};
    }
    return out;
}

void checkWellFormed(const std::vector<Span>& s) {
    for (size_t i = 0; i < s.size(); ++i) {
        ASSERT_LT(s[i].in.t, s[i].out.t);
        if (i > 0) {
            ASSERT_LT(s[i - 1].out.t, s[i].in.t) << "not disjoint or touching";
        }
    }
}

enum class Op { Unite, Intersect, Subtract };

std::vector<Span> combine(Op op, const std::vector<Span>& a, const std::vector<Span>& b) {
    std::vector<Span> out(a.size() + b.size() + 1);
    size_t n = 0;
    switch (op) {
        case Op::Unite:
            n = uniteSpans(a.data(), a.size(), b.data(), b.size(), out.data());
            break;
        case Op::Intersect:
            n = intersectSpans(a.data(), a.size(), b.data(), b.size(), out.data());
            break;
        case Op::Subtract:
            n = subtractSpans(a.data(), a.size(), b.data(), b.size(), out.data());
            break;
    }
    out.resize(n);
    return out;
}

bool truth(Op op, bool a, bool b) {
    switch (op) {
        case Op::Unite:
            return a || b;
        case Op::Intersect:
            return a && b;
        case Op::Subtract:
            return a && !b;
    }
    return false;
}

// Membership at t, away from all ends (where "inside" is ambiguous).
void checkAgainstBruteForce(Op op, const std::vector<Span>& a, const std::vector<Span>& b,
                            const std::vector<Span>& r, std::mt19937_64& gen) {
    std::uniform_real_distribution<double> pos(-12, 12);
    std::vector<double> ends;
    for (const auto* l : {&a, &b})
        for (const Span& s : *l) ends.insert(ends.end(), {s.in.t, s.out.t});
    // Sample points between ends too, not only random ones.
    std::vector<double> probes;
    for (int i = 0; i < 200; ++i) probes.push_back(pos(gen));
    std::vector<double> sorted = ends;
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 0; i + 1 < sorted.size(); ++i)
        if (std::isfinite(sorted[i]) && std::isfinite(sorted[i + 1]))
            probes.push_back(0.5 * (sorted[i] + sorted[i + 1]));
    for (double t : probes) {
        bool nearEnd = false;
        for (double e : ends)
            if (std::fabs(t - e) < 1e-9) nearEnd = true;
        if (nearEnd) continue;
        const bool ia = insideSpans(a.data(), a.size(), t), ib = insideSpans(b.data(), b.size(), t);
        ASSERT_EQ(insideSpans(r.data(), r.size(), t), truth(op, ia, ib)) << "t=" << t;
    }
}

TEST(SpanList, AlgebraMatchesBruteForce) {
    std::mt19937_64 gen(42);
    for (int trial = 0; trial < 20000; ++trial) {
        const auto a = randomList(gen, 1), b = randomList(gen, 2);
        for (Op op : {Op::Unite, Op::Intersect, Op::Subtract}) {
            const auto r = combine(op, a, b);
            checkWellFormed(r);
            ASSERT_LE(r.size(), a.size() + b.size());
            checkAgainstBruteForce(op, a, b, r, gen);
            if (HasFatalFailure()) {
                ADD_FAILURE() << "trial " << trial << " op " << int(op);
                return;
            }
        }
    }
}

TEST(SpanList, EndsComeFromTheRightOperand) {
    // [0, 4] \ [1, 2]: the cut faces at 1 and 2 come from b, normals negated, b's material.
    const std::vector<Span> a = {Span{Boundary{0, {-1, 0, 0}, 1}, Boundary{4, {1, 0, 0}, 1}}};
    const std::vector<Span> b = {Span{Boundary{1, {-1, 0, 0}, 2}, Boundary{2, {1, 0, 0}, 2}}};
    const auto r = combine(Op::Subtract, a, b);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r[0].in.t, 0);
    EXPECT_EQ(r[0].in.material, 1u);
    EXPECT_EQ(r[0].out.t, 1);
    EXPECT_EQ(r[0].out.material, 2u);
    EXPECT_EQ(r[0].out.normal, (Vec3{1, 0, 0}));  // out of the result: along the ray
    EXPECT_EQ(r[1].in.t, 2);
    EXPECT_EQ(r[1].in.normal, (Vec3{-1, 0, 0}));
    EXPECT_EQ(r[1].out.material, 1u);

    // Intersection keeps the later entry and the earlier exit.
    const auto i = combine(Op::Intersect, a, b);
    ASSERT_EQ(i.size(), 1u);
    EXPECT_EQ(i[0].in.material, 2u);
    EXPECT_EQ(i[0].out.material, 2u);

    // Touching spans merge in a union: no surface at the shared face.
    const std::vector<Span> c = {Span{Boundary{4, {-1, 0, 0}, 3}, Boundary{5, {1, 0, 0}, 3}}};
    const auto u = combine(Op::Unite, a, c);
    ASSERT_EQ(u.size(), 1u);
    EXPECT_EQ(u[0].in.t, 0);
    EXPECT_EQ(u[0].out.t, 5);
    EXPECT_EQ(u[0].out.material, 3u);
}

TEST(SpanList, EmptyOperands) {
    const std::vector<Span> a = {Span{Boundary{0, {}, 1}, Boundary{1, {}, 1}}};
    const std::vector<Span> none;
    EXPECT_EQ(combine(Op::Unite, a, none).size(), 1u);
    EXPECT_EQ(combine(Op::Unite, none, a).size(), 1u);
    EXPECT_EQ(combine(Op::Intersect, a, none).size(), 0u);
    EXPECT_EQ(combine(Op::Subtract, a, none).size(), 1u);
    EXPECT_EQ(combine(Op::Subtract, none, a).size(), 0u);
}

}  // namespace
}  // namespace pcsg::tracer
