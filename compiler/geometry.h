// Small, header-only 3D math shared by the compiler, the tracer and the expander:
// vectors, affine maps and axis-aligned boxes, all in double precision.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "csg_op.h"

namespace pcsg {

struct Vec3 {
    double x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}

    constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3& operator+=(const Vec3& o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    constexpr Vec3& operator-=(const Vec3& o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    constexpr Vec3& operator*=(double s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    constexpr bool operator==(const Vec3&) const = default;
};

constexpr Vec3 operator*(double s, const Vec3& v) {
    return v * s;
}
constexpr double dot(const Vec3& a, const Vec3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr Vec3 mul(const Vec3& a, const Vec3& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline double length(const Vec3& v) {
    return std::sqrt(dot(v, v));
}
inline Vec3 normalize(const Vec3& v) {
    return v / length(v);
}
constexpr Vec3 vmin(const Vec3& a, const Vec3& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3 vmax(const Vec3& a, const Vec3& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline bool isFinite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// An affine map p -> L p + t, with L stored row-major (column-vector convention:
// l[i][j] is the factor of p[j] in the i-th coordinate of the result).
//
// A T-node's matrix maps points of its operand (the child's frame) into the
// T-node's own frame. Composition follows the textual order: for `T1 T2 A`,
// the point of A maps to T1(T2(p)), i.e. the matrix T1 * T2.
struct Affine {
    double l[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    Vec3 t{};

    static constexpr Affine identity() { return Affine{}; }
    static constexpr Affine translate(const Vec3& d) {
        Affine a;
        a.t = d;
        return a;
    }
    static constexpr Affine scale(const Vec3& f) {
        Affine a;
        a.l[0][0] = f.x;
        a.l[1][1] = f.y;
        a.l[2][2] = f.z;
        return a;
    }

    constexpr Vec3 point(const Vec3& p) const {
        return {l[0][0] * p.x + l[0][1] * p.y + l[0][2] * p.z + t.x,
                l[1][0] * p.x + l[1][1] * p.y + l[1][2] * p.z + t.y,
                l[2][0] * p.x + l[2][1] * p.y + l[2][2] * p.z + t.z};
    }
    constexpr Vec3 vector(const Vec3& v) const {
        return {l[0][0] * v.x + l[0][1] * v.y + l[0][2] * v.z,
                l[1][0] * v.x + l[1][1] * v.y + l[1][2] * v.z,
                l[2][0] * v.x + l[2][1] * v.y + l[2][2] * v.z};
    }
    // Multiplies v by the transpose of L: with L the inverse of an object-to-world map,
    // this takes an object-space normal to world space (up to length).
    constexpr Vec3 transposedVector(const Vec3& v) const {
        return {l[0][0] * v.x + l[1][0] * v.y + l[2][0] * v.z,
                l[0][1] * v.x + l[1][1] * v.y + l[2][1] * v.z,
                l[0][2] * v.x + l[1][2] * v.y + l[2][2] * v.z};
    }

    // (*this) * o : first o, then *this.
    constexpr Affine operator*(const Affine& o) const {
        Affine r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                r.l[i][j] = l[i][0] * o.l[0][j] + l[i][1] * o.l[1][j] + l[i][2] * o.l[2][j];
        r.t = point(o.t);
        return r;
    }

    constexpr double determinant() const {
        return l[0][0] * (l[1][1] * l[2][2] - l[1][2] * l[2][1]) -
               l[0][1] * (l[1][0] * l[2][2] - l[1][2] * l[2][0]) +
               l[0][2] * (l[1][0] * l[2][1] - l[1][1] * l[2][0]);
    }

    // The inverse map. The caller guarantees the determinant is non-zero
    // (the evaluation code rejects singular T-nodes with a run-time error).
    constexpr Affine inverse() const {
        const double d = determinant();
        const double id = 1.0 / d;
        Affine r;
        r.l[0][0] = (l[1][1] * l[2][2] - l[1][2] * l[2][1]) * id;
        r.l[0][1] = (l[0][2] * l[2][1] - l[0][1] * l[2][2]) * id;
        r.l[0][2] = (l[0][1] * l[1][2] - l[0][2] * l[1][1]) * id;
        r.l[1][0] = (l[1][2] * l[2][0] - l[1][0] * l[2][2]) * id;
        r.l[1][1] = (l[0][0] * l[2][2] - l[0][2] * l[2][0]) * id;
        r.l[1][2] = (l[0][2] * l[1][0] - l[0][0] * l[1][2]) * id;
        r.l[2][0] = (l[1][0] * l[2][1] - l[1][1] * l[2][0]) * id;
        r.l[2][1] = (l[0][1] * l[2][0] - l[0][0] * l[2][1]) * id;
        r.l[2][2] = (l[0][0] * l[1][1] - l[0][1] * l[1][0]) * id;
        r.t = -r.vector(t);
        return r;
    }

    bool isFinite() const {
        for (const auto& row : l)
            for (double v : row)
                if (!std::isfinite(v)) return false;
        return pcsg::isFinite(t);
    }
    constexpr bool operator==(const Affine&) const = default;
};

// An axis-aligned box. Empty when lo > hi in any axis (the default).
struct Box {
    static constexpr double inf = std::numeric_limits<double>::infinity();
    Vec3 lo{inf, inf, inf};
    Vec3 hi{-inf, -inf, -inf};

    static constexpr Box empty() { return Box{}; }
    static constexpr Box everything() { return Box{{-inf, -inf, -inf}, {inf, inf, inf}}; }

    constexpr bool isEmpty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    bool isBounded() const { return !isEmpty() && pcsg::isFinite(lo) && pcsg::isFinite(hi); }
    constexpr void extend(const Vec3& p) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
    }
    constexpr void extend(const Box& b) {
        lo = vmin(lo, b.lo);
        hi = vmax(hi, b.hi);
    }
    constexpr bool contains(const Vec3& p) const {
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z &&
               p.z <= hi.z;
    }
    constexpr bool contains(const Box& b) const {
        return b.isEmpty() || (contains(b.lo) && contains(b.hi));
    }
    constexpr Vec3 center() const { return (lo + hi) * 0.5; }
    constexpr bool operator==(const Box&) const = default;
};

constexpr Box unite(const Box& a, const Box& b) {
    Box r = a;
    r.extend(b);
    return r;
}
constexpr Box intersect(const Box& a, const Box& b) {
    return Box{vmax(a.lo, b.lo), vmin(a.hi, b.hi)};
}

// The box of an affine image of a box (Arvo's method): tight for the image of the
// box itself, and correct for infinite extents as long as no 0 * inf arises
// (zero factors contribute nothing).
// The box of what a CSG operator holds, from its operands' boxes `boxOf(i)`: a union's box
// holds them all, an intersection's is their common part, a difference's its first
// operand's.
template <class BoxOf>
Box csgBox(CsgOp op, uint32_t count, BoxOf boxOf) {
    if (op == CsgOp::Difference) return count ? boxOf(0) : Box::empty();
    Box b = op == CsgOp::Union ? Box::empty() : Box::everything();
    for (uint32_t i = 0; i < count; ++i)
        b = op == CsgOp::Union ? unite(b, boxOf(i)) : intersect(b, boxOf(i));
    return b.isEmpty() ? Box::empty() : b;
}

inline Box transformBox(const Affine& m, const Box& b) {
    if (b.isEmpty()) return b;
    Box r;
    for (int i = 0; i < 3; ++i) {
        double lo = m.t[i], hi = m.t[i];
        for (int j = 0; j < 3; ++j) {
            const double a = m.l[i][j];
            if (a == 0) continue;
            const double e = a * b.lo[j], f = a * b.hi[j];
            lo += std::min(e, f);
            hi += std::max(e, f);
        }
        r.lo[i] = lo;
        r.hi[i] = hi;
    }
    return r;
}

}  // namespace pcsg
