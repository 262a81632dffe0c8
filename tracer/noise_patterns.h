// POV-Ray 3.7's noise-based pigment patterns (bozo = spotted, granite, wood, marble, agate,
// wrinkles, dents), its classic turbulence warp, and the per-pattern defaults the caller
// must reproduce (wave form, whether turbulence is already inside, default colour map).
//
// Everything here is in pattern space: the caller has already mapped the point through the
// pattern's transformations (PatternSpec::toPattern) as POV-Ray's Warp_EPoint does.
#pragma once

#include <vector>

#include "geometry.h"
#include "texture.h"

namespace pcsg {

// The raw value of a noise-based pattern at a pattern-space point, in [0, 1]: POV-Ray's
// EvaluateRaw for that pattern, BEFORE frequency, phase, wave form and colour map, and
// including the turbulence the pattern applies itself (see PatternDefaults). For the
// kinds listed by patternDefaults(k).turbulenceInside == true, the caller must NOT also
// warp the point with turbulenceWarp. Returns 0 for kinds that are not noise-based.
double noisePatternValue(const PatternSpec& spec, const Vec3& patternPoint);

// POV-Ray's classic turbulence warp (`turbulence`, `octaves`, `omega`, `lambda` in a
// pattern): p + t.amount * DTurbulence(p) componentwise. Returns p when !t.on().
Vec3 turbulenceWarp(const Turbulence& t, const Vec3& p);

// POV-Ray's wave forms, applied after value * frequency + phase (the caller's job).
enum class WaveForm : uint8_t { Ramp, Triangle, Sine, Scallop, Cubic };

// Applies a wave form to a value already reduced to [0, 1] by frequency and phase.
double applyWaveForm(WaveForm w, double value);

// What POV-Ray does by default for a pattern kind (facts and their sources are in
// noise_patterns.cpp's comment above patternDefaults).
struct PatternDefaults {
    WaveForm wave = WaveForm::Ramp;  // the wave form used when the scene names none
    bool usesFrequency = true;       // false for the discrete patterns (checker, brick, hexagon)
    bool turbulenceInside = false;   // true: noisePatternValue applied the turbulence itself
    std::vector<ColourMapEntry> colourMap;  // POV-Ray's map when none is given (may be empty
                                            // for list patterns: their colours default)
};

PatternDefaults patternDefaults(PatternKind kind);

}  // namespace pcsg
