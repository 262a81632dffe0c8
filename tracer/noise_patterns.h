// POV-Ray 3.7's noise-based pigment patterns (bozo = spotted, granite, wood, marble, agate,
// wrinkles, dents), its classic turbulence warp, its wave forms, and the per-pattern
// defaults the caller must reproduce (wave form, frequency, turbulence, default colour map).
//
// How the patterns branch uses this for a pigment at a point (POV-Ray 3.7's
// Compute_Pigment, Warp_EPoint, Evaluate_TPat):
//
//     Vec3 p = spec.toPattern.point(pointInPaintFrame);      // the transformations
//     const PatternDefaults d = patternDefaults(spec.kind);
//     double raw;
//     if (d.turbulenceInside) {                              // the 7 noise patterns
//         raw = noisePatternValue(spec, p);                  // applies the turbulence
//     } else {
//         p = turbulenceWarp(spec.turbulence, p);            // POV-Ray's classic warp
//         raw = yourPattern(spec, p);
//     }
//     double v = d.continuous ? waveValue(raw, spec.frequency, spec.phase, wave) : raw;
//     then the colour map (or d.colourMap when the pigment has none).
//
// `turbulence` is always applied after all the pattern's transformations, whatever the
// order they were written in: POV-Ray keeps the classic turbulence as the last warp of
// the pattern (parstxtr.cpp Check_Turb, "one and only one classic turb may exist in a warp
// chain ... it must be the last") and puts every scale, rotate and translate into one
// transform before it (pattern.cpp Transform_Tpattern). So turbulence scales with the
// pattern.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry.h"
#include "texture.h"

namespace pcsg {

// The raw value of a noise-based pattern at a pattern-space point (after the pattern's
// transformations, BEFORE turbulence): POV-Ray's pattern function for that kind, before
// frequency, phase, wave form and colour map, including the turbulence: the classic warp
// p + amount * DTurbulence(p) for bozo, granite, wrinkles, dents and agate (agate also
// reads Turbulence(p) * agate_turb itself), and the special handling of wood (the point
// moved by cycloidal((x + DTurbulence.x) * amount.x) in x, likewise in y, no warp) and
// marble (x + amount.x * Turbulence(p), no warp). In [0, 1] except wood (the distance from
// the z axis) and marble (x plus turbulence), which POV-Ray folds with frequency and its
// triangle wave. Returns 0 for kinds that are not noise-based.
double noisePatternValue(const PatternSpec& spec, const Vec3& patternPoint);

// POV-Ray's classic turbulence warp, for the patterns that do not handle turbulence
// themselves: p + amount * DTurbulence(p) componentwise. Returns p when !t.on().
Vec3 turbulenceWarp(const Turbulence& t, const Vec3& p);

// POV-Ray's wave forms (ramp_wave, triangle_wave, sine_wave, scallop_wave, cubic_wave).
enum class WaveForm : uint8_t { Ramp, Triangle, Sine, Scallop, Cubic };

// Applies a wave form to a value in [0, 1] (pattern.cpp Evaluate_TPat's switch).
double applyWaveForm(WaveForm w, double value);

// POV-Ray's Evaluate_TPat after the pattern function, exactly: when frequency != 0,
// v = fmod(raw * frequency + phase, 1.00001); then v -= floor(v) if v < 0; then the wave
// form. (With frequency 0, phase is ignored, as in POV-Ray.)
double waveValue(double raw, double frequency, double phase, WaveForm w);

// POV-Ray's cycloidal(v) = sin(2 pi frac(v)) as 3.7 computes it, and Triangle_Wave(v).
double cycloidal(double v);
double triangleWave(double v);

// What POV-Ray does by default for a pattern kind; the facts and their sources are in the
// comment above patternDefaults in noise_patterns.cpp.
struct PatternDefaults {
    WaveForm wave = WaveForm::Ramp;  // the wave form when the scene names none
    bool continuous = true;          // false: a discrete pattern (checker, brick, hexagon)
                                     // whose value is used as is (POV-Ray sets its
                                     // frequency to 0)
    bool turbulenceInside = false;   // true: noisePatternValue applies the turbulence; do
                                     // not warp the point with turbulenceWarp as well
    // POV-Ray's colour map when the pigment gives none. For checker, brick and hexagon,
    // the colours by pattern value (0, 1, 2) when the list gives none: checker blue,
    // green; brick mortar grey, brick red; hexagon blue, green, red.
    std::vector<ColourMapEntry> colourMap;
};

// `spotted` is bozo with the grey default map instead of bozo's (pass true when the
// pigment was written `spotted`).
PatternDefaults patternDefaults(PatternKind kind, bool spotted = false);

}  // namespace pcsg
