// What ∪ ∩ \ do with one ray, shared by the walk of the cyclic graph (traversal.cpp) and
// the walk of expanded sub-graph instances (expanded_instances.cpp), so that both find
// the same surface by the same arithmetic:
//
//  - first hit of a union: operands front to back by the entry of the ray into their
//    boxes, stopping when the next box starts beyond the nearest hit so far;
//  - span lists of ∪ ∩ \ (Roth 1982): operands combined one by one with span_list.h,
//    the window of t narrowed by the first operand of ∩ and \;
//  - the first boundary of a span list;
//  - ties: of two surfaces at exactly the same t, the one with the smaller instance path
//    wins, whatever the order the walk found them in.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "geometry.h"
#include "graph.h"
#include "primitives.h"
#include "span_list.h"

namespace pcsg::tracer {

// A ray in some node's frame: the direction is never normalised, so t is the same number
// in every frame. The reciprocals of the direction's components are computed at the ray's
// first box test in this frame (clipToBox below) and kept for the others: a node's boxes
// are tested with one set of divisions, and rays that meet no box (into a primitive) pay
// none.
struct LocalRay {
    Vec3 o, d;

    LocalRay(const Vec3& origin, const Vec3& dir) : o(origin), d(dir) {}

    // 1 / d per axis; hasZeroAxis(): some component of d is zero (its reciprocal is
    // infinite, and the box test takes the careful path).
    const Vec3& inverse() const {
        if (inverseState_ == kUnknown) computeInverse();
        return inverse_.v;
    }
    bool hasZeroAxis() const { return inverseState_ == kZeroAxis; }

