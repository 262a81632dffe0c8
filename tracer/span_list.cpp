#include "span_list.h"

namespace pcsg::tracer {

namespace {
Boundary flipped(const Boundary& b) {
    return Boundary{b.t, -b.normal, b.material, b.paint};
}
}  // namespace

size_t uniteSpans(const Span* a, size_t na, const Span* b, size_t nb, Span* out) {
    size_t i = 0, j = 0, n = 0;
    bool open = false;
    Span cur;
    while (i < na || j < nb) {
        // The next span by start.
        const Span& s = (j >= nb || (i < na && a[i].in.t <= b[j].in.t)) ? a[i++] : b[j++];
        if (open && s.in.t <= cur.out.t) {
            if (s.out.t > cur.out.t) cur.out = s.out;
            continue;
        }
        if (open) out[n++] = cur;
        cur = s;
        open = true;
    }
    if (open) out[n++] = cur;
    return n;
}

size_t intersectSpans(const Span* a, size_t na, const Span* b, size_t nb, Span* out) {
    size_t i = 0, j = 0, n = 0;
    while (i < na && j < nb) {
        const Boundary& in = a[i].in.t >= b[j].in.t ? a[i].in : b[j].in;
        const bool aEndsFirst = a[i].out.t <= b[j].out.t;
        const Boundary& outB = aEndsFirst ? a[i].out : b[j].out;
        if (in.t < outB.t) out[n++] = Span{in, outB};
        if (aEndsFirst)
            ++i;
        else
            ++j;
    }
    return n;
}

size_t subtractSpans(const Span* a, size_t na, const Span* b, size_t nb, Span* out) {
    size_t n = 0, j = 0;
    for (size_t i = 0; i < na; ++i) {
        Boundary in = a[i].in;
        const Boundary& end = a[i].out;
        // Spans of b that end before this span starts cannot touch later spans of a either.
        while (j < nb && b[j].out.t <= in.t) ++j;
        bool alive = true;
        for (size_t k = j; k < nb && b[k].in.t < end.t; ++k) {
            if (b[k].out.t <= in.t) continue;
            if (b[k].in.t > in.t) out[n++] = Span{in, flipped(b[k].in)};
            if (b[k].out.t >= end.t) {
                alive = false;
                break;
            }
            in = flipped(b[k].out);
        }
        if (alive && in.t < end.t) out[n++] = Span{in, end};
    }
    return n;
}

bool insideSpans(const Span* s, size_t n, double t) {
    for (size_t i = 0; i < n; ++i)
        if (t >= s[i].in.t && t <= s[i].out.t) return true;
    return false;
}

}  // namespace pcsg::tracer
