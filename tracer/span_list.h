// Span lists (Roth 1982, "Ray casting for modeling solids"): the parts of a ray inside a
// solid, as sorted, disjoint intervals [in, out] whose ends carry the surface normal and
// material. The Boolean operators of CSG become merges of two sorted lists, each in time
// linear in the lengths of the lists.
//
// Every function reads two sorted, disjoint lists and writes the result, also sorted and
// disjoint, to `out` (which must not alias the inputs and must have room for na + nb
// spans), and returns the number of spans written. Intervals that touch are merged by a
// union (so the shared face of two adjoining solids is not a surface of their union) and
// dropped by an intersection or difference when only a point remains.
#pragma once

#include <cstddef>

#include "primitives.h"

namespace pcsg::tracer {

// a ∪ b.
size_t uniteSpans(const Span* a, size_t na, const Span* b, size_t nb, Span* out);

// a ∩ b.
size_t intersectSpans(const Span* a, size_t na, const Span* b, size_t nb, Span* out);

// a \ b: the boundaries taken from b face the other way (their normals are negated, so that
// they point out of the result), and keep b's material, as the cut faces of a difference do.
size_t subtractSpans(const Span* a, size_t na, const Span* b, size_t nb, Span* out);

// True when t lies in one of the spans (ends included): for tests.
bool insideSpans(const Span* s, size_t n, double t);

}  // namespace pcsg::tracer
