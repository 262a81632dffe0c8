// The box test of the expansions' BVH nodes in floats (bvh_slabs.h) against the one in
// doubles: it must meet every child the doubles meet, entering no later, on rays that
// graze the boxes' faces, edges and corners, from near and far.
#include "bvh_slabs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "outward_float.h"

namespace pcsg::tracer {
namespace {

#if defined(__SSE2__)

constexpr double kInf = std::numeric_limits<double>::infinity();

// Compares the two tests on node b for ray r; returns the children the doubles meet.
int expectFloatHoldsDouble(const UnrolledInstance::BvhNode& b, const LocalRay& r, double tmin,
                           double tmax) {
    double td[4] = {};
    float tf[4] = {};
    const int exact = enterChildren(b, r, tmin, tmax, td);
    const FloatRay f = floatRay(r, tmin);
    EXPECT_TRUE(f.ok);
    if (!f.ok) return exact;
    const int wide = enterChildrenFloat(b, f, tmax, tf);
    EXPECT_EQ(exact & ~wide, 0) << "culled a child the doubles meet: " << exact << " " << wide;
    for (int c = 0; c < 4; ++c) {
        if (exact & (1 << c)) {
            EXPECT_LE(tf[c], td[c]) << c;
        }
        if (b.child[c] == kNone) {
            EXPECT_FALSE(wide & (1 << c)) << "an empty slot";
        }
    }
    return exact;
}

// A node whose child c is the box [lo, hi] rounded outwards (three used slots, one empty).
void setChild(UnrolledInstance::BvhNode& b, int c, const Vec3& lo, const Vec3& hi) {
    for (int a = 0; a < 3; ++a) {
        b.lo[a][c] = floatBelow(lo[a]);
        b.hi[a][c] = floatAbove(hi[a]);
    }
    b.child[c] = static_cast<uint32_t>(c);
    b.link[c] = kNone;
}

// Rays at boxes that end exactly where the ray passes: a face through the point at t
// (one bound a float just before or after the point), so that the doubles meet some and
// miss others by a last bit; origins from next to the box to 10^5 away.
TEST(BvhSlabs, FloatsMeetWhatDoublesMeetOnGrazingRays) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> unit(-1, 1);
    int met = 0, missed = 0;
    for (int k = 0; k < 200000; ++k) {
        const double far = std::pow(10.0, 5 * (unit(rng) + 1) / 2 - 2);
        const Vec3 o{unit(rng) * far, unit(rng) * far, unit(rng) * far};
        Vec3 d{unit(rng), unit(rng), unit(rng)};
        if (k % 7 == 0) d[k % 3] *= 1e-6;  // nearly parallel to a face
        const LocalRay r{o, d};
        const double t = std::fabs(unit(rng)) * 3 * far + 1e-3;
        const Vec3 p = o + d * t;
        UnrolledInstance::BvhNode b{};
        for (int c = 0; c < 4; ++c) b.child[c] = b.link[c] = kNone;
        for (int c = 0; c < 3; ++c) {
            const double size = std::pow(10.0, 3 * unit(rng)) * (far + 1);
            Vec3 lo = p - Vec3{size, size, size}, hi = p + Vec3{size, size, size};
            const int axis = static_cast<int>(rng() % 3);
            // The face at the point itself, or one float step beyond it on either side.
            const float at = static_cast<float>(p[axis]);
            const float face =
                c == 0 ? at : (c == 1 ? std::nextafter(at, kInf) : std::nextafter(at, -kInf));
            if (rng() & 1)
                lo[axis] = face;
            else
                hi[axis] = face;
            setChild(b, c, lo, hi);  // (a float bound stays as it is)
        }
        const double tmin = (k % 3 == 0) ? t * (1 - 1e-9) : 1e-6;
        const double tmax = (k % 5 == 0) ? t * (1 + 1e-9) : (k % 2 ? kInf : 1e7 * far);
        const int exact = expectFloatHoldsDouble(b, r, tmin, tmax);
        met += __builtin_popcount(static_cast<unsigned>(exact));
        missed += 3 - __builtin_popcount(static_cast<unsigned>(exact));
        if (testing::Test::HasFailure()) return;
    }
    EXPECT_GT(met, 100000);
    EXPECT_GT(missed, 50000);
}

// Unbounded boxes (planes), boxes beyond the floats' range and subnormal distances.
TEST(BvhSlabs, FloatsMeetWhatDoublesMeetAtTheEdgesOfTheRange) {
    UnrolledInstance::BvhNode b{};
    for (int c = 0; c < 4; ++c) b.child[c] = b.link[c] = kNone;
    setChild(b, 0, {-kInf, -kInf, -kInf}, {kInf, kInf, 0});
    setChild(b, 1, {1e38, 1e38, 1e38}, {kInf, kInf, kInf});
    setChild(b, 2, {1e-40, -1, -1}, {2e-40, 1, 1});
    const LocalRay toward{{0, 0, 0}, {1, 1, 1}};
    EXPECT_EQ(expectFloatHoldsDouble(b, toward, 0, kInf), 7);
    const LocalRay along{{-1e-30, 0, 0}, {1e-15, 1e-15, 1e-15}};
    expectFloatHoldsDouble(b, along, -1e300, 1e300);
    const LocalRay back{{1e17, -3, 0.5}, {-1, 1e-17, -1e-10}};
    expectFloatHoldsDouble(b, back, 0, kInf);
}

// Rays outside the bound's domain are left to the doubles.
TEST(BvhSlabs, RaysOutsideTheErrorBoundsDomainAreNotTakenInFloats) {
    EXPECT_FALSE(floatRay(LocalRay{{0, 0, 0}, {1, 0, 1}}, 0).ok);  // a zero axis
    EXPECT_FALSE(floatRay(LocalRay{{1e20, 0, 0}, {1, 1, 1}}, 0).ok);
    EXPECT_FALSE(floatRay(LocalRay{{0, 0, 0}, {1e-20, 1, 1}}, 0).ok);
    EXPECT_FALSE(floatRay(LocalRay{{0, 0, 0}, {1e20, 1, 1}}, 0).ok);
    EXPECT_TRUE(floatRay(LocalRay{{1e17, 0, 0}, {1e-17, 1, 1e17}}, 0).ok);
}

#endif

}  // namespace
}  // namespace pcsg::tracer
