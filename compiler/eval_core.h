// What the plain stack machine (eval.cpp) and the fast machine (fast_eval.cpp) share, so
// that both compute every value with the same code: the functions of the language, the
// mixers behind rand(), the pick of choose(). Internal to the compiler library, but for
// the instance path's mixers, which the tracer's expanded instances inline too.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "graph.h"

namespace pcsg {

// std::pow and std::log of the language's pow() and ln(), recalled per thread by the bits of
// their arguments as sinDegrees() is (eval.cpp): the terrains repeat them at every triangle
// that shares a corner or an edge. The same bits as std::pow and std::log.
double powRecalled(double a, double b);
double lnRecalled(double a);

// SplitMix64's finaliser: a bijective 64-bit mixer.
constexpr uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
constexpr double toUnit(uint64_t h) {
    return static_cast<double>(h >> 11) * 0x1.0p-53;
}

// The instance path's steps (eval.h's pathChild and pathRule), inline.
inline uint64_t pathChildInline(uint64_t path, uint32_t childIndex) {
    return mix64(path ^ (0x6a09e667f3bcc908ULL + (static_cast<uint64_t>(childIndex) << 1)));
}
inline uint64_t pathRuleInline(uint64_t path, uint32_t ruleIndex) {
    return mix64(path ^ (0xbb67ae8584caa73bULL + (static_cast<uint64_t>(ruleIndex) << 1)));
}

// rand(x) and rand() (eval.h's randOf and randAt), inline for the machines' loops.
inline double randOfInline(uint64_t seed, double x) {
    if (x == 0) x = 0;  // -0 and +0 are the same argument
    // So is every NaN: which NaN an operation gives (its sign, its payload) is up to the
    // compiler, which may swap the operands of + and * (the sanitizer build does).
    if (std::isnan(x)) x = std::numeric_limits<double>::quiet_NaN();
    const uint64_t bits = std::bit_cast<uint64_t>(x);
    return toUnit(mix64(mix64(bits ^ 0x3c6ef372fe94f82bULL) ^ mix64(seed + 0xa54ff53a5f1d36f1ULL)));
}
inline double randAtInline(uint64_t seed, uint64_t path, uint32_t callSite) {
    return toUnit(mix64(mix64(path ^ mix64(seed + 0x510e527fade682d1ULL)) + callSite));
}

// Function f of the n arguments a[0..n).
double callFunc(Func f, const double* a, uint32_t n, uint64_t seed);

// choose(w1..wn): whether the weights are valid (finite, not negative, not all zero), and
// the rule number 1..n that u in [0,1) picks from valid weights.
bool chooseWeightsValid(const double* w, uint32_t n);
double choosePick(const double* w, uint32_t n, double u);

// Runs Graph::fastCode from `start` to its End: loads read `frame`, Store writes `out`, and
// `result` gets the value. False when the plain code would throw there (an unassigned
// read, invalid choose() weights): the caller runs the plain code, which reports it.
bool runFast(const Graph& g, uint32_t start, const double* frame, double* out, uint64_t path,
             double& result);

}  // namespace pcsg
