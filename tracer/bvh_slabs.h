// The box test of the expansions' four-wide BVH nodes (unrolled_instances.h): where a ray
// enters each of a node's four child boxes, and which of them it meets.
//
// Boxes only cull there: a hit is the nearest (t, instance path) of the operands whose
// boxes the ray meets, whatever the order they are visited in, and a box that lets more
// rays through never changes a hit (the boxes are padded and rounded outwards already).
// So a test may let through more than the exact one, and report entries a little
// earlier, as long as it never culls a box that the exact test lets through, nor reports
// an entry later than it:
//
//  - enterChildren: the reference, in doubles, two children per SSE2 register, with
//    clipToBox's rule for a NaN bound (it culls nothing).
//  - enterChildrenFloat: all four children in one SSE register of floats, with the ray in
//    floats (FloatRay, made once per walk of a hierarchy) and each entry and exit widened
//    by a bound of the rounding errors of floats against doubles, so that its entries are
//    at most enterChildren's and it meets every child that enterChildren meets (the
//    tests check both on rays that graze boxes). Half the instructions of the doubles.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "operators.h"
#include "outward_float.h"
#include "unrolled_instances.h"

namespace pcsg::tracer {

// Where the ray enters each of a BVH node's child boxes within [tmin, tmax] (t0[c]), and
// which it meets at all (bit c of the result; never an empty slot). Boxes are only
// culling here: hits do not depend on them, so they are tested two at a time in SSE2
// registers, in doubles, with the same rule as clipToBox for a NaN (it culls nothing).
inline int enterChildren(const UnrolledInstance::BvhNode& b, const LocalRay& r, double tmin,
                         double tmax, double t0[4]) {
    int used = 0;
    for (int c = 0; c < 4; ++c) used |= (b.child[c] != kNone) << c;
    const Vec3& inv = r.inverse();
#if defined(__SSE2__)
    if (!r.hasZeroAxis()) {
        __m128d lo[2] = {_mm_set1_pd(tmin), _mm_set1_pd(tmin)};
        __m128d hi[2] = {_mm_set1_pd(tmax), _mm_set1_pd(tmax)};
        for (int a = 0; a < 3; ++a) {
            const __m128d o = _mm_set1_pd(r.o[a]), iv = _mm_set1_pd(inv[a]);
            const __m128 bl = _mm_load_ps(b.lo[a]), bh = _mm_load_ps(b.hi[a]);
            const __m128d l[2] = {_mm_cvtps_pd(bl), _mm_cvtps_pd(_mm_movehl_ps(bl, bl))};
            const __m128d h[2] = {_mm_cvtps_pd(bh), _mm_cvtps_pd(_mm_movehl_ps(bh, bh))};
            for (int p = 0; p < 2; ++p) {
                const __m128d x = _mm_mul_pd(_mm_sub_pd(l[p], o), iv);
                const __m128d y = _mm_mul_pd(_mm_sub_pd(h[p], o), iv);
                lo[p] = _mm_max_pd(_mm_min_pd(y, x), lo[p]);
                hi[p] = _mm_min_pd(_mm_max_pd(x, y), hi[p]);
            }
        }
        _mm_storeu_pd(t0, lo[0]);
        _mm_storeu_pd(t0 + 2, lo[1]);
        const int mask = _mm_movemask_pd(_mm_cmple_pd(lo[0], hi[0])) |
                         (_mm_movemask_pd(_mm_cmple_pd(lo[1], hi[1])) << 2);
        return mask & used;
    }
#endif
    int mask = 0;
    for (int c = 0; c < 4; ++c) {
        if (!(used & (1 << c))) continue;
        const Box box{{b.lo[0][c], b.lo[1][c], b.lo[2][c]}, {b.hi[0][c], b.hi[1][c], b.hi[2][c]}};
        double t1 = tmax;
        t0[c] = tmin;
        if (clipToBox(box, r, t0[c], t1)) mask |= 1 << c;
    }
    return mask;
}

// enterChildren with the entries rounded down to floats (at most the doubles').
inline int enterChildrenBelow(const UnrolledInstance::BvhNode& b, const LocalRay& r, double tmin,
                              double tmax, float t0[4]) {
    double t[4];
    const int mask = enterChildren(b, r, tmin, tmax, t);
    for (int c = 0; c < 4; ++c) t0[c] = floatBelow(t[c]);
    return mask;
}

#if defined(__SSE2__)

// A ray in floats for enterChildrenFloat, made once per walk of a hierarchy: `ok` only
// where the float test's error bound holds (no zero axis; the float origin and 1/d with
// |o| < 2^60 and 2^-60 < |1/d| < 2^60, so that no float product is a NaN and the margin
// is finite), else the walk takes enterChildren.
struct FloatRay {
    __m128 o[3], inv[3];
    __m128 tmin, margin;
    bool ok = false;
};

// The constants of enterChildrenFloat's widening, operands in memory of its instructions.
// Defined in bvh_slabs.cpp, out of the compiler's sight: with their values known, GCC
// broadcast each from a scalar at every node (the walk's calls leave no register to keep
// them in), and copying them into every walk's FloatRay cost ~16 instructions a walk.
struct alignas(16) FloatSlabConstants {
    float down[4], up[4], max[4], lowest[4];
    // floatRay's: its checks' bounds (2^60, 2^-60), the margin's factor and floor (2^-21,
    // 2^-120), and the mask of a float's magnitude
    float big[4], small[4], reachFactor[4], floor[4];
    uint32_t magnitude[4];
};
extern const FloatSlabConstants kFloatSlabs;

// The error bound: for a slab bound t = (lo - o) / d, the float origin is off by at most
// 2^-24 |o|, and the difference, 1/d and the product by 2^-24 of theirs, so the float
// result a and the double one A differ by |a - A| <= 2^-22 |a| + 2^-23 |o / d| (A's own
// error is ~2^-52 |A|; tmin and tmax in floats are off by 2^-24 of theirs).
// enterChildrenFloat widens each entry and exit by 2^-19 of itself (2^-21 after the
// widening's own rounding) and by `margin` = 2^-21 max |o / d| + 2^-120 (underflow).
inline FloatRay floatRay(const LocalRay& r, double tmin) {
    FloatRay f;
    const Vec3& inv = r.inverse();
    if (r.hasZeroAxis()) return f;
    // (x, y, z, 0) in floats; a double beyond the floats' range becomes an infinity
    const __m128 o =
        _mm_movelh_ps(_mm_cvtpd_ps(_mm_loadu_pd(&r.o.x)), _mm_cvtpd_ps(_mm_set_sd(r.o.z)));
    const __m128 iv =
        _mm_movelh_ps(_mm_cvtpd_ps(_mm_loadu_pd(&inv.x)), _mm_cvtpd_ps(_mm_set_sd(inv.z)));
    const FloatSlabConstants& k = kFloatSlabs;
    const __m128 magnitude = _mm_load_ps(reinterpret_cast<const float*>(k.magnitude));
    const __m128 ao = _mm_and_ps(o, magnitude), ai = _mm_and_ps(iv, magnitude);
    const __m128 big = _mm_load_ps(k.big);
    const __m128 in = _mm_and_ps(_mm_and_ps(_mm_cmplt_ps(ao, big), _mm_cmplt_ps(ai, big)),
                                 _mm_cmpgt_ps(ai, _mm_load_ps(k.small)));
    if ((_mm_movemask_ps(in) & 7) != 7) return f;  // (a NaN fails too)
    __m128 reach = _mm_mul_ps(ao, ai);             // (the fourth lane 0)
    reach = _mm_max_ps(reach, _mm_shuffle_ps(reach, reach, _MM_SHUFFLE(2, 3, 0, 1)));
    reach = _mm_max_ps(reach, _mm_movehl_ps(reach, reach));
    reach = _mm_shuffle_ps(reach, reach, 0);
    f.margin = _mm_add_ps(_mm_mul_ps(reach, _mm_load_ps(k.reachFactor)), _mm_load_ps(k.floor));
    f.o[0] = _mm_shuffle_ps(o, o, 0x00);
    f.o[1] = _mm_shuffle_ps(o, o, 0x55);
    f.o[2] = _mm_shuffle_ps(o, o, 0xaa);
    f.inv[0] = _mm_shuffle_ps(iv, iv, 0x00);
    f.inv[1] = _mm_shuffle_ps(iv, iv, 0x55);
    f.inv[2] = _mm_shuffle_ps(iv, iv, 0xaa);
    f.tmin = _mm_set1_ps(static_cast<float>(tmin));
    f.ok = true;
    return f;
}

// enterChildren in floats (f.ok): t0[c] at most enterChildren's, and every child it meets
// met. The slabs take the doubles' operand order, so a NaN bound culls nothing here too;
// the widened entries stay below FLT_MAX and the exits above -FLT_MAX (a float that
// overflows is then still on the right side of a double that does not).
inline int enterChildrenFloat(const UnrolledInstance::BvhNode& b, const FloatRay& f, double tmax,
                              float t0[4]) {
    __m128 lo = f.tmin, hi = _mm_set1_ps(static_cast<float>(tmax));
    for (int a = 0; a < 3; ++a) {
        const __m128 x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(b.lo[a]), f.o[a]), f.inv[a]);
        const __m128 y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(b.hi[a]), f.o[a]), f.inv[a]);
        lo = _mm_max_ps(_mm_min_ps(y, x), lo);
        hi = _mm_min_ps(_mm_max_ps(x, y), hi);
    }
    const FloatSlabConstants& k = kFloatSlabs;
    const __m128 down = _mm_load_ps(k.down), up = _mm_load_ps(k.up);
    lo = _mm_sub_ps(_mm_min_ps(_mm_mul_ps(lo, down), _mm_mul_ps(lo, up)), f.margin);
    hi = _mm_add_ps(_mm_max_ps(_mm_mul_ps(hi, down), _mm_mul_ps(hi, up)), f.margin);
    lo = _mm_min_ps(lo, _mm_load_ps(k.max));
    hi = _mm_max_ps(hi, _mm_load_ps(k.lowest));
    _mm_storeu_ps(t0, lo);
    const __m128i empty = _mm_cmpeq_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(b.child)),
                                          _mm_set1_epi32(-1));
    const int used = ~_mm_movemask_ps(_mm_castsi128_ps(empty)) & 15;
    return _mm_movemask_ps(_mm_cmple_ps(lo, hi)) & used;
}

#endif

}  // namespace pcsg::tracer
