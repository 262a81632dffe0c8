// What POV-Ray 3.7.0 does by default for each pattern of docs/language.md section 10, so
// that the patterns branch reproduces it. The facts and where they come from:
//
//  - Wave form (source/backend/parser/parstxtr.cpp, Parse_Pattern; pattern.cpp
//    Init_TPat_Fields): every pattern starts with ramp_wave, frequency 1, phase 0; `wood`
//    and `marble` set triangle_wave. Evaluate_TPat then applies frequency, phase and the
//    wave to every pattern's value (waveValue in noise_patterns.h).
//  - Discrete patterns (Parse_Pattern): `checker`, `brick` and `hexagon` set frequency 0,
//    so their values 0, 1 (2 for hexagon) are used as they are. Their colours come from the
//    list after the keyword (Parse_Blend_List), and when it is empty from the defaults below.
//    brick's mortar defaults to 0.5 - 2 EPSILON, and `mortar m` stores m - 2 EPSILON
//    (EPSILON = 1e-10); brick_size defaults to <8, 3, 4.5>.
//  - Turbulence (warps.cpp Warp_EPoint): the classic turbulence warp moves the point of
//    every pattern except `wood` and `marble`, which read the turbulence in their own way
//    (pattern.cpp wood_pattern, marble_pattern); `agate` is warped AND reads Turbulence
//    itself. `agate` creates the turbulence settings (octaves 6, omega 0.5, lambda 2, amount
//    0) even when none is written (Parse_Pattern: Check_Turb), with agate_turb 1.
//    noisePatternValue does all of this for the seven noise patterns.
//  - Default colour maps (pigment.cpp Post_Pigment, when the pigment has no color_map):
//    bozo (not spotted), wood, marble, agate, radial, checker, brick and hexagon have
//    their own (below, pigment.cpp's Bozo_Entries, Wood_Entries, Marble_Entries,
//    Agate_Entries, Radial_Entries, Hex_Entries, Brick_Entries; checker uses the first two
//    of Hex_Entries); every other pattern (spotted, granite, wrinkles, dents, gradient,
//    onion, leopard) gets black at 0 to white at 1.
#include "noise_patterns.h"

namespace pcsg {
namespace {

ColourMapEntry entry(double value, double r, double g, double b) {
    return ColourMapEntry{value, FilterColour{Vec3{r, g, b}, 0.0, 0.0}};
}

std::vector<ColourMapEntry> defaultColourMap(PatternKind kind, bool spotted) {
    switch (kind) {
        case PatternKind::Bozo:
            if (spotted) break;
            return {entry(0.4, 1, 1, 1), entry(0.4, 0, 1, 0), entry(0.6, 0, 1, 0),
                    entry(0.6, 0, 0, 1), entry(0.8, 0, 0, 1), entry(0.8, 1, 0, 0)};
        case PatternKind::Wood:
            return {entry(0.6, 0.666, 0.312, 0.2), entry(0.6, 0.4, 0.1333, 0.066)};
        case PatternKind::Marble:
            return {entry(0.0, 0.9, 0.8, 0.8), entry(0.9, 0.9, 0.08, 0.08), entry(0.9, 0, 0, 0)};
        case PatternKind::Agate:
            return {entry(0.0, 1, 1, 1),       entry(0.5, 0.95, 0.75, 0.5),
                    entry(0.5, 0.9, 0.7, 0.5), entry(0.6, 0.9, 0.7, 0.4),
                    entry(0.6, 1.0, 0.7, 0.4), entry(1.0, 0.6, 0.3, 0.0)};
        case PatternKind::Radial:
            return {entry(0.0, 0, 1, 1), entry(0.333, 1, 1, 0), entry(0.666, 1, 0, 1),
                    entry(1.0, 0, 1, 1)};
        case PatternKind::Checker:
            return {entry(0.0, 0, 0, 1), entry(1.0, 0, 1, 0)};
        case PatternKind::Hexagon:
            return {entry(0.0, 0, 0, 1), entry(1.0, 0, 1, 0), entry(2.0, 1, 0, 0)};
        case PatternKind::Brick:
            return {entry(0.0, 0.5, 0.5, 0.5), entry(1.0, 0.6, 0.15, 0.15)};
        case PatternKind::Plain:
            return {};
        default:
            break;
    }
    return {entry(0.0, 0, 0, 0), entry(1.0, 1, 1, 1)};
}

// The seven noise patterns, which noisePatternValue evaluates with their turbulence.
bool isNoiseKind(PatternKind kind) {
    switch (kind) {
        case PatternKind::Bozo:
        case PatternKind::Granite:
        case PatternKind::Wood:
        case PatternKind::Marble:
        case PatternKind::Agate:
        case PatternKind::Wrinkles:
        case PatternKind::Dents:
            return true;
        default:
            return false;
    }
}

}  // namespace

PatternDefaults patternDefaults(PatternKind kind, bool spotted) {
    PatternDefaults d;
    d.colourMap = defaultColourMap(kind, spotted);
    d.wave = (kind == PatternKind::Wood || kind == PatternKind::Marble) ? WaveForm::Triangle
                                                                        : WaveForm::Ramp;
    d.continuous = !(kind == PatternKind::Checker || kind == PatternKind::Brick ||
                     kind == PatternKind::Hexagon || kind == PatternKind::Plain);
    d.turbulenceInside = isNoiseKind(kind);
    return d;
}

}  // namespace pcsg
