// Ray-primitive intersection: closed forms for the quadrics and polytopes, a robust
// root isolation for the torus quartic.
#include "primitives.h"

#include <cmath>
#include <limits>
#include <utility>

namespace pcsg::tracer {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One end of an interval being built: its t and outward normal.
struct End {
    double t;
    Vec3 n;
};

// [in, out] as a candidate interval; empty when !(in.t < out.t).
struct Piece {
    End in{-kInf, {}};
    End out{kInf, {}};
    bool empty() const { return !(in.t < out.t); }
};

void clip(Piece& p, const End& in, const End& out) {
    if (in.t > p.in.t) p.in = in;
    if (out.t < p.out.t) p.out = out;
}

int emit(const Piece& p, Span* out) {
    if (p.empty()) return 0;
    out[0].in = Boundary{p.in.t, p.in.n, 0};
    out[0].out = Boundary{p.out.t, p.out.n, 0};
    return 1;
}

// Roots of a t^2 + 2 b t + c = 0 given disc = b^2 - a c > 0 (a != 0), sorted.
std::pair<double, double> quadraticRoots(double a, double b, double c, double disc) {
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    double t1 = q / a, t2 = q != 0 ? c / q : -b / a;
    if (t1 > t2) std::swap(t1, t2);
    return {t1, t2};
}

// The slab lo <= o + t d <= hi along one axis, as an entry and an exit with normals
// -axis at lo and +axis at hi. Returns false when the ray misses (parallel and outside).
bool slab(int axis, double o, double d, double lo, double hi, Piece& p) {
    if (d == 0) return o >= lo && o <= hi;
    Vec3 nLo{}, nHi{};
    nLo[axis] = -1;
    nHi[axis] = 1;
    const double tLo = (lo - o) / d, tHi = (hi - o) / d;
    if (d > 0)
        clip(p, End{tLo, nLo}, End{tHi, nHi});
    else
        clip(p, End{tHi, nHi}, End{tLo, nLo});
    return true;
}

int sphere(const Vec3& o, const Vec3& d, Span* out) {
    const double a = dot(d, d), b = dot(o, d), c = dot(o, o) - 1;
    // b^2 - a c = a (1 - |m|^2) with m the point of the line closest to the centre: no
    // cancellation for rays from far away.
    const Vec3 m = o - d * (b / a);
    const double disc = a * (1 - dot(m, m));
    if (!(disc > 0)) return 0;
    const auto [t1, t2] = quadraticRoots(a, b, c, disc);
    Piece p;
    p.in = End{t1, o + d * t1};
    p.out = End{t2, o + d * t2};
    return emit(p, out);
}

int cube(const Vec3& o, const Vec3& d, Span* out) {
    Piece p;
    for (int i = 0; i < 3; ++i)
        if (!slab(i, o[i], d[i], -1, 1, p)) return 0;
    return emit(p, out);
}

int tetrahedron(const Vec3& o, const Vec3& d, Span* out) {
    // The solid is {p : n . p <= 1} for the four outward face normals n = -v, v the vertices.
    static constexpr Vec3 kNormals[4] = {{-1, -1, -1}, {1, 1, -1}, {-1, 1, 1}, {1, -1, 1}};
    Piece p;
    for (const Vec3& n : kNormals) {
        const double den = dot(n, d), num = 1 - dot(n, o);
        if (den == 0) {
            if (num < 0) return 0;
            continue;
        }
        const double t = num / den;
        if (den < 0)
            clip(p, End{t, n}, End{kInf, {}});
        else
            clip(p, End{-kInf, {}}, End{t, n});
    }
    return emit(p, out);
}

int cylinder(const Vec3& o, const Vec3& d, Span* out) {
    Piece p;
    if (!slab(2, o.z, d.z, 0, 1, p)) return 0;
    const double a = d.x * d.x + d.y * d.y;
    const double b = o.x * d.x + o.y * d.y;
    if (a == 0) {
        if (o.x * o.x + o.y * o.y > 1) return 0;
    } else {
        const double mx = o.x - d.x * (b / a), my = o.y - d.y * (b / a);
        const double disc = a * (1 - (mx * mx + my * my));
        if (!(disc > 0)) return 0;
        const double c = o.x * o.x + o.y * o.y - 1;
        const auto [t1, t2] = quadraticRoots(a, b, c, disc);
        const Vec3 p1 = o + d * t1, p2 = o + d * t2;
        clip(p, End{t1, {p1.x, p1.y, 0}}, End{t2, {p2.x, p2.y, 0}});
    }
    return emit(p, out);
}

Vec3 coneNormal(const Vec3& o, const Vec3& d, double t) {
    const Vec3 p = o + d * t;
    const Vec3 n{p.x, p.y, 1 - p.z};
    return (n.x == 0 && n.y == 0 && n.z == 0) ? Vec3{0, 0, 1} : n;
}

int cone(const Vec3& o, const Vec3& d, Span* out) {
    // Inside the lower nappe of x^2 + y^2 = (1 - z)^2, within 0 <= z <= 1 (a convex set).
    Piece slabPiece;
    if (!slab(2, o.z, d.z, 0, 1, slabPiece)) return 0;
    const double w = 1 - o.z;
    const double a = d.x * d.x + d.y * d.y - d.z * d.z;
    const double b = o.x * d.x + o.y * d.y + w * d.z;
    const double c = o.x * o.x + o.y * o.y - w * w;
    Piece pieces[2];
    int count = 0;
    if (a == 0) {
        if (b == 0) {
            if (c > 0) return 0;
            pieces[count++] = Piece{};
        } else {
            const double t0 = -c / (2 * b);
            if (b > 0)
                pieces[count++] = Piece{End{-kInf, {}}, End{t0, coneNormal(o, d, t0)}};
            else
                pieces[count++] = Piece{End{t0, coneNormal(o, d, t0)}, End{kInf, {}}};
        }
    } else {
        const double disc = b * b - a * c;
        if (a > 0) {
            if (!(disc > 0)) return 0;
            const auto [t1, t2] = quadraticRoots(a, b, c, disc);
            pieces[count++] = Piece{End{t1, coneNormal(o, d, t1)}, End{t2, coneNormal(o, d, t2)}};
        } else if (!(disc > 0)) {
            pieces[count++] = Piece{};
        } else {
            const auto [t1, t2] = quadraticRoots(a, b, c, disc);
            pieces[count++] = Piece{End{-kInf, {}}, End{t1, coneNormal(o, d, t1)}};
            pieces[count++] = Piece{End{t2, coneNormal(o, d, t2)}, End{kInf, {}}};
        }
    }
    // The convex result is the hull of the non-empty pieces clipped to the slab.
    Piece result{End{kInf, {}}, End{-kInf, {}}};
    for (int i = 0; i < count; ++i) {
        Piece q = pieces[i];
        clip(q, slabPiece.in, slabPiece.out);
        if (q.empty()) continue;
        if (q.in.t < result.in.t) result.in = q.in;
        if (q.out.t > result.out.t) result.out = q.out;
    }
    return emit(result, out);
}

int plane(const Vec3& o, const Vec3& d, Span* out) {
    Piece p;
    if (!slab(2, o.z, d.z, -kInf, 0, p)) return 0;
    return emit(p, out);
}

double torusInside(double R, double r, const Vec3& p) {
    const double rho = std::sqrt(p.x * p.x + p.y * p.y);
    const double dr = rho - R;
    return dr * dr + p.z * p.z - r * r;
}

Vec3 torusNormal(double R, const Vec3& p) {
    const double rho = std::sqrt(p.x * p.x + p.y * p.y);
    if (rho == 0) return {0, 0, p.z};
    const double k = 1 - R / rho;
    return {p.x * k, p.y * k, p.z};
}

int torus(const double* args, const Vec3& o, const Vec3& d, Span* out) {
    const double R = args[0], r = args[1];
    const double ext = std::fabs(R) + std::fabs(r);
    // Clip the line to the torus's box first, then solve the quartic in a parameter s
    // along the unit direction from the box entry: well conditioned whatever the
    // distance of the ray origin.
    Piece box;
    if (!slab(0, o.x, d.x, -ext, ext, box) || !slab(1, o.y, d.y, -ext, ext, box) ||
        !slab(2, o.z, d.z, -std::fabs(r), std::fabs(r), box) || box.empty())
        return 0;
    const double len = length(d);
    const Vec3 u = d / len;
    const double t0 = box.in.t;
    const Vec3 q = o + d * t0;
    const double sEnd = (box.out.t - t0) * len;

    const double R2 = R * R;
    const double e = dot(q, q) + R2 - r * r;
    const double f1 = dot(q, u);
    const double uxy = u.x * u.x + u.y * u.y;
    const double qu = q.x * u.x + q.y * u.y;
    const double qxy = q.x * q.x + q.y * q.y;
    const double c[5] = {e * e - 4 * R2 * qxy, 4 * f1 * e - 8 * R2 * qu,
                         2 * e + 4 * f1 * f1 - 4 * R2 * uxy, 4 * f1, 1};
    double s[6];
    int n = solvePolynomial(c, 4, 0, sEnd, s + 1);
    s[0] = 0;
    s[n + 1] = sEnd;
    // Classify the segments between consecutive roots with the exact inside function and
    // emit the runs that are inside.
    int count = 0;
    bool inside = false;
    double start = 0;
    for (int i = 0; i <= n; ++i) {
        if (s[i + 1] <= s[i]) continue;
        const double mid = 0.5 * (s[i] + s[i + 1]);
        const bool segInside = torusInside(R, r, q + u * mid) <= 0;
        if (segInside && !inside) {
            start = s[i];
            inside = true;
        } else if (!segInside && inside) {
            if (count < kMaxPrimitiveSpans) {
                const double ta = t0 + start / len, tb = t0 + s[i] / len;
                out[count].in = Boundary{ta, torusNormal(R, o + d * ta), 0};
                out[count].out = Boundary{tb, torusNormal(R, o + d * tb), 0};
                ++count;
            }
            inside = false;
        }
    }
    if (inside && count < kMaxPrimitiveSpans) {
        const double ta = t0 + start / len, tb = t0 + sEnd / len;
        out[count].in = Boundary{ta, torusNormal(R, o + d * ta), 0};
        out[count].out = Boundary{tb, torusNormal(R, o + d * tb), 0};
        ++count;
    }
    return count;
}

double evalPoly(const double* c, int degree, double x) {
    double v = c[degree];
    for (int i = degree - 1; i >= 0; --i) v = v * x + c[i];
    return v;
}

// The root of a polynomial monotone on [a, b] with a sign change, by Newton's method
// kept inside the bracket (bisection when a step leaves it or stalls).
double refineRoot(const double* c, const double* dc, int degree, double a, double b, double fa) {
    double x = 0.5 * (a + b);
    for (int iter = 0; iter < 200; ++iter) {
        const double fx = evalPoly(c, degree, x);
        if (fx == 0) return x;
        if ((fx < 0) == (fa < 0)) {
            a = x;
            fa = fx;
        } else {
            b = x;
        }
        if (b - a <=
                4 * std::numeric_limits<double>::epsilon() * std::max(std::fabs(a), std::fabs(b)) ||
            b - a < 1e-300)
            break;
        const double dfx = evalPoly(dc, degree - 1, x);
        double next = dfx != 0 ? x - fx / dfx : 0.5 * (a + b);
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        // Newton converging slowly (a multiple root nearby): bisect instead.
        if (std::fabs(next - x) > 0.5 * (b - a)) next = 0.5 * (a + b);
        x = next;
    }
    return x;
}

}  // namespace

