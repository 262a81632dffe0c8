// Reading a material's body: see build_material.h.
#include "build_material.h"

#include <fmt/format.h>

#include <array>
#include <optional>
#include <string_view>

#include "build_pattern.h"

namespace pcsg {

namespace {

constexpr uint8_t kConstant = 255;  // the field of a value that may not read the time

constexpr std::string_view kMaterialTakes =
    "color, ambient, diffuse, phong, phong_size, reflection and the blocks pigment, normal, "
    "finish, interior";
constexpr std::string_view kFinishTakes =
    "ambient, diffuse, brilliance, phong, phong_size, specular, roughness, metallic, reflection, "
    "conserve_energy";
constexpr std::string_view kInteriorTakes = "ior, fade_distance, fade_power, fade_color";

bool isColourWord(std::string_view w) {
    return w == "color" || w == "colour" || w == "rgb" || w == "rgbf" || w == "rgbt" ||
           w == "rgbft";
}

class MaterialReader : public PatternValues {
  public:
    MaterialReader(BuildContext& ctx, ExprCompiler& exprs, uint32_t index)
        : ctx_(ctx), ast_(ctx.ast), exprs_(exprs), m_(ctx.g.materials[index]), index_(index) {}
    // Reads into `scratch` with constant values only (sky_sphere's pigment).
    MaterialReader(BuildContext& ctx, ExprCompiler& exprs, Material& scratch)
        : ctx_(ctx), ast_(ctx.ast), exprs_(exprs), m_(scratch), index_(0), constantOnly_(true) {}

    void body(const Stmt& s);
    void skyBody(const Stmt& s);

  private:
    using Range = AtomRange;

  public:  // PatternValues: the values of patterns, constants
    std::optional<double> constant(const Atom& n) override { return value(n.expr, kConstant); }
    std::optional<double> number(Range& r, const Atom& item) override {
        return number(r, item, kConstant);
    }
    std::optional<FilterColour> colour(Range& r, const Atom& item) override;
    std::optional<Vec3> vector(Range& r, const Atom& item, bool numberToo) override;
    void skipValues(Range& r) override;

  private:
    const Atom& peek(const Range& r) const { return ast_.atoms[r.i]; }
    bool nextIs(const Range& r, AtomKind k) const { return !r.done() && peek(r).kind == k; }
    std::string_view word(const Atom& a) const { return ctx_.text(a.tok); }
    static Range inside(const Atom& a) { return {a.first, a.first + a.count}; }
    std::string describeAtom(const Atom& a) const;

    std::optional<double> value(uint32_t expr, uint8_t field);
    std::optional<double> number(Range& r, const Atom& item, uint8_t field);
    std::optional<FilterColour> colour(Range& r, const Atom& item, uint8_t field);
    std::optional<FilterColour> colourComponents(const Atom& model, const Atom& v, uint8_t field);
    void setColour(const FilterColour& c);
    const Atom* block(Range& r, const Atom& item);
    bool flag(Range& r);
    void reject(Range& r, const Atom& item, std::string_view block, std::string_view takes);

    bool flatItem(Range& r, const Atom& item, std::string_view n);
    void pigment(Range r);
    void finish(Range r);
    bool finishItem(Range& r, const Atom& item, std::string_view n);
    void reflection(Range& r, const Atom& item);
    void reflectionBlock(Range r, const Atom& item);
    void normal(Range r);
    void interior(Range r);
    bool interiorItem(Range& r, const Atom& item, std::string_view n);
    void checkPositive(const Atom& item, double v);

