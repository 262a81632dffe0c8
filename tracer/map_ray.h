// A ray mapped through a chain of affine matrices (the expansions' enter() and linked
// rays), in SSE2, with the very results of Affine::point and Affine::vector applied one
// matrix after the other: the same products and sums in the same order (each coordinate
// ((l0 x + l1 y) + l2 z), plus t for the point), so that a hit's t and normal stay the
// graph walk's bit for bit.
//
// The ray is kept as three pairs (x of the origin and of the direction, then y, then z):
// each row of a matrix is then three products and two sums of pairs, and the origin's
// translation one scalar sum, about two thirds of the scalar code's instructions.
#pragma once

#include "geometry.h"
#include "operators.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace pcsg::tracer {

#if defined(__SSE2__)

// (o[a], d[a]) for each axis a.
struct PairedRay {
    __m128d x, y, z;
};

inline PairedRay pairedRay(const Vec3& o, const Vec3& d) {
    return {_mm_set_pd(d.x, o.x), _mm_set_pd(d.y, o.y), _mm_set_pd(d.z, o.z)};
}

// Row i of m applied to both: (l[i][0] x + l[i][1] y) + l[i][2] z, then + t[i] for the
// origin only (_mm_add_sd leaves the direction's lane as it is).
inline __m128d mapRow(const double* row, double t, const PairedRay& p) {
    const __m128d s =
        _mm_add_pd(_mm_mul_pd(_mm_set1_pd(row[0]), p.x), _mm_mul_pd(_mm_set1_pd(row[1]), p.y));
    return _mm_add_sd(_mm_add_pd(s, _mm_mul_pd(_mm_set1_pd(row[2]), p.z)), _mm_set_sd(t));
}

inline PairedRay mapPaired(const Affine& m, const PairedRay& p) {
    return {mapRow(m.l[0], m.t.x, p), mapRow(m.l[1], m.t.y, p), mapRow(m.l[2], m.t.z, p)};
}

inline LocalRay localRay(const PairedRay& p) {
    alignas(16) double x[2], y[2], z[2];
    _mm_store_pd(x, p.x);
    _mm_store_pd(y, p.y);
    _mm_store_pd(z, p.z);
    return LocalRay{Vec3{x[0], y[0], z[0]}, Vec3{x[1], y[1], z[1]}};
}

#endif

// m.point(r.o) and m.vector(r.d) for each matrix of ms[refs[0..count)] in turn.
inline LocalRay mapRay(const Affine* ms, const uint32_t* refs, uint32_t count, const LocalRay& r) {
#if defined(__SSE2__)
    PairedRay p = pairedRay(r.o, r.d);
    for (uint32_t k = 0; k < count; ++k) p = mapPaired(ms[refs[k]], p);
    return localRay(p);
#else
    LocalRay rr{r.o, r.d};
    for (uint32_t k = 0; k < count; ++k) {
        const Affine& m = ms[refs[k]];
        rr = LocalRay{m.point(rr.o), m.vector(rr.d)};
    }
    return rr;
#endif
}

// The same for a single matrix.
inline LocalRay mapRay(const Affine& m, const LocalRay& r) {
#if defined(__SSE2__)
    return localRay(mapPaired(m, pairedRay(r.o, r.d)));
#else
    return LocalRay{m.point(r.o), m.vector(r.d)};
#endif
}

}  // namespace pcsg::tracer
