// Reading the patterns of section 10 inside a material's `pigment { }` and `normal { }`
// (docs/language.md section 10): the pattern word with its list colours or amount, and the
// modifiers color_map, frequency, phase, turbulence, octaves, omega, lambda, brick_size,
// mortar, agate_turb, scale, rotate and translate, with POV-Ray 3.7's syntax and meaning.
// An item of POV-Ray's that the language does not have is an error naming it.
//
// The material reader (build_material.cpp) owns the values: it reads numbers, vectors and
// colours for this reader through PatternValues. Pattern values are constants.
#pragma once

#include <optional>
#include <string_view>

#include "ast.h"
#include "build_state.h"
#include "texture.h"

namespace pcsg {

// Atoms [i, end) of Ast::atoms, read from i on.
struct AtomRange {
    uint32_t i, end;
    bool done() const { return i >= end; }
};

// The values of a block, as the material reader reads them (errors reported there).
class PatternValues {
  public:
    virtual ~PatternValues() = default;
    // The value of a number atom.
    virtual std::optional<double> constant(const Atom& number) = 0;
    // The number after `item`.
    virtual std::optional<double> number(AtomRange& r, const Atom& item) = 0;
    // A colour starting at `item` (`color`, `colour`, `rgb`, `rgbf`, `rgbt`, `rgbft`).
    virtual std::optional<FilterColour> colour(AtomRange& r, const Atom& item) = 0;
    // The vector `<x, y, z>` after `item`; with `numberToo`, a number n is <n, n, n>.
    virtual std::optional<Vec3> vector(AtomRange& r, const Atom& item, bool numberToo) = 0;
    // After an error: skips the values up to the next word.
    virtual void skipValues(AtomRange& r) = 0;
};

// A pattern word or modifier of pigment { } at `item` (already taken from r): read into
// p and true, or false when `item` is not one (the caller reports it).
bool readPigmentItem(BuildContext& ctx, PatternValues& v, AtomRange& r, const Atom& item,
                     Pigment& p);

// The same for normal { }.
bool readNormalItem(BuildContext& ctx, PatternValues& v, AtomRange& r, const Atom& item,
                    NormalSpec& n);

// The words readPigmentItem and readNormalItem take, for error messages.
std::string_view pigmentPatternItems();
std::string_view normalPatternItems();

// Whether `w` names a pigment pattern (checker ... dents).
bool isPigmentPatternWord(std::string_view w);

// The name of a pattern as POV-Ray writes it (the exporter's too).
std::string_view patternName(PatternKind k);
std::string_view normalName(NormalKind k);

}  // namespace pcsg