    BuildContext& ctx_;
    const Ast& ast_;
    ExprCompiler& exprs_;
    Material& m_;
    uint32_t index_;
    bool constantOnly_ = false;  // no value may read the time
    bool timed_ = false;         // the last value read reads the time
};

std::string MaterialReader::describeAtom(const Atom& a) const {
    return describe(ctx_.src, ctx_.tokens[a.tok]);
}

// A value: a constant, or one that reads the time, kept as a TimedValue of this material.
std::optional<double> MaterialReader::value(uint32_t expr, uint8_t field) {
    timed_ = false;
    if (field == kConstant || constantOnly_) return exprs_.constant(expr);
    const auto v = exprs_.directiveValue(expr);
    if (!v) return std::nullopt;
    if (v->timed != kNone) {
        ctx_.g.timedValues.push_back(
            TimedValue{DirectiveTarget::Material, index_, field, v->timed});
        timed_ = true;
    }
    return v->value;
}

// The number that follows `item`.
std::optional<double> MaterialReader::number(Range& r, const Atom& item, uint8_t field) {
    if (nextIs(r, AtomKind::Number)) return value(ast_.atoms[r.i++].expr, field);
    if (nextIs(r, AtomKind::Vector)) {
        ctx_.error(item.tok, fmt::format("'{}' takes a number, not a vector", clip(word(item))));
        ++r.i;
    } else if (nextIs(r, AtomKind::Word) && isColourWord(word(peek(r)))) {
        ctx_.error(item.tok,
                   fmt::format("'{}' takes a number here, not a colour", clip(word(item))));
        ++r.i;
        skipValues(r);
    } else {
        ctx_.error(item.tok, fmt::format("'{}' takes a number", clip(word(item))));
    }
    return std::nullopt;
}

// A colour after `item` (`color` or a model word itself): `<r, g, b>` or POV-Ray's `rgb
// <r, g, b>`, `rgbf <r, g, b, f>`, `rgbt <r, g, b, t>`, `rgbft <r, g, b, f, t>`, `rgb x`.
// Its red, green and blue go to fields `field` to `field + 2`, and with `field` 0 (the
// material's colour) its filter and transmit to fields 14 and 15.
std::optional<FilterColour> MaterialReader::colour(Range& r, const Atom& item, uint8_t field) {
    const Atom* model = &item;
    if (word(item) == "color" || word(item) == "colour") {
        if (nextIs(r, AtomKind::Vector)) return colourComponents(item, ast_.atoms[r.i++], field);
        if (!nextIs(r, AtomKind::Word)) {
            ctx_.error(item.tok, fmt::format("'{}' takes a vector '<x, y, z>' or rgb, rgbf, "
                                             "rgbt, rgbft and a vector",
                                             clip(word(item))));
            skipValues(r);
            return std::nullopt;
        }
        model = &ast_.atoms[r.i++];
    }
    const std::string_view m = word(*model);
    if (m != "rgb" && m != "rgbf" && m != "rgbt" && m != "rgbft") {
        ctx_.error(model->tok, fmt::format("expected rgb, rgbf, rgbt, rgbft or a vector '<r, g, "
                                           "b>' in a colour, found '{}'",
                                           clip(m)));
        skipValues(r);
        return std::nullopt;
    }
    if (m == "rgb" && nextIs(r, AtomKind::Number)) {
        const auto g = value(ast_.atoms[r.i++].expr, kConstant);
        if (!g) return std::nullopt;
        return FilterColour{Vec3{*g, *g, *g}};
    }
    if (!nextIs(r, AtomKind::Vector)) {
        ctx_.error(model->tok, fmt::format("'{}' takes a vector", clip(m)));
        skipValues(r);
        return std::nullopt;
    }
    return colourComponents(*model, ast_.atoms[r.i++], field);
}

// A pattern's colour (list colours, colour maps): a constant.
std::optional<FilterColour> MaterialReader::colour(Range& r, const Atom& item) {
    return colour(r, item, kConstant);
}

// A vector `<x, y, z>` after `item` (with numberToo, a number n is <n, n, n>): a constant.
std::optional<Vec3> MaterialReader::vector(Range& r, const Atom& item, bool numberToo) {
    if (numberToo && nextIs(r, AtomKind::Number)) {
        const auto v = value(ast_.atoms[r.i++].expr, kConstant);
        if (!v) return std::nullopt;
        return Vec3{*v, *v, *v};
    }
    if (nextIs(r, AtomKind::Word)) {  // POV-Ray's x, y, z: the unit vectors
        const std::string_view w = word(peek(r));
        if (w == "x" || w == "y" || w == "z") {
            ++r.i;
            return Vec3{w == "x" ? 1.0 : 0.0, w == "y" ? 1.0 : 0.0, w == "z" ? 1.0 : 0.0};
        }
    }
    if (!nextIs(r, AtomKind::Vector)) {
        ctx_.error(item.tok, fmt::format("'{}' takes a vector '<x, y, z>'{}", clip(word(item)),
                                         numberToo ? " or a number" : ""));
        skipValues(r);
        return std::nullopt;
    }
    const Atom& v = ast_.atoms[r.i++];
    if (v.count != 3) {
        ctx_.error(v.tok, fmt::format("'{}' takes a vector of 3 components, found {}",
                                      clip(word(item)), v.count));
        return std::nullopt;
    }
    Vec3 out;
    for (int k = 0; k < 3; ++k) {
        const auto x = value(ast_.lists[v.first + static_cast<uint32_t>(k)], kConstant);
        if (!x) return std::nullopt;
        out[k] = *x;
    }
    return out;
}

// The components of a colour vector `v` after the model word (or `color`).
std::optional<FilterColour> MaterialReader::colourComponents(const Atom& model, const Atom& v,
                                                             uint8_t field) {
    const std::string_view m = word(model);
    const uint32_t want = m == "rgbft" ? 5 : (m == "rgbf" || m == "rgbt") ? 4 : 3;
    if (v.count != want) {
        ctx_.error(v.tok, fmt::format("'{}' takes a vector of {} components, found {}", clip(m),
                                      want, v.count));
        return std::nullopt;
    }
    // Where each component goes: red, green, blue, then filter and/or transmit.
    const bool transmitOnly = m == "rgbt";
    FilterColour c;
    bool ok = true;
    for (uint32_t k = 0; k < v.count; ++k) {
        const bool isTransmit = k == 4 || (k == 3 && transmitOnly);
        const uint8_t slot = k < 3 ? k : (isTransmit ? 15 : 14);
        const uint8_t f = field == kConstant ? kConstant
                          : k < 3            ? static_cast<uint8_t>(field + k)
                          : field == 0       ? slot
                                             : kConstant;
        const auto x = value(ast_.lists[v.first + k], f);
        if (!x)
            ok = false;
        else if (k < 3)
            c.rgb[static_cast<int>(k)] = *x;
        else
            (isTransmit ? c.transmit : c.filter) = *x;
    }
    if (!ok) return std::nullopt;
    return c;
}

// The material's plain colour (flat `color` or a pigment without a pattern).
void MaterialReader::setColour(const FilterColour& c) {
    m_.color = c.rgb;
    m_.filter = c.filter;
    m_.transmit = c.transmit;
}

// The block `{ ... }` that follows `item`, or null (reported).
const Atom* MaterialReader::block(Range& r, const Atom& item) {
    if (nextIs(r, AtomKind::Block)) return &ast_.atoms[r.i++];
    ctx_.error(item.tok, fmt::format("'{}' takes a block '{{ ... }}'", clip(word(item))));
    skipValues(r);
    return nullptr;
}

// An optional boolean after a flag word (`fresnel`, `conserve_energy`): on, off, true,
// false, yes, no or a number; the flag alone is on.
bool MaterialReader::flag(Range& r) {
    if (nextIs(r, AtomKind::Number)) {
        const auto v = value(ast_.atoms[r.i++].expr, kConstant);
        return v && *v != 0;
    }
    if (nextIs(r, AtomKind::Word)) {
        const std::string_view w = word(peek(r));
        const bool on = w == "on" || w == "true" || w == "yes";
        if (on || w == "off" || w == "false" || w == "no") {
            ++r.i;
            return on;
        }
    }
    return true;
}

// After an error: the values up to the next word, so that one mistake is one error.
void MaterialReader::skipValues(Range& r) {
    while (!r.done() && peek(r).kind != AtomKind::Word) ++r.i;
}

// An item the block does not take.
void MaterialReader::reject(Range& r, const Atom& item, std::string_view block,
                            std::string_view takes) {
    ctx_.error(item.tok, fmt::format("unknown {} setting '{}' ({} takes {})", block,
                                     clip(word(item)), block, takes));
    skipValues(r);
    while (nextIs(r, AtomKind::Block) || nextIs(r, AtomKind::Bracket)) ++r.i;
}

// ior (greater than 0), and POV-Ray's fade_distance, fade_power (numbers, constants) and
// fade_color (a colour's red, green and blue).
bool MaterialReader::interiorItem(Range& r, const Atom& item, std::string_view n) {
    if (n == "ior") {
        if (auto v = number(r, item, 13)) {
            checkPositive(item, *v);
            m_.ior = *v;
        }
    } else if (n == "fade_distance" || n == "fade_power") {
        if (auto v = number(r, item, kConstant))
            (n == "fade_power" ? m_.fadePower : m_.fadeDistance) = *v;
    } else if (n == "fade_color" || n == "fade_colour") {
        if (nextIs(r, AtomKind::Word) && isColourWord(word(peek(r)))) {
            const Atom& model = ast_.atoms[r.i++];
            if (auto c = colour(r, model, kConstant)) m_.fadeColour = c->rgb;
        } else if (nextIs(r, AtomKind::Vector)) {
            if (auto c = colourComponents(item, ast_.atoms[r.i++], kConstant))
                m_.fadeColour = c->rgb;
        } else {
            ctx_.error(item.tok, fmt::format("'{}' takes a colour", clip(n)));
            skipValues(r);
        }
    } else {
        return false;
    }
    m_.interior = true;
    return true;
}

void MaterialReader::checkPositive(const Atom& item, double v) {
    if (!timed_ && !(v > 0))
        ctx_.error(item.tok,
                   fmt::format("{} must be greater than 0, found {}", clip(word(item)), v));
}

void MaterialReader::body(const Stmt& s) {
    Range r{s.first, s.first + s.count};
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        if (item.kind != AtomKind::Word) {
            ctx_.error(item.tok,
                       fmt::format("expected a material setting, found {}", describeAtom(item)));
            continue;
        }
        const std::string_view n = word(item);
        if (flatItem(r, item, n)) continue;
        const bool isBlock = n == "pigment" || n == "finish" || n == "normal" || n == "interior";
        if (!isBlock) {
            reject(r, item, "material", kMaterialTakes);
            continue;
        }
        const Atom* b = block(r, item);
        if (!b) continue;
        if (n == "pigment") pigment(inside(*b));
        if (n == "finish") finish(inside(*b));
        if (n == "normal") normal(inside(*b));
        if (n == "interior") interior(inside(*b));
    }
}

// The shorthand of section 7: color, ambient, diffuse, phong, phong_size, reflection.
bool MaterialReader::flatItem(Range& r, const Atom& item, std::string_view n) {
    if (n == "color" || n == "colour") {
        if (nextIs(r, AtomKind::Number)) {
            ctx_.error(item.tok, fmt::format("'{}' takes a vector '<x, y, z>'", clip(n)));
            ++r.i;
        } else if (auto c = colour(r, item, 0)) {
            setColour(*c);
        }
        return true;
    }
    if (n == "reflection") {
        if (auto v = number(r, item, 7)) {
            m_.reflection = *v;
            m_.reflectionRange = false;
        }
        return true;
    }
    if (n == "ambient" || n == "diffuse" || n == "phong" || n == "phong_size")
        return finishItem(r, item, n);
    return false;
}

void MaterialReader::pigment(Range r) {
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        if (item.kind != AtomKind::Word) {
            ctx_.error(item.tok,
                       fmt::format("expected a pigment item, found {}", describeAtom(item)));
            continue;
        }
        const std::string_view n = word(item);
        if (isColourWord(n) && m_.pigment.pattern.kind == PatternKind::Plain) {
            if (auto c = colour(r, item, 0)) setColour(*c);
            continue;
        }
        if (isColourWord(n)) {
            ctx_.error(item.tok, fmt::format("a pigment with a pattern takes its colours from "
                                             "color_map or from the list after '{}', not from "
                                             "'{}'",
                                             patternName(m_.pigment.pattern.kind), clip(n)));
            (void)colour(r, item, kConstant);  // read past it
            continue;
        }
        if (!readPigmentItem(ctx_, *this, r, item, m_.pigment))
            reject(r, item, "pigment", pigmentPatternItems());
    }
}

