// Reading pigment and normal patterns: see build_pattern.h.
#include "build_pattern.h"

#include <fmt/format.h>

#include <array>

#include "eval.h"
#include "lexer.h"

namespace pcsg {

namespace {

struct PatternWord {
    std::string_view name;
    PatternKind kind;
};
constexpr std::array<PatternWord, 15> kPatterns = {{
    {"checker", PatternKind::Checker},
    {"gradient", PatternKind::Gradient},
    {"onion", PatternKind::Onion},
    {"leopard", PatternKind::Leopard},
    {"radial", PatternKind::Radial},
    {"brick", PatternKind::Brick},
    {"hexagon", PatternKind::Hexagon},
    {"bozo", PatternKind::Bozo},
    {"spotted", PatternKind::Bozo},
    {"granite", PatternKind::Granite},
    {"wood", PatternKind::Wood},
    {"marble", PatternKind::Marble},
    {"agate", PatternKind::Agate},
    {"wrinkles", PatternKind::Wrinkles},
    {"dents", PatternKind::Dents},
}};

struct NormalWord {
    std::string_view name;
    NormalKind kind;
};
constexpr std::array<NormalWord, 5> kNormals = {{
    {"bumps", NormalKind::Bumps},
    {"dents", NormalKind::Dents},
    {"wrinkles", NormalKind::Wrinkles},
    {"ripples", NormalKind::Ripples},
    {"waves", NormalKind::Waves},
}};

constexpr std::string_view kPigmentItems =
    "color, the patterns checker, gradient, onion, leopard, radial, brick, hexagon, bozo, "
    "spotted, granite, wood, marble, agate, wrinkles, dents, and color_map, frequency, phase, "
    "turbulence, octaves, omega, lambda, brick_size, mortar, agate_turb, scale, rotate, "
    "translate";
constexpr std::string_view kNormalItems =
    "bumps, dents, wrinkles, ripples, waves, and frequency, phase, turbulence, octaves, omega, "
    "lambda, scale, rotate, translate";

// How many list colours a pattern takes (0: it is colour-mapped).
size_t listSize(PatternKind k) {
    switch (k) {
        case PatternKind::Checker:
        case PatternKind::Brick:
            return 2;
        case PatternKind::Hexagon:
            return 3;
        default:
            return 0;
    }
}

bool isColourWord(std::string_view w) {
    return w == "color" || w == "colour" || w == "rgb" || w == "rgbf" || w == "rgbt" ||
           w == "rgbft";
}

class Reader {
  public:
    Reader(BuildContext& ctx, PatternValues& v, AtomRange& r, const Atom& item)
        : ctx_(ctx), v_(v), r_(r), item_(item), name_(ctx.text(item.tok)) {}

    bool modifier(PatternSpec& s, std::string_view block);
    void listColours(Pigment& p);
    void colourMap(Pigment& p);
    void patternArguments(PatternSpec& s);

  private:
    bool nextIs(AtomKind k) const { return !r_.done() && ctx_.ast.atoms[r_.i].kind == k; }
    const Atom& peek() const { return ctx_.ast.atoms[r_.i]; }
    void transform(PatternSpec& s, PatternTransform::Kind kind);
    bool turbulenceItem(PatternSpec& s);
    bool mapEntry(const Atom& bracket, Pigment& p);

