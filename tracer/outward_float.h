// Doubles rounded outwards to floats, for boxes that only cull (a BVH's child boxes,
// unrolled_instances.h): the float box holds the double box, so it never culls a ray
// that the double box lets through.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// floatBelow (floatAbove) of x[0..3] into out[0..3], the same bits, four at a time with
// SSE2 where the target has it (a four-wide BVH node rounds 24 bounds, collapse() in
// unrolled_instances.cpp): the casts round to nearest, a cast that went above x steps down
// one (sign ? +1 : -1 on the bits: -0 steps to -denorm_min; +0 never went above x, nor
// did a cast to -FLT_MAX), and min(FLT_MAX, f) takes +infinity to FLT_MAX and keeps NaN.
#if defined(__SSE2__)
inline __m128 floatsBelowSse2(__m128d x01, __m128d x23) {
    const __m128 f = _mm_movelh_ps(_mm_cvtpd_ps(x01), _mm_cvtpd_ps(x23));
    const __m128d above01 = _mm_cmpgt_pd(_mm_cvtps_pd(f), x01);
    const __m128d above23 = _mm_cmpgt_pd(_mm_cvtps_pd(_mm_movehl_ps(f, f)), x23);
    const __m128i above = _mm_castps_si128(
        _mm_shuffle_ps(_mm_castpd_ps(above01), _mm_castpd_ps(above23), _MM_SHUFFLE(2, 0, 2, 0)));
    const __m128i bits = _mm_castps_si128(f);
    const __m128i sign = _mm_srai_epi32(bits, 31);  // 0 or -1
    const __m128i away = _mm_or_si128(_mm_add_epi32(sign, sign), _mm_set1_epi32(1));
    const __m128i stepped = _mm_sub_epi32(bits, _mm_and_si128(above, away));
    return _mm_min_ps(_mm_set1_ps(std::numeric_limits<float>::max()), _mm_castsi128_ps(stepped));
}
#endif

inline void floatsBelow(const double x[4], float out[4]) {
#if defined(__SSE2__)
    _mm_storeu_ps(out, floatsBelowSse2(_mm_loadu_pd(x), _mm_loadu_pd(x + 2)));
#else
    for (int k = 0; k < 4; ++k) out[k] = floatBelow(x[k]);
#endif
}

inline void floatsAbove(const double x[4], float out[4]) {
#if defined(__SSE2__)
    const __m128d flip = _mm_set1_pd(-0.0);
    const __m128 below =
        floatsBelowSse2(_mm_xor_pd(_mm_loadu_pd(x), flip), _mm_xor_pd(_mm_loadu_pd(x + 2), flip));
    _mm_storeu_ps(out, _mm_xor_ps(below, _mm_set1_ps(-0.0f)));
#else
    for (int k = 0; k < 4; ++k) out[k] = floatAbove(x[k]);
#endif
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