void MaterialReader::finish(Range r) {
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        if (item.kind != AtomKind::Word) {
            ctx_.error(item.tok,
                       fmt::format("expected a finish item, found {}", describeAtom(item)));
            continue;
        }
        const std::string_view n = word(item);
        if (n == "reflection") {
            reflection(r, item);
        } else if (n == "conserve_energy") {
            m_.conserveEnergy = flag(r);
        } else if (n == "metallic") {
            m_.metallic = 1;
            if (nextIs(r, AtomKind::Number))
                if (auto v = number(r, item, 11)) m_.metallic = *v;
        } else if (!finishItem(r, item, n)) {
            reject(r, item, "finish", kFinishTakes);
        }
    }
}

// The finish items that are one number.
bool MaterialReader::finishItem(Range& r, const Atom& item, std::string_view n) {
    struct Field {
        std::string_view name;
        uint8_t field;
        double Material::*member;
    };
    static constexpr Field kFields[] = {
        {"ambient", 3, &Material::ambient},       {"diffuse", 4, &Material::diffuse},
        {"phong", 5, &Material::phong},           {"phong_size", 6, &Material::phongSize},
        {"brilliance", 8, &Material::brilliance}, {"specular", 9, &Material::specular},
        {"roughness", 10, &Material::roughness}};
    for (const Field& f : kFields) {
        if (n != f.name) continue;
        if (auto v = number(r, item, f.field)) {
            if (n == "roughness") checkPositive(item, *v);
            m_.*f.member = *v;
        }
        return true;
    }
    return false;
}

