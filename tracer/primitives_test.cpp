// Property tests for the primitives: random rays against randomly transformed primitives
// (with mirrors and shears). Every reported boundary lies on the surface, the world normal
// (through the inverse transpose) is unit and outward, entries and exits alternate, and a
// brute-force inside test along the ray agrees with the intervals.
#include "primitives.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pcsg::tracer {
namespace {

struct Rng {
    std::mt19937_64 gen;
    explicit Rng(uint64_t seed) : gen(seed) {}
    double uniform(double lo, double hi) {
        return std::uniform_real_distribution<double>(lo, hi)(gen);
    }
    Vec3 inBox(double r) { return {uniform(-r, r), uniform(-r, r), uniform(-r, r)}; }
    Vec3 unit() {
        for (;;) {
            const Vec3 v = inBox(1);
            const double l = length(v);
            if (l > 0.1 && l <= 1) return v / l;
        }
    }
};

// A random affine map with rotation, non-uniform scale, shear and sometimes a mirror.
Affine randomAffine(Rng& rng) {
    for (;;) {
        Affine m;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) m.l[i][j] = rng.uniform(-1.5, 1.5);
        m.t = rng.inBox(1);
        const double det = m.determinant();
        if (std::fabs(det) > 0.2) return m;
    }
}

// Distance-like residual of the surface at a local point (0 on the surface).
double surfaceResidual(PrimitiveKind k, const double* args, const Vec3& p) {
    switch (k) {
        case PrimitiveKind::Sphere:
            return length(p) - 1;
        case PrimitiveKind::Cube:
            return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) - 1;
        case PrimitiveKind::Cylinder:
            return std::max({std::sqrt(p.x * p.x + p.y * p.y) - 1, -p.z, p.z - 1});
        case PrimitiveKind::Cone:
            return std::max(
                {(std::sqrt(p.x * p.x + p.y * p.y) - (1 - p.z)) / std::sqrt(2.0), -p.z, p.z - 1});
        case PrimitiveKind::Tetrahedron:
            return std::max(
                       {-p.x - p.y - p.z, p.x + p.y - p.z, -p.x + p.y + p.z, p.x - p.y + p.z}) -
                   1;
        case PrimitiveKind::Torus: {
            const double rho = std::sqrt(p.x * p.x + p.y * p.y);
            return std::sqrt((rho - args[0]) * (rho - args[0]) + p.z * p.z) - args[1];
        }
        case PrimitiveKind::Plane:
            return p.z;
        default:
            return 1e9;
    }
}

void checkPrimitive(PrimitiveKind kind, const double* args, uint64_t seed, int minHits = 500) {
    Rng rng(seed);
    int hits = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const Affine m = randomAffine(rng);  // object to world
        const Affine inv = m.inverse();      // world to object
        // Aim near the object most of the time so that many rays hit.
        const Vec3 origin = rng.inBox(6);
        const Vec3 target = m.point(rng.inBox(1.3));
        const Vec3 dir = normalize(target - origin);
        const Vec3 lo = inv.point(origin), ld = inv.vector(dir);

        Span spans[kMaxPrimitiveSpans];
        const int n = intersectSolid(kind, args, lo, ld, spans);
        ASSERT_GE(n, 0);
        ASSERT_LE(n, kMaxPrimitiveSpans);
        for (int i = 0; i < n; ++i) {
            const Span& s = spans[i];
            ASSERT_LT(s.in.t, s.out.t) << "span " << i;
            if (i > 0) {
                ASSERT_LE(spans[i - 1].out.t, s.in.t) << "spans overlap";
            }
            for (int e = 0; e < 2; ++e) {
                const Boundary& b = e == 0 ? s.in : s.out;
                if (std::isinf(b.t)) continue;
                ++hits;
                const Vec3 p = lo + ld * b.t;
                ASSERT_NEAR(surfaceResidual(kind, args, p), 0, 1e-8)
                    << "boundary off the surface, trial " << trial;
                // World normal through the inverse transpose: unit after normalising, and
                // outward: against the ray at an entry, along it at an exit.
                const Vec3 nw = normalize(inv.transposedVector(b.normal));
                ASSERT_TRUE(isFinite(nw));
                ASSERT_NEAR(length(nw), 1, 1e-12);
                const double c = dot(nw, dir);
                if (e == 0) {
                    ASSERT_LE(c, 1e-9) << "entry normal not outward, trial " << trial;
                } else {
                    ASSERT_GE(c, -1e-9) << "exit normal not outward, trial " << trial;
                }
                // Outward for real: a step along the normal leaves the solid, a step
                // against it enters (away from edges, where the step could cross another
                // face; the residual tells us the point is on exactly one smooth piece).
                const Vec3 nl = normalize(b.normal);
                const double h = 1e-5;
                if (kind != PrimitiveKind::Cube && kind != PrimitiveKind::Tetrahedron &&
                    kind != PrimitiveKind::Cylinder && kind != PrimitiveKind::Cone) {
                    ASSERT_FALSE(insideSolid(kind, args, p + nl * h));
                    ASSERT_TRUE(insideSolid(kind, args, p - nl * h));
                }
            }
        }
        // Brute force along the ray: inside exactly where a span is, away from boundaries.
        for (int k = 0; k < 64; ++k) {
            const double t = rng.uniform(-12, 12);
            bool nearBoundary = false, in = false;
            for (int i = 0; i < n; ++i) {
                if (std::fabs(t - spans[i].in.t) < 1e-6 || std::fabs(t - spans[i].out.t) < 1e-6)
                    nearBoundary = true;
                if (t >= spans[i].in.t && t <= spans[i].out.t) in = true;
            }
            if (nearBoundary) continue;
            ASSERT_EQ(insideSolid(kind, args, lo + ld * t), in)
                << "inside test disagrees at t=" << t << " trial " << trial;
        }
    }
    EXPECT_GT(hits, minHits) << "too few rays hit: the test proves little";
}