int solvePolynomial(const double* coeffs, int degree, double lo, double hi, double* roots) {
    double c[5];
    for (int i = 0; i <= degree; ++i) c[i] = coeffs[i];
    while (degree > 0 && c[degree] == 0) --degree;
    if (degree <= 0 || !(lo <= hi)) return 0;
    if (degree == 1) {
        const double x = -c[0] / c[1];
        if (x >= lo && x <= hi) {
            roots[0] = x;
            return 1;
        }
        return 0;
    }
    double dc[4];
    for (int i = 1; i <= degree; ++i) dc[i - 1] = c[i] * i;
    double crit[6];
    crit[0] = lo;
    int nc = solvePolynomial(dc, degree - 1, lo, hi, crit + 1);
    crit[nc + 1] = hi;
    int n = 0;
    for (int i = 0; i <= nc; ++i) {
        const double a = crit[i], b = crit[i + 1];
        const double fa = evalPoly(c, degree, a), fb = evalPoly(c, degree, b);
        double root;
        if (fa == 0) {
            root = a;
        } else if (fb == 0) {
            if (i < nc) continue;  // found as the next segment's start
            root = b;
        } else if ((fa < 0) != (fb < 0)) {
            root = refineRoot(c, dc, degree, a, b, fa);
        } else {
            continue;
        }
        if (n > 0 && root <= roots[n - 1]) continue;
        roots[n++] = root;
    }
    return n;
}

