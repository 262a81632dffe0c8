// POV-Ray 3.7 textures as the compiler reads them (docs/language.md section 10): a pigment
// (a colour, or a pattern with a colour map) and a normal (a perturbation pattern). The
// compiler fills these in, the tracer evaluates them (tracer/pigment.h, tracer/noise.h,
// tracer/normal_patterns.h) and the exporter writes them back as POV-Ray text.
//
// Pattern values are constants: unlike the plain colour and the finish, they may not read
// the time (section 11).
#pragma once

#include <cstdint>
#include <vector>

#include "geometry.h"

namespace pcsg {

// A colour with POV-Ray's filter (light passes, tinted by the colour) and transmit (light
// passes untinted).
struct FilterColour {
    Vec3 rgb{0, 0, 0};
    double filter = 0;
    double transmit = 0;
};

// POV-Ray's turbulence modifiers: `turbulence <x,y,z>` (a number is all three), `octaves`,
// `omega`, `lambda`, with POV-Ray's defaults.
struct Turbulence {
    Vec3 amount{0, 0, 0};
    int octaves = 6;
    double omega = 0.5;
    double lambda = 2.0;
    bool on() const { return amount.x != 0 || amount.y != 0 || amount.z != 0; }
};

// The patterns of section 10. Plain is a pigment without a pattern (its colour only).
enum class PatternKind : uint8_t {
    Plain,
    Checker,
    Gradient,
    Onion,
    Leopard,
    Radial,
    Brick,
    Hexagon,
    Bozo,  // also `spotted`
    Granite,
    Wood,
    Marble,
    Agate,
    Wrinkles,
    Dents,
};

struct ColourMapEntry {
    double value = 0;
    FilterColour colour;
};

// One of a pattern's transformations as written (the exporter writes them back).
struct PatternTransform {
    enum Kind : uint8_t { Scale, Rotate, Translate } kind = Scale;
    Vec3 v{1, 1, 1};
};

// What a pattern is and where it lives, shared by pigments and normals.
struct PatternSpec {
    PatternKind kind = PatternKind::Plain;
    bool spotted = false;       // Bozo written `spotted`: POV-Ray's grey default map
    Vec3 gradient{1, 0, 0};     // gradient's axis
    Vec3 brickSize{8, 3, 4.5};  // brick_size
    double mortar = 0.5;        // brick's mortar
    double agateTurb = 1.0;     // agate_turb
    double frequency = 1.0;
    double phase = 0.0;
    Turbulence turbulence;
    // From the paint node's frame into pattern space: the inverse of the pattern's scale,
    // rotate and translate, in the order written.
    Affine toPattern = Affine::identity();
    Affine fromPattern = Affine::identity();  // its inverse (the transformations as written)
    bool transformed = false;
    std::vector<PatternTransform> transforms;  // as written, in order
    bool turbulenceWritten = false;            // turbulence, octaves, omega or lambda was written
};

struct Pigment {
    PatternSpec pattern;
    // Plain: Material::color with filter and transmit. Checker, brick: two colours (brick:
    // brick, mortar ... as POV-Ray orders them); hexagon: three.
    std::vector<FilterColour> listColours;
    std::vector<ColourMapEntry> colourMap;  // empty: POV-Ray's default map for the pattern
    bool hasColourMap() const { return !colourMap.empty(); }
};

// The normal perturbations of section 10.
enum class NormalKind : uint8_t { None, Bumps, Dents, Wrinkles, Ripples, Waves };

struct NormalSpec {
    NormalKind kind = NormalKind::None;
    double amount = 0.5;  // POV-Ray's default bump_size
    PatternSpec pattern;  // frequency, phase, turbulence and transformations
};

}  // namespace pcsg
