#include "pov_texture.h"

#include <fmt/format.h>

#include "build_pattern.h"

namespace pcsg {

namespace {

std::string num(double v) {
    return fmt::format("{}", v == 0 ? 0.0 : v);
}

std::string vec(const Vec3& v) {
    return fmt::format("<{},{},{}>", num(v.x), num(v.y), num(v.z));
}

std::string colour(const FilterColour& c) {
    if (c.filter == 0 && c.transmit == 0) return fmt::format("color rgb {}", vec(c.rgb));
    return fmt::format("color rgbft <{},{},{},{},{}>", num(c.rgb.x), num(c.rgb.y), num(c.rgb.z),
                       num(c.filter), num(c.transmit));
}

// The modifiers of a pattern: its own parameters, frequency and phase where not POV-Ray's
// defaults, turbulence, and the transformations in the order written.
std::string modifiers(const PatternSpec& s) {
    std::string out;
    if (s.kind == PatternKind::Brick)
        out += fmt::format(" brick_size {} mortar {}", vec(s.brickSize), num(s.mortar));
    if (s.kind == PatternKind::Agate) out += fmt::format(" agate_turb {}", num(s.agateTurb));
    if (s.frequency != 1) out += fmt::format(" frequency {}", num(s.frequency));
    if (s.phase != 0) out += fmt::format(" phase {}", num(s.phase));
    if (s.turbulenceWritten) {
        const Turbulence& t = s.turbulence;
        out += fmt::format(" turbulence {} octaves {} omega {} lambda {}", vec(t.amount), t.octaves,
                           num(t.omega), num(t.lambda));
    }
    for (const PatternTransform& t : s.transforms) {
        const char* word = t.kind == PatternTransform::Scale    ? "scale"
                           : t.kind == PatternTransform::Rotate ? "rotate"
                                                                : "translate";
        out += fmt::format(" {} {}", word, vec(t.v));
    }
    return out;
}

}  // namespace

std::string povPigment(const Material& m) {
    return povPigment(m.pigment, FilterColour{m.color, m.filter, m.transmit});
}

std::string povPigment(const Pigment& p, const FilterColour& plain) {
    if (p.pattern.kind == PatternKind::Plain) return fmt::format("pigment {{ {} }}", colour(plain));
    std::string out =
        fmt::format("pigment {{ {}", p.pattern.spotted ? "spotted" : patternName(p.pattern.kind));
    if (p.pattern.kind == PatternKind::Gradient) out += fmt::format(" {}", vec(p.pattern.gradient));
    for (const FilterColour& c : p.listColours) out += fmt::format(" {}", colour(c));
    if (p.hasColourMap()) {
        out += " color_map {";
        for (const ColourMapEntry& e : p.colourMap)
            out += fmt::format(" [{} {}]", num(e.value), colour(e.colour));
        out += " }";
    }
    out += modifiers(p.pattern);
    out += " }";
    return out;
}

std::string povNormal(const Material& m) {
    const NormalSpec& n = m.normal;
    if (n.kind == NormalKind::None) return "";
    return fmt::format(" normal {{ {} {}{} }}", normalName(n.kind), num(n.amount),
                       modifiers(n.pattern));
}

}  // namespace pcsg