    BuildContext& ctx_;
    PatternValues& v_;
    AtomRange& r_;
    const Atom& item_;
    std::string_view name_;
};

// scale, rotate, translate: composed after the transformations before them.
void Reader::transform(PatternSpec& s, PatternTransform::Kind kind) {
    const auto v = v_.vector(r_, item_, kind == PatternTransform::Scale);
    if (!v) return;
    Affine m;
    if (kind == PatternTransform::Scale) {
        if (v->x == 0 || v->y == 0 || v->z == 0) {
            ctx_.error(item_.tok, "a pattern's scale must not be 0 in any component");
            return;
        }
        m = Affine::scale(*v);
    } else if (kind == PatternTransform::Translate) {
        m = Affine::translate(*v);
    } else {  // POV-Ray's rotate <a, b, c>: about x, then y, then z, in degrees
        const double ax = v->x, ay = v->y, az = v->z;
        m = makeTransform(TransformOp::RotZ, &az) * makeTransform(TransformOp::RotY, &ay) *
            makeTransform(TransformOp::RotX, &ax);
    }
    s.fromPattern = m * s.fromPattern;
    s.toPattern = s.fromPattern.inverse();
    s.transformed = true;
    s.transforms.push_back(PatternTransform{kind, *v});
}

bool Reader::turbulenceItem(PatternSpec& s) {
    Turbulence& t = s.turbulence;
    if (name_ == "turbulence") {
        if (const auto v = v_.vector(r_, item_, true)) t.amount = *v;
    } else if (name_ == "octaves") {
        if (const auto v = v_.number(r_, item_)) {
            if (*v < 1 || *v > 10 || *v != static_cast<int>(*v))
                ctx_.error(
                    item_.tok,
                    fmt::format("octaves must be a whole number from 1 to 10, found {}", *v));
            else
                t.octaves = static_cast<int>(*v);
        }
    } else if (name_ == "omega") {
        if (const auto v = v_.number(r_, item_)) t.omega = *v;
    } else if (name_ == "lambda") {
        if (const auto v = v_.number(r_, item_)) t.lambda = *v;
    } else {
        return false;
    }
    s.turbulenceWritten = true;
    return true;
}

// The modifiers pigments and normals share; false when `item` is none of them.
bool Reader::modifier(PatternSpec& s, std::string_view block) {
    if (name_ == "scale") return transform(s, PatternTransform::Scale), true;
    if (name_ == "rotate") return transform(s, PatternTransform::Rotate), true;
    if (name_ == "translate") return transform(s, PatternTransform::Translate), true;
    if (name_ == "frequency") {
        if (const auto v = v_.number(r_, item_)) s.frequency = *v;
        return true;
    }
    if (name_ == "phase") {
        if (const auto v = v_.number(r_, item_)) s.phase = *v;
        return true;
    }
    if (turbulenceItem(s)) return true;
    const bool brickItem = name_ == "brick_size" || name_ == "mortar";
    if (brickItem || name_ == "agate_turb") {
        const PatternKind owner = brickItem ? PatternKind::Brick : PatternKind::Agate;
        if (s.kind != owner) {
            ctx_.error(item_.tok, fmt::format("'{}' in {} applies to the pattern {} only", name_,
                                              block, brickItem ? "brick" : "agate"));
            v_.skipValues(r_);
        } else if (name_ == "brick_size") {
            if (const auto v = v_.vector(r_, item_, true)) s.brickSize = *v;
        } else if (const auto v = v_.number(r_, item_)) {
            (name_ == "mortar" ? s.mortar : s.agateTurb) = *v;
        }
        return true;
    }
    return false;
}

// The arguments right after a pattern word: gradient's axis.
void Reader::patternArguments(PatternSpec& s) {
    if (s.kind != PatternKind::Gradient) return;
    const auto v = v_.vector(r_, item_, false);
    if (!v) return;
    if (v->x == 0 && v->y == 0 && v->z == 0)
        ctx_.error(item_.tok, "gradient's axis must not be <0, 0, 0>");
    else
        s.gradient = normalize(*v);  // POV-Ray normalises it: only its direction counts
}

// checker, brick, hexagon: up to their number of colours right after the pattern word.
void Reader::listColours(Pigment& p) {
    const size_t want = listSize(p.pattern.kind);
    while (p.listColours.size() < want && nextIs(AtomKind::Word) &&
           isColourWord(ctx_.text(peek().tok))) {
        const Atom& c = ctx_.ast.atoms[r_.i++];
        const auto colour = v_.colour(r_, c);
        if (!colour) return;
        p.listColours.push_back(*colour);
    }
    if (!p.listColours.empty() && p.listColours.size() < want)
        ctx_.error(item_.tok, fmt::format("'{}' takes {} colours, found {}", name_, want,
                                          p.listColours.size()));
}

// One entry `[v color c]`, or the pair `[v1, v2 color c1 color c2]`.
bool Reader::mapEntry(const Atom& bracket, Pigment& p) {
    AtomRange r{bracket.first, bracket.first + bracket.count};
    std::vector<double> values;
    while (values.size() < 2 && !r.done() && ctx_.ast.atoms[r.i].kind == AtomKind::Number) {
        const auto v = v_.constant(ctx_.ast.atoms[r.i++]);
        if (!v) return false;
        values.push_back(*v);
    }
    std::vector<FilterColour> colours;
    while (colours.size() < values.size() && !r.done() &&
           ctx_.ast.atoms[r.i].kind == AtomKind::Word &&
           isColourWord(ctx_.text(ctx_.ast.atoms[r.i].tok))) {
        const Atom& c = ctx_.ast.atoms[r.i++];
        const auto colour = v_.colour(r, c);
        if (!colour) return false;
        colours.push_back(*colour);
    }
    if (values.empty() || colours.size() != values.size() || !r.done()) {
        const uint32_t at = r.done() ? bracket.tok : ctx_.ast.atoms[r.i].tok;
        ctx_.error(at, fmt::format("a colour map entry is '[value color ...]' or '[value1, "
                                   "value2 color ... color ...]"));
        return false;
    }
    for (size_t k = 0; k < values.size(); ++k)
        p.colourMap.push_back(ColourMapEntry{values[k], colours[k]});
    return true;
}

// color_map { [v color c] ... } (also colour_map), with POV-Ray's rules: values in
// increasing order (equal values make a sharp edge), at most 256 entries.
void Reader::colourMap(Pigment& p) {
    if (listSize(p.pattern.kind) != 0) {
        ctx_.error(item_.tok, fmt::format("'{}' does not apply to {}: it takes its colours as "
                                          "a list after the pattern word",
                                          name_, patternName(p.pattern.kind)));
    }
    if (!nextIs(AtomKind::Block)) {
        ctx_.error(item_.tok,
                   fmt::format("'{}' takes a block '{{ [value color ...] ... }}'", name_));
        v_.skipValues(r_);
        return;
    }
    const Atom& b = ctx_.ast.atoms[r_.i++];
    p.colourMap.clear();
    bool bad = false;
    for (uint32_t k = b.first; k < b.first + b.count && !bad; ++k) {
        const Atom& e = ctx_.ast.atoms[k];
        if (e.kind != AtomKind::Bracket) {
            ctx_.error(e.tok, fmt::format("expected a colour map entry '[value color ...]' in "
                                          "'{}', found {}",
                                          name_, describe(ctx_.src, ctx_.tokens[e.tok])));
            bad = true;
            continue;
        }
        const size_t before = p.colourMap.size();
        bad = !mapEntry(e, p);
        for (size_t j = std::max<size_t>(before, 1); j < p.colourMap.size(); ++j)
            if (p.colourMap[j].value < p.colourMap[j - 1].value)
                ctx_.error(e.tok, fmt::format("colour map entries must be in increasing order: "
                                              "{} after {}",
                                              p.colourMap[j].value, p.colourMap[j - 1].value));
    }
    if (p.colourMap.empty() && !bad)
        ctx_.error(b.tok, fmt::format("'{}' needs at least one entry", name_));
    if (p.colourMap.size() > 256)
        ctx_.error(b.tok, fmt::format("'{}' takes at most 256 entries", name_));
}

}  // namespace

bool isPigmentPatternWord(std::string_view w) {
    for (const PatternWord& p : kPatterns)
        if (p.name == w) return true;
    return false;
}

std::string_view patternName(PatternKind k) {
    for (const PatternWord& p : kPatterns)
        if (p.kind == k) return p.name;
    return "plain";
}

std::string_view normalName(NormalKind k) {
    for (const NormalWord& n : kNormals)
        if (n.kind == k) return n.name;
    return "none";
}

std::string_view pigmentPatternItems() {
    return kPigmentItems;
}
std::string_view normalPatternItems() {
    return kNormalItems;
}

bool readPigmentItem(BuildContext& ctx, PatternValues& v, AtomRange& r, const Atom& item,
                     Pigment& p) {
    const std::string_view n = ctx.text(item.tok);
    Reader reader(ctx, v, r, item);
    if (isPigmentPatternWord(n)) {
        if (p.pattern.kind != PatternKind::Plain) {
            ctx.error(item.tok, fmt::format("a pigment has one pattern: '{}' after '{}'", n,
                                            patternName(p.pattern.kind)));
            return true;
        }
        for (const PatternWord& w : kPatterns)
            if (w.name == n) p.pattern.kind = w.kind;
        p.pattern.spotted = n == "spotted";
        reader.patternArguments(p.pattern);
        reader.listColours(p);
        return true;
    }
    const bool known = n == "color_map" || n == "colour_map" || n == "frequency" || n == "phase" ||
                       n == "turbulence" || n == "octaves" || n == "omega" || n == "lambda" ||
                       n == "scale" || n == "rotate" || n == "translate" || n == "brick_size" ||
                       n == "mortar" || n == "agate_turb";
    if (!known) return false;
    if (p.pattern.kind == PatternKind::Plain) {
        ctx.error(item.tok, fmt::format("'{}' in pigment comes after its pattern (checker, "
                                        "gradient, ..., dents)",
                                        n));
        v.skipValues(r);
        while (!r.done() && ctx.ast.atoms[r.i].kind == AtomKind::Block) ++r.i;
        return true;
    }
    if (n == "color_map" || n == "colour_map")
        reader.colourMap(p);
    else
        reader.modifier(p.pattern, "pigment");
    return true;
}

bool readNormalItem(BuildContext& ctx, PatternValues& v, AtomRange& r, const Atom& item,
                    NormalSpec& ns) {
    const std::string_view n = ctx.text(item.tok);
    Reader reader(ctx, v, r, item);
    for (const NormalWord& w : kNormals) {
        if (w.name != n) continue;
        if (ns.kind != NormalKind::None) {
            ctx.error(item.tok, fmt::format("a normal has one pattern: '{}' after '{}'", n,
                                            normalName(ns.kind)));
            return true;
        }
        ns.kind = w.kind;
        if (!r.done() && ctx.ast.atoms[r.i].kind == AtomKind::Number)
            if (const auto a = v.number(r, item)) ns.amount = *a;
        return true;
    }
    if (n == "brick_size" || n == "mortar" || n == "agate_turb") return false;
    const bool known = n == "frequency" || n == "phase" || n == "turbulence" || n == "octaves" ||
                       n == "omega" || n == "lambda" || n == "scale" || n == "rotate" ||
                       n == "translate";
    if (!known) return false;
    if (ns.kind == NormalKind::None) {
        ctx.error(item.tok, fmt::format("'{}' in normal comes after its pattern (bumps, dents, "
                                        "wrinkles, ripples, waves)",
                                        n));
        v.skipValues(r);
        return true;
    }
    return reader.modifier(ns.pattern, "normal");
}

}  // namespace pcsg
