// Ray intersection with the primitives of docs/language.md section 5, in their own coordinates.
//
// The ray is p(t) = origin + t dir with a direction of any length (the tracer never
// normalises directions in child frames, so that t is the same parameter everywhere in
// the graph). Solids return all their intervals along the whole line, sorted, each with
// the outward normal at its entry and at its exit (unnormalised; the zero vector at an
// infinite end). Zero-length intervals (tangent rays) are dropped. Triangles are surfaces
// and return a single hit.
#pragma once

#include <cstdint>

#include "geometry.h"
#include "graph.h"
#include "primitive_table.h"

namespace pcsg::tracer {

struct Boundary {
    double t;
    Vec3 normal;  // outward normal of the solid that owns this boundary, in the frame of the
                  // node that last handled it; zero at an infinite end
    uint32_t material = 0;
    uint32_t paint = 0;  // the tracer's handle on the frame of the material's paint node
};

struct Span {
    Boundary in, out;  // in.t < out.t; in.t may be -inf and out.t +inf
};

// At most this many intervals come out of one primitive (the torus: 2).
inline constexpr int kMaxPrimitiveSpans = 2;

// The intervals of a solid primitive along the ray, sorted; returns their number. `args`
// holds the primitive's arguments (torus: R r). Triangles and `empty` return 0.
int intersectSolid(PrimitiveKind kind, const double* args, const Vec3& origin, const Vec3& dir,
                   Span out[kMaxPrimitiveSpans]);

// The triangle (a, b, c) hit with t in (tmin, tmax): the normal is (b - a) x (c - a).
bool intersectTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& origin,
                       const Vec3& dir, double tmin, double tmax, Boundary& hit);

// Inside test for the solids (points on the surface count as inside), for tests.
bool insideSolid(PrimitiveKind kind, const double* args, const Vec3& p);

// Real roots of c[0] + c[1] x + ... + c[degree] x^degree in [lo, hi], sorted, found by
// isolating them between the roots of the derivative and refining each by safeguarded
// Newton iteration. Returns their number (at most degree). Exposed for tests.
int solvePolynomial(const double* c, int degree, double lo, double hi, double* roots);

}  // namespace pcsg::tracer