int intersectSolid(PrimitiveKind kind, const double* args, const Vec3& o, const Vec3& d,
                   Span out[kMaxPrimitiveSpans]) {
    switch (kind) {
        case PrimitiveKind::Sphere:
            return sphere(o, d, out);
        case PrimitiveKind::Cube:
            return cube(o, d, out);
        case PrimitiveKind::Cylinder:
            return cylinder(o, d, out);
        case PrimitiveKind::Cone:
            return cone(o, d, out);
        case PrimitiveKind::Tetrahedron:
            return tetrahedron(o, d, out);
        case PrimitiveKind::Torus:
            return torus(args, o, d, out);
        case PrimitiveKind::Plane:
            return plane(o, d, out);
        case PrimitiveKind::Empty:
        case PrimitiveKind::Tri1:
        case PrimitiveKind::Tri2:
        case PrimitiveKind::Triangle:
            return 0;
    }
    return 0;
}

bool intersectTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& o, const Vec3& d,
                       double tmin, double tmax, Boundary& hit) {
    // Moeller-Trumbore, with a small tolerance on the barycentric coordinates so that rays
    // through an edge shared by two triangles (computed in different frames) hit one.
    constexpr double kEdge = 1e-9;
    const Vec3 e1 = b - a, e2 = c - a;
    const Vec3 pv = cross(d, e2);
    const double det = dot(e1, pv);
    if (det == 0) return false;
    const double inv = 1.0 / det;
    const Vec3 tv = o - a;
    const double u = dot(tv, pv) * inv;
    if (u < -kEdge || u > 1 + kEdge) return false;
    const Vec3 qv = cross(tv, e1);
    const double v = dot(d, qv) * inv;
    if (v < -kEdge || u + v > 1 + kEdge) return false;
    const double t = dot(e2, qv) * inv;
    if (!(t > tmin && t < tmax)) return false;
    hit.t = t;
    hit.normal = cross(e1, e2);
    return true;
}

bool insideSolid(PrimitiveKind kind, const double* args, const Vec3& p) {
    switch (kind) {
        case PrimitiveKind::Sphere:
            return dot(p, p) <= 1;
        case PrimitiveKind::Cube:
            return std::fabs(p.x) <= 1 && std::fabs(p.y) <= 1 && std::fabs(p.z) <= 1;
        case PrimitiveKind::Cylinder:
            return p.x * p.x + p.y * p.y <= 1 && p.z >= 0 && p.z <= 1;
        case PrimitiveKind::Cone:
            return p.z >= 0 && p.z <= 1 && std::sqrt(p.x * p.x + p.y * p.y) <= 1 - p.z;
        case PrimitiveKind::Tetrahedron:
            return -p.x - p.y - p.z <= 1 && p.x + p.y - p.z <= 1 && -p.x + p.y + p.z <= 1 &&
                   p.x - p.y + p.z <= 1;
        case PrimitiveKind::Torus:
            return torusInside(args[0], args[1], p) <= 0;
        case PrimitiveKind::Plane:
            return p.z <= 0;
        default:
            return false;
    }
}

}  // namespace pcsg::tracer
