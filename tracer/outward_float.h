// Doubles rounded outwards to floats, for boxes that only cull (a BVH's child boxes,
// unrolled_instances.h): the float box holds the double box, so it never culls a ray
// that the double box lets through.
#pragma once

#include <cmath>
#include <limits>

namespace pcsg::tracer {

// The largest float at most x (NaN stays NaN; below -FLT_MAX: -infinity).
inline float floatBelow(double x) {
    constexpr float kMax = std::numeric_limits<float>::max();
    if (x > kMax) return kMax;  // (also +infinity: the largest float is at most it)
    if (x < -kMax) return -std::numeric_limits<float>::infinity();
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = std::nextafter(f, -kMax);
    return f;
}

// The smallest float at least x (NaN stays NaN; above FLT_MAX: +infinity).
inline float floatAbove(double x) {
    return -floatBelow(-x);
}

}  // namespace pcsg::tracer