// `reflection r` or `reflection { [min,] max [fresnel on] [metallic [m]] }`.
void MaterialReader::reflection(Range& r, const Atom& item) {
    if (nextIs(r, AtomKind::Block)) {
        reflectionBlock(inside(ast_.atoms[r.i++]), item);
        return;
    }
    if (auto v = number(r, item, 7)) {
        m_.reflection = *v;
        m_.reflectionRange = false;
    }
}

void MaterialReader::reflectionBlock(Range r, const Atom& at) {
    uint32_t count = 0;
    while (count < 2 && r.i + count < r.end && ast_.atoms[r.i + count].kind == AtomKind::Number)
        ++count;
    if (count == 1) {  // one value is both the minimum and the maximum
        if (auto v = value(ast_.atoms[r.i].expr, 7)) m_.reflection = *v;
        m_.reflectionRange = false;
    } else if (count == 2) {
        if (auto v = value(ast_.atoms[r.i].expr, 12)) m_.reflectionMin = *v;
        if (auto v = value(ast_.atoms[r.i + 1].expr, 7)) m_.reflection = *v;
        m_.reflectionRange = true;
    }
    r.i += count;
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        const std::string_view n = item.kind == AtomKind::Word ? word(item) : "";
        if (n == "fresnel") {
            m_.fresnel = flag(r);
        } else if (n == "metallic") {
            m_.reflectMetallic = 1;
            if (nextIs(r, AtomKind::Number))
                if (auto v = value(ast_.atoms[r.i++].expr, kConstant)) m_.reflectMetallic = *v;
        } else if (item.kind != AtomKind::Word) {
            ctx_.error(item.tok, fmt::format("reflection {{ }} takes one or two numbers first "
                                             "(min, max), found {}",
                                             describeAtom(item)));
        } else {
            ctx_.error(item.tok,
                       fmt::format("unknown reflection setting '{}' (reflection {{ }} takes a "
                                   "minimum and maximum, fresnel, metallic)",
                                   clip(n)));
            skipValues(r);
        }
    }
    if (count == 0) ctx_.error(at.tok, "reflection { } needs its amount: { max } or { min, max }");
}

