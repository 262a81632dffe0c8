// Pattern values (docs/language.md section 10), as POV-Ray 3.7 computes them
// (source/core/material/pattern.cpp): a point in the paint node's frame goes into pattern
// space (PatternSpec::toPattern), through the turbulence warp (unless the pattern applies
// its turbulence itself: marble, wood, agate), to the pattern's raw value, then through
// frequency, phase and the pattern's wave form. checker, brick and hexagon are discrete:
// their value is the index of a list colour, without frequency, phase or wave form.
//
// The noise-based patterns (bozo, granite, wood, marble, agate, wrinkles, dents) and the
// turbulence come from noise_patterns.h; the others are here.
#pragma once

#include "geometry.h"
#include "texture.h"

namespace pcsg::tracer {

// Whether the pattern's value is a list index (checker, brick, hexagon).
bool isListPattern(PatternKind k);

// The raw value of a pattern that is not noise-based, at a point in pattern space (after
// the warp): POV-Ray's EvaluateRaw, or for the list patterns their index (0, 1 or 2).
double plainPatternValue(const PatternSpec& s, const Vec3& p);

// The pattern's value at a point in the paint node's frame: for the list patterns their
// index, else a value in [0, 1] for the colour map.
double patternValue(const PatternSpec& s, const Vec3& paintPoint);

// POV-Ray's frequency and phase on a raw value, then the wave form (ramp for all but wood
// and marble, which are triangular): ContinuousPattern::Evaluate.
double applyFrequencyPhase(const PatternSpec& s, double raw);

}  // namespace pcsg::tracer
