// mapRay (map_ray.h) against Affine::point and Affine::vector applied one matrix after the
// other: the same bits for random matrices, rays and chains, signed zeros, infinities and
// subnormals included.
#include "map_ray.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace pcsg::tracer {
namespace {

// Mostly ordinary numbers of all signs and sizes, sometimes a zero of either sign, a
// subnormal, an infinity or a NaN.
double randomEntry(std::mt19937_64& g) {
    std::uniform_real_distribution<double> u(-4, 4);
    std::uniform_int_distribution<int> kind(0, 31), e(-40, 40);
    switch (kind(g)) {
        case 0:
            return 0.0;
        case 1:
            return -0.0;
        case 2:
            return std::numeric_limits<double>::denorm_min() * (1 + kind(g));
        case 3:
            return -std::numeric_limits<double>::infinity();
        case 4:
            return 1.0;
        default:
            return std::ldexp(u(g), e(g));
    }
}

Affine randomMatrix(std::mt19937_64& g) {
    Affine m;
    std::uniform_int_distribution<int> shape(0, 3);
    const int s = shape(g);  // 0: full, 1: diagonal (a scale and a move), 2: a move only
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            m.l[i][j] = s == 2 ? (i == j ? 1.0 : 0.0) : (s == 1 && i != j) ? 0.0 : randomEntry(g);
        m.t[i] = randomEntry(g);
    }
    return m;
}

Vec3 randomVec(std::mt19937_64& g) {
    return {randomEntry(g), randomEntry(g), randomEntry(g)};
}

void expectSameBits(const Vec3& a, const Vec3& b) {
    for (int i = 0; i < 3; ++i)
        EXPECT_EQ(std::bit_cast<uint64_t>(a[i]), std::bit_cast<uint64_t>(b[i]))
            << a[i] << " " << b[i];
}

TEST(MapRay, ChainsGiveTheScalarMapsBitForBit) {
    std::mt19937_64 g(20261204);
    std::vector<Affine> ms(64);
    for (Affine& m : ms) m = randomMatrix(g);
    std::uniform_int_distribution<uint32_t> pick(0, 63), len(0, 6);
    for (int n = 0; n < 100000; ++n) {
        const LocalRay r{randomVec(g), randomVec(g)};
        uint32_t refs[6];
        const uint32_t count = len(g);
        for (uint32_t k = 0; k < count; ++k) refs[k] = pick(g);
        Vec3 o = r.o, d = r.d;
        for (uint32_t k = 0; k < count; ++k) {
            o = ms[refs[k]].point(o);
            d = ms[refs[k]].vector(d);
        }
        const LocalRay chained = mapRay(ms.data(), refs, count, r);
        expectSameBits(chained.o, o);
        expectSameBits(chained.d, d);
        if (count == 0) continue;
        const LocalRay single = mapRay(ms[refs[0]], r);
        expectSameBits(single.o, ms[refs[0]].point(r.o));
        expectSameBits(single.d, ms[refs[0]].vector(r.d));
        if (HasFailure()) return;
    }
}

// The direction takes no translation: a zero of either sign stays as the scalar code
// leaves it (adding t, even 0, to it could turn -0 into +0).
TEST(MapRay, TheDirectionIsNotTranslated) {
    Affine m;
    m.t = {0.0, 5.0, -0.0};
    const LocalRay r{{1, 2, 3}, {-0.0, -0.0, -0.0}};
    const LocalRay out = mapRay(m, r);
    expectSameBits(out.d, m.vector(r.d));
    expectSameBits(out.o, m.point(r.o));
    EXPECT_TRUE(std::signbit(out.d.x));
}

// LocalRay::inverse and hasZeroAxis (operators.h, in SSE2 where there is SSE2) against their
// definition: 1 / d per axis, bit for bit, and a zero axis where some component is +0 or
// -0 (not a NaN). Directions of random entries (zeros of either sign, subnormals,
// infinities and NaNs among them), and every axis zero alone.
TEST(LocalRay, InverseAndZeroAxisAreTheirDefinition) {
    std::mt19937_64 g(15);
    const auto check = [](const Vec3& d) {
        const LocalRay r{{1, 2, 3}, d};
        const Vec3 inv = r.inverse();
        const Vec3 want{1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
        for (int a = 0; a < 3; ++a)
            EXPECT_EQ(std::bit_cast<uint64_t>(inv[a]), std::bit_cast<uint64_t>(want[a])) << a;
        EXPECT_EQ(r.hasZeroAxis(), d.x == 0 || d.y == 0 || d.z == 0)
            << d.x << " " << d.y << " " << d.z;
    };
    for (int k = 0; k < 100000; ++k) check({randomEntry(g), randomEntry(g), randomEntry(g)});
    for (int a = 0; a < 3; ++a) {
        for (double zero : {0.0, -0.0}) {
            Vec3 d{0.5, -2, 3};
            (a == 0 ? d.x : a == 1 ? d.y : d.z) = zero;
            check(d);
        }
    }
    check({0.5, -2, 3});
}

}  // namespace
}  // namespace pcsg::tracer