void MaterialReader::normal(Range r) {
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        if (item.kind != AtomKind::Word) {
            ctx_.error(item.tok,
                       fmt::format("expected a normal item, found {}", describeAtom(item)));
            continue;
        }
        if (!readNormalItem(ctx_, *this, r, item, m_.normal))
            reject(r, item, "normal", normalPatternItems());
    }
}

void MaterialReader::interior(Range r) {
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        if (item.kind == AtomKind::Word && interiorItem(r, item, word(item))) continue;
        if (item.kind != AtomKind::Word) {
            ctx_.error(item.tok,
                       fmt::format("expected an interior item, found {}", describeAtom(item)));
            continue;
        }
        reject(r, item, "interior", kInteriorTakes);
    }
}

// sky_sphere { pigment { ... } }: one pigment, nothing else.
void MaterialReader::skyBody(const Stmt& s) {
    Range r{s.first, s.first + s.count};
    bool seen = false;
    while (!r.done()) {
        const Atom& item = ast_.atoms[r.i++];
        if (item.kind != AtomKind::Word || word(item) != "pigment") {
            if (item.kind == AtomKind::Word)
                reject(r, item, "sky_sphere", "pigment");
            else
                ctx_.error(item.tok, fmt::format("expected a sky_sphere setting, found {}",
                                                 describeAtom(item)));
            continue;
        }
        const Atom* b = block(r, item);
        if (!b) continue;
        if (seen)
            ctx_.error(item.tok,
                       "sky_sphere takes one pigment (layered pigments are not "
                       "supported)");
        seen = true;
        pigment(inside(*b));
    }
    if (!seen) ctx_.error(s.tok, "sky_sphere needs a pigment { ... }");
}

}  // namespace

void readSkySphere(BuildContext& ctx, ExprCompiler& exprs, const Stmt& s) {
    Material scratch;
    MaterialReader(ctx, exprs, scratch).skyBody(s);
    Scene& scene = ctx.g.scene;
    scene.skySphere = true;
    scene.skyPigment = scratch.pigment;
    scene.skyColour = FilterColour{scratch.color, scratch.filter, scratch.transmit};
}

void readMaterial(BuildContext& ctx, ExprCompiler& exprs, const Stmt& s, uint32_t index) {
    MaterialReader(ctx, exprs, index).body(s);
}

}  // namespace pcsg