TEST(Primitives, Sphere) {
    checkPrimitive(PrimitiveKind::Sphere, nullptr, 1);
}
TEST(Primitives, Cube) {
    checkPrimitive(PrimitiveKind::Cube, nullptr, 2);
}
TEST(Primitives, Cylinder) {
    checkPrimitive(PrimitiveKind::Cylinder, nullptr, 3);
}
TEST(Primitives, Cone) {
    checkPrimitive(PrimitiveKind::Cone, nullptr, 4);
}
TEST(Primitives, Tetrahedron) {
    checkPrimitive(PrimitiveKind::Tetrahedron, nullptr, 5);
}
TEST(Primitives, Plane) {
    checkPrimitive(PrimitiveKind::Plane, nullptr, 6);
}
TEST(Primitives, Torus) {
    const double args[2] = {0.8, 0.25};
    checkPrimitive(PrimitiveKind::Torus, args, 7);
}
TEST(Primitives, ThinTorus) {
    const double args[2] = {1.0, 0.02};
    checkPrimitive(PrimitiveKind::Torus, args, 8, 100);
}

TEST(Primitives, EmptyHasNoSpans) {
    Span s[kMaxPrimitiveSpans];
    EXPECT_EQ(intersectSolid(PrimitiveKind::Empty, nullptr, {0, 0, -5}, {0, 0, 1}, s), 0);
}

TEST(Primitives, TorusSeenAlongItsAxisHasNoHitThroughTheHole) {
    const double args[2] = {1.0, 0.25};
    Span s[kMaxPrimitiveSpans];
    EXPECT_EQ(intersectSolid(PrimitiveKind::Torus, args, {0, 0, -5}, {0, 0, 1}, s), 0);
    // Along the x axis: two intervals, [-1.25, -0.75] and [0.75, 1.25] shifted by 5.
    ASSERT_EQ(intersectSolid(PrimitiveKind::Torus, args, {-5, 0, 0}, {1, 0, 0}, s), 2);
    EXPECT_NEAR(s[0].in.t, 3.75, 1e-12);
    EXPECT_NEAR(s[0].out.t, 4.25, 1e-12);
    EXPECT_NEAR(s[1].in.t, 5.75, 1e-12);
    EXPECT_NEAR(s[1].out.t, 6.25, 1e-12);
}

TEST(Primitives, RayParameterIsTheSameWithAScaledDirection) {
    // The tracer never normalises directions in child frames: t must not depend on the
    // direction's length beyond the scaling.
    Span a[kMaxPrimitiveSpans], b[kMaxPrimitiveSpans];
    ASSERT_EQ(intersectSolid(PrimitiveKind::Sphere, nullptr, {0, -3, 0}, {0, 1, 0}, a), 1);
    ASSERT_EQ(intersectSolid(PrimitiveKind::Sphere, nullptr, {0, -3, 0}, {0, 0.25, 0}, b), 1);
    EXPECT_NEAR(a[0].in.t, 2, 1e-12);
    EXPECT_NEAR(b[0].in.t, 8, 1e-12);
}

TEST(Primitives, PlaneIsAHalfSpace) {
    Span s[kMaxPrimitiveSpans];
    ASSERT_EQ(intersectSolid(PrimitiveKind::Plane, nullptr, {0, 0, 2}, {0, 0, -1}, s), 1);
    EXPECT_EQ(s[0].in.t, 2);
    EXPECT_TRUE(std::isinf(s[0].out.t));
    EXPECT_EQ(s[0].in.normal, (Vec3{0, 0, 1}));
    // Parallel to the plane: inside everywhere or nowhere.
    ASSERT_EQ(intersectSolid(PrimitiveKind::Plane, nullptr, {0, 0, -1}, {1, 0, 0}, s), 1);
    EXPECT_TRUE(std::isinf(s[0].in.t) && std::isinf(s[0].out.t));
    EXPECT_EQ(intersectSolid(PrimitiveKind::Plane, nullptr, {0, 0, 1}, {1, 0, 0}, s), 0);
}