  private:
    static constexpr uint8_t kUnknown = 0, kFinite = 1, kZeroAxis = 2;
    void computeInverse() const {
#if defined(__SSE2__)
        // (the same three divisions; the zero test in one compare of each register)
        const __m128d xy = _mm_loadu_pd(&d.x), z = _mm_load_sd(&d.z), one = _mm_set1_pd(1.0);
        _mm_storeu_pd(&inverse_.v.x, _mm_div_pd(one, xy));
        _mm_store_sd(&inverse_.v.z, _mm_div_sd(one, z));
        const __m128d zero = _mm_setzero_pd();
        const int zeros =
            _mm_movemask_pd(_mm_cmpeq_pd(xy, zero)) | (_mm_movemask_pd(_mm_cmpeq_sd(z, zero)) & 1);
        inverseState_ = zeros != 0 ? kZeroAxis : kFinite;
#else
        inverse_.v = Vec3{1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
        inverseState_ = (d.x == 0 || d.y == 0 || d.z == 0) ? kZeroAxis : kFinite;
#endif
    }
    // Left unwritten until computeInverse (most rays of the expansions' links and
    // matrices are made, copied and dropped without a box test in their frame).
    union Inverse {
        Inverse() {}
        Vec3 v;
    };
    mutable Inverse inverse_;
    mutable uint8_t inverseState_ = kUnknown;
};

// The nearest surface found so far.
struct Hit {
    double t = 0;
    Vec3 normal;  // in the frame of the node that returned it
    uint32_t material = 0;
    bool valid = false;  // a surface was found
    uint64_t key = 0;    // the instance path of what was hit: breaks ties in t
    uint32_t paint = 0;  // the tracer's handle on the frame of the material's paint node
};

// Does a surface at t from the instance `key` replace the nearest one so far (at tmax)?
inline bool nearer(double t, uint64_t key, double tmax, const Hit& hit) {
    return t < tmax || (t == tmax && hit.valid && key < hit.key);
}

// Clips [t0, t1] to the part of the line inside the box; false when nothing is left.
inline bool clipToBox(const Box& b, const Vec3& o, const Vec3& d, double& t0, double& t1) {
    if (b.lo.x > b.hi.x) return false;  // empty
    for (int i = 0; i < 3; ++i) {
        if (d[i] == 0) {
            if (o[i] < b.lo[i] || o[i] > b.hi[i]) return false;
            continue;
        }
        const double inv = 1.0 / d[i];
        double a = (b.lo[i] - o[i]) * inv, c = (b.hi[i] - o[i]) * inv;
        if (a > c) std::swap(a, c);
        if (a > t0) t0 = a;
        if (c < t1) t1 = c;
        if (!(t0 <= t1)) return false;
    }
    return true;
}

// The same for a LocalRay, with the reciprocals of its direction computed once per frame,
// and the same arithmetic: every bound is (lo - o) * (1 / d) as above, and the result is
// the same (where the loop above stops at the first axis that empties [t0, t1], this takes
// all three, which only shrinks [t0, t1] further; nothing reads t0 and t1 after false).
inline bool clipToBox(const Box& b, const LocalRay& r, double& t0, double& t1) {
    const Vec3& inv = r.inverse();
    if (r.hasZeroAxis()) return clipToBox(b, r.o, r.d, t0, t1);
    if (b.lo.x > b.hi.x) return false;  // empty
    double lo = t0, hi = t1;
    // Per axis, as `if (a > c) swap(a, c)`, `if (a > lo) lo = a`, `if (c < hi) hi = c` but
    // without branches: SSE2's min and max return their second operand when the first
    // comparison fails, as these do (also for NaN, which a subnormal d can give).
#if defined(__SSE2__)
    {
        const __m128d o = _mm_loadu_pd(&r.o.x), iv = _mm_loadu_pd(&inv.x);
        const __m128d a = _mm_mul_pd(_mm_sub_pd(_mm_loadu_pd(&b.lo.x), o), iv);
        const __m128d c = _mm_mul_pd(_mm_sub_pd(_mm_loadu_pd(&b.hi.x), o), iv);
        const __m128d near = _mm_min_pd(c, a), far = _mm_max_pd(a, c);
        const __m128d l = _mm_max_pd(near, _mm_set1_pd(lo));
        const __m128d h = _mm_min_pd(far, _mm_set1_pd(hi));
        const double lx = _mm_cvtsd_f64(l), ly = _mm_cvtsd_f64(_mm_unpackhi_pd(l, l));
        const double hx = _mm_cvtsd_f64(h), hy = _mm_cvtsd_f64(_mm_unpackhi_pd(h, h));
        lo = ly > lx ? ly : lx;
        hi = hy < hx ? hy : hx;
    }
#else
    for (int i = 0; i < 2; ++i) {
        const double a = (b.lo[i] - r.o[i]) * inv[i], c = (b.hi[i] - r.o[i]) * inv[i];
        const double near = a > c ? c : a, far = a > c ? a : c;
        lo = near > lo ? near : lo;
        hi = far < hi ? far : hi;
    }
#endif
    const double a = (b.lo.z - r.o.z) * inv.z, c = (b.hi.z - r.o.z) * inv.z;
    const double near = a > c ? c : a, far = a > c ? a : c;
    lo = near > lo ? near : lo;
    hi = far < hi ? far : hi;
    if (!(lo <= hi)) return false;
    t0 = lo;
    t1 = hi;
    return true;
}

// Whether operand i is in a union's mask of leading operands (firstOfUnion).
inline bool leadsUnion(uint32_t lead, uint32_t i) {
    return i < 32 && ((lead >> i) & 1u);
}

// The first hit among a union's operands. `entry(i, t0)` sets t0 to where the ray enters
// operand i's box within [tmin, tmax] and returns false when it misses the box;
// `first(i, tmax, hit)` looks for a nearer surface in operand i. `order` is scratch space
// (used as a stack, so the walk may recurse).
// `lead` (bit i: operand i, i < 32) names operands looked at first, in operand order,
// whatever their boxes' entry: cheap ones (TraceScene::unionLeads: a primitive below
// constant steps) whose hit then narrows the window of the others, as a sea's plane does
// for the terrain under it, whose box the ray enters first. The union's hit is the nearest
// (t, instance path) of all its operands whatever the order they are looked at in (nearer()),
// and a box only culls what lies beyond the nearest hit, so the hit is the same.
template <class Entry, class First>
bool firstOfUnion(uint32_t count, double tmin, double& tmax, Hit& hit, bool anyHit,
                  std::vector<std::pair<double, uint32_t>>& order, Entry entry, First first,
                  uint32_t lead = 0) {
    bool found = false;
    for (uint32_t i = 0; lead != 0 && i < count && i < 32; ++i) {
        double t0 = tmin;
        if (!leadsUnion(lead, i) || !entry(i, t0) || t0 > tmax) continue;
        if (first(i, tmax, hit)) {
            found = true;
            if (anyHit) return true;
        }
    }
    // Few operands (a BVH node's two halves, most unions of a derivation): sorted by
    // insertion on the stack, in the same order as std::sort gives below (by entry, then
    // by operand: the pairs are distinct, so the sorted order is unique).
    constexpr uint32_t kFew = 8;
    if (count <= kFew) {
        struct Entered {
            double t0;
            uint32_t i;
        } few[kFew];  // (left uninitialised: filled below as far as it is read)
        uint32_t m = 0;
        for (uint32_t i = 0; i < count; ++i) {
            double t0 = tmin;
            if (leadsUnion(lead, i) || !entry(i, t0)) continue;
            uint32_t k = m++;
            for (; k > 0 && few[k - 1].t0 > t0; --k) few[k] = few[k - 1];
            few[k] = {t0, i};
        }
        for (uint32_t k = 0; k < m; ++k) {
            if (few[k].t0 > tmax) break;  // (at tmax exactly it may still win a tie)
            if (first(few[k].i, tmax, hit)) {
                found = true;
                if (anyHit) break;
            }
        }
        return found;
    }
    const size_t base = order.size();
    for (uint32_t i = 0; i < count; ++i) {
        double t0 = tmin;
        if (!leadsUnion(lead, i) && entry(i, t0)) order.emplace_back(t0, i);
    }
    const size_t end = order.size();
    if (end - base > 1) std::sort(order.begin() + base, order.begin() + end);
    for (size_t k = base; k < end; ++k) {
        const auto [t0, i] = order[k];
        if (t0 > tmax) break;  // (at tmax exactly it may still win a tie)
        if (first(i, tmax, hit)) {
            found = true;
            if (anyHit) break;
        }
    }
    order.resize(base);
    return found;
}

// The first boundary of spans[base, base + count) with tmin < t < tmax (or at tmax,
// winning the tie): becomes `hit`.
inline bool boundaryHit(const std::vector<Span>& spans, size_t base, size_t count, double tmin,
                        double tmax, uint64_t key, Hit& hit) {
    for (size_t k = 0; k < count; ++k) {
        const Span& s = spans[base + k];
        const Boundary* b = nullptr;
        if (s.in.t > tmin)
            b = &s.in;
        else if (s.out.t > tmin)
            b = &s.out;
        else
            continue;
        if (!nearer(b->t, key, tmax, hit)) return false;
        hit = Hit{b->t, b->normal, b->material, true, key, b->paint};
        return true;
    }
    return false;
}

// The span list of an operator over `count`
// operands, appended to `spans` at its end; returns the number of spans. `inWindow(i, lo,
// hi)` says whether operand i's box meets the window [lo, hi]; `operand(i, lo, hi)`
// appends operand i's spans and returns their number.
template <class InWindow, class Operand>
size_t combineOperands(CsgOp op, uint32_t count, std::vector<Span>& spans, double tmin, double tmax,
                       InWindow inWindow, Operand operand) {
    const size_t base = spans.size();
    size_t acc = 0;
    double lo = tmin, hi = tmax;
    for (uint32_t i = 0; i < count; ++i) {
        // Empty in the window: an intersection becomes empty, and so does a difference
        // whose first operand is.
        const bool emptiesAll = emptyOperandEmptiesAll(op, i);
        if (!inWindow(i, lo, hi)) {
            if (emptiesAll) {
                spans.resize(base);
                return 0;
            }
            continue;
        }
        const size_t cbase = base + acc;
        const size_t n = operand(i, lo, hi);
        if (n == 0) {
            if (emptiesAll) {
                spans.resize(base);
                return 0;
            }
            continue;
        }
        if (i == 0 || (op == CsgOp::Union && acc == 0)) {
            acc = n;  // already at base
        } else {
            // Combine [base, base+acc) with [cbase, cbase+n) above them, then move the
            // result down to base.
            const size_t rbase = cbase + n;
            spans.resize(rbase + acc + n);
            Span* s = spans.data();
            size_t m = 0;
            switch (op) {
                case CsgOp::Union:
                    m = uniteSpans(s + base, acc, s + cbase, n, s + rbase);
                    break;
                case CsgOp::Intersection:
                    m = intersectSpans(s + base, acc, s + cbase, n, s + rbase);
                    break;
                case CsgOp::Difference:
                    m = subtractSpans(s + base, acc, s + cbase, n, s + rbase);
                    break;
            }
            std::memmove(static_cast<void*>(s + base), s + rbase, m * sizeof(Span));
            acc = m;
            spans.resize(base + acc);
            if (acc == 0 && op != CsgOp::Union) return 0;
        }
        // ∩ and \ never grow beyond their first operand: narrow the window.
        if (op != CsgOp::Union) {
            lo = std::max(lo, spans[base].in.t);
            hi = std::min(hi, spans[base + acc - 1].out.t);
        }
    }
    return acc;
}

}  // namespace pcsg::tracer
