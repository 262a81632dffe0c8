// Doubles rounded outwards to floats, for boxes that only cull (a BVH's child boxes,
// unrolled_instances.h): the float box holds the double box, so it never culls a ray
// that the double box lets through.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pcsg::tracer {

// The float just below f (finite, above -FLT_MAX): std::nextafter(f, -FLT_MAX), one step of
// the bits instead of a call into libm (a terrain patch's hierarchy rounds some 1,500
// bounds).
inline float floatStepDown(float f) {
    const uint32_t bits = std::bit_cast<uint32_t>(f);
    if (f > 0) return std::bit_cast<float>(bits - 1);
    if (f == 0) return -std::numeric_limits<float>::denorm_min();
    return std::bit_cast<float>(bits + 1);
}

// The largest float at most x (NaN stays NaN; below -FLT_MAX: -infinity).
inline float floatBelow(double x) {
    constexpr float kMax = std::numeric_limits<float>::max();
    if (x > kMax) return kMax;  // (also +infinity: the largest float is at most it)
    if (x < -kMax) return -std::numeric_limits<float>::infinity();
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = floatStepDown(f);
    return f;
}

// The smallest float at least x (NaN stays NaN; above FLT_MAX: +infinity).
inline float floatAbove(double x) {
    return -floatBelow(-x);
}

// x cast to float, then stepped down (up) once if the cast went above (below) x: the bits
// std::nextafter(static_cast<float>(x), -inf) (+inf) gives there, without the call into
// libm. Unlike floatBelow, an infinite x stays infinite (the instance boxes' rounding,
// instance_boxes.cpp, which rounds every S-node instance's box so).
inline float castDown(double x) {
    const float f = static_cast<float>(x);
    return static_cast<double>(f) > x ? floatStepDown(f) : f;
}
inline float castUp(double x) {
    const float f = static_cast<float>(x);
    return static_cast<double>(f) < x ? -floatStepDown(-f) : f;
}

}  // namespace pcsg::tracer
