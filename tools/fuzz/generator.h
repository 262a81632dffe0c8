// Random, valid, terminating PCSG systems for `pcsg fuzz` (docs/fuzz.md).
//
// A system is a function of one 64-bit seed alone: the generator draws from its own
// generator (xoshiro256** seeded by splitmix64), maps integers to numbers by integer
// arithmetic only, and prints every number in thousandths, so that a seed gives the same
// text on every machine and with every standard library (std::uniform_*_distribution
// would not). The camera comes from the object's hyper-bounding box (tracer/bounds.h),
// which is computed by this project's own code from the same text.
//
// What a system holds:
//  - 2 to 4 modules, in notation A (a selection function over the parameters, some with
//    choose()) or notation B (conditions over the formals); each has a terminating rule
//    at d <= 0 and recursive rules that call themselves and later modules with d - 1, so
//    every path ends and the expansion stays small (at most 3 calls a rule, d <= 3);
//  - rule bodies nesting ∪ ∩ \ with every transformation and every primitive, C-nodes,
//    paint, rand() and rand(x); triangles only in modules that no ∩ or \ can reach;
//  - materials, one or two lights, a background, and sometimes a ground plane below the
//    object; sometimes section 10's appearance items (appearance.h): patterns, normals,
//    finish items, transparency and interiors in materials, area lights and spotlights,
//    fog and a sky_sphere.
// Surfaces are never exactly coincident: every primitive gets its own random offset and
// size (in thousandths), and every recursive call its own random transformation.
#pragma once

#include <cstdint>
#include <string>

namespace pcsg::fuzz {

// xoshiro256** (Blackman and Vigna), seeded through splitmix64.
class Rng {
  public:
    explicit Rng(uint64_t seed);
    uint64_t next();
    // Uniform in [0, n) for n >= 1 (by remainder: the tiny bias does not matter here).
    uint64_t below(uint64_t n) { return next() % n; }
    // True with probability percent/100.
    bool percent(int percent) { return below(100) < uint64_t(percent); }
    // An integer in [lo, hi].
    int64_t range(int64_t lo, int64_t hi) { return lo + int64_t(below(uint64_t(hi - lo + 1))); }

  private:
    uint64_t s_[4];
};

// splitmix64's finaliser: a well-mixed 64-bit function of x.
uint64_t mix64(uint64_t x);

// The seed of system `index` of a campaign started with `campaignSeed`.
uint64_t systemSeed(uint64_t campaignSeed, uint64_t index);

// Prints thousandths as a decimal number: 1250 -> "1.25", -5 -> "-0.005", 3000 -> "3".
std::string milli(int64_t thousandths);

// The text of the system for `seed`. It always compiles and renders without run-time
// errors (the tests check both).
std::string generateSystem(uint64_t seed);

}  // namespace pcsg::fuzz