TEST(Primitives, TriangleHitsAndMisses) {
    Vec3 c[3];
    triangleCorners(PrimitiveKind::Tri1, nullptr, c);
    Boundary hit;
    ASSERT_TRUE(intersectTriangle(c[0], c[1], c[2], {0.2, 0.2, 1}, {0, 0, -2}, 0, 10, hit));
    EXPECT_NEAR(hit.t, 0.5, 1e-15);
    EXPECT_EQ(hit.normal, (Vec3{0, 0, 1}));
    EXPECT_FALSE(intersectTriangle(c[0], c[1], c[2], {0.7, 0.7, 1}, {0, 0, -1}, 0, 10, hit));
    EXPECT_FALSE(intersectTriangle(c[0], c[1], c[2], {0.2, 0.2, 1}, {0, 0, -1}, 0, 0.5, hit));
    triangleCorners(PrimitiveKind::Tri2, nullptr, c);
    EXPECT_TRUE(intersectTriangle(c[0], c[1], c[2], {-0.2, -0.2, 1}, {0, 0, -1}, 0, 10, hit));
    EXPECT_FALSE(intersectTriangle(c[0], c[1], c[2], {0.2, 0.2, 1}, {0, 0, -1}, 0, 10, hit));
}

TEST(Primitives, TrianglePropertyHitsLieOnThePlaneInsideTheCorners) {
    Rng rng(11);
    int hits = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const Vec3 a = rng.inBox(1), b = rng.inBox(1), c = rng.inBox(1);
        const Vec3 o = rng.inBox(4);
        const Vec3 target = a * 0.3 + b * 0.3 + c * 0.4 + rng.inBox(0.5);
        const Vec3 d = (target - o) * rng.uniform(0.2, 3);
        Boundary hit;
        if (!intersectTriangle(a, b, c, o, d, 0, 1e30, hit)) continue;
        ++hits;
        const Vec3 p = o + d * hit.t;
        const Vec3 n = normalize(cross(b - a, c - a));
        ASSERT_NEAR(dot(p - a, n), 0, 1e-9);
        // Barycentric coordinates within [0, 1] up to the edge tolerance.
        const Vec3 nn = cross(b - a, c - a);
        const double area = dot(nn, nn);
        const double u = dot(cross(c - b, p - b), nn) / area;
        const double v = dot(cross(a - c, p - c), nn) / area;
        ASSERT_GE(u, -1e-7);
        ASSERT_GE(v, -1e-7);
        ASSERT_LE(u + v, 1 + 1e-7);
    }
    EXPECT_GT(hits, 300);
}

TEST(Primitives, PolynomialRoots) {
    // (x - 1)(x - 2)(x + 0.5)(x - 3) = x^4 - 5.5x^3 + 8x^2 - 0.5x - 3
    const double c[5] = {-3, -0.5, 8, -5.5, 1};
    double r[4];
    ASSERT_EQ(solvePolynomial(c, 4, -10, 10, r), 4);
    EXPECT_NEAR(r[0], -0.5, 1e-12);
    EXPECT_NEAR(r[1], 1, 1e-12);
    EXPECT_NEAR(r[2], 2, 1e-12);
    EXPECT_NEAR(r[3], 3, 1e-12);
    ASSERT_EQ(solvePolynomial(c, 4, 1.5, 2.5, r), 1);
    EXPECT_NEAR(r[0], 2, 1e-12);
    // No real roots: x^4 + 1.
    const double d[5] = {1, 0, 0, 0, 1};
    EXPECT_EQ(solvePolynomial(d, 4, -10, 10, r), 0);
    // A double root: (x - 1)^2 (x + 1)(x + 2): the double root is found once or not at all,
    // never as two separate crossings.
    const double e[5] = {2, -1, -3, 1, 1};
    const int n = solvePolynomial(e, 4, -10, 10, r);
    ASSERT_GE(n, 2);
    EXPECT_NEAR(r[0], -2, 1e-12);
    EXPECT_NEAR(r[1], -1, 1e-12);
}

TEST(Primitives, BoxesContainTheSolids) {
    Rng rng(12);
    const double torusArgs[2] = {0.7, 0.3};
    for (PrimitiveKind k :
         {PrimitiveKind::Sphere, PrimitiveKind::Cube, PrimitiveKind::Cylinder, PrimitiveKind::Cone,
          PrimitiveKind::Tetrahedron, PrimitiveKind::Torus}) {
        const Box b = primitiveBox(k, torusArgs);
        for (int i = 0; i < 20000; ++i) {
            const Vec3 p = rng.inBox(1.5);
            if (insideSolid(k, torusArgs, p)) {
                ASSERT_TRUE(b.contains(p)) << int(k);
            }
        }
    }
}

}  // namespace
}  // namespace pcsg::tracer
