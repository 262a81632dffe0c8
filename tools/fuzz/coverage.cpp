// Features of a scene, from its syntax tree: see coverage.h.
#include "coverage.h"

#include "ast.h"
#include "lexer.h"
#include "parser.h"

namespace pcsg::fuzz {

const std::vector<std::string>& featureNames() {
    static const std::vector<std::string> names = {
        "select", "transform", "calc", "paint", "union", "intersection", "difference", "sphere",
        "cube", "cylinder", "cone", "tetrahedron", "torus", "plane", "triangle", "notation_b",
        "rand", "choose",
        // section 10 (appearance items, read from the tokens)
        "pigment_checker", "pigment_gradient", "pigment_onion", "pigment_leopard", "pigment_radial",
        "pigment_brick", "pigment_hexagon", "pigment_bozo", "pigment_granite", "pigment_wood",
        "pigment_marble", "pigment_agate", "pigment_wrinkles", "pigment_dents", "color_map",
        "frequency", "phase", "turbulence", "pattern_transform", "normal_bumps", "normal_dents",
        "normal_wrinkles", "normal_ripples", "normal_waves", "brilliance", "specular", "metallic",
        "fresnel", "conserve_energy", "filter", "transmit", "ior", "fade", "area_light",
        "spotlight", "fog", "sky_sphere"};
    return names;
}

namespace {

const char* csgFeature(const CsgNode& n) {
    switch (n.kind) {
        case CsgKind::Operator:
            return n.csgOp == CsgOp::Union          ? "union"
                   : n.csgOp == CsgOp::Intersection ? "intersection"
                                                    : "difference";
        case CsgKind::Transform:
            return "transform";
        case CsgKind::Calc:
            return "calc";
        case CsgKind::Paint:
            return "paint";
        case CsgKind::Primitive:
            switch (n.prim) {
                case PrimitiveKind::Sphere:
                    return "sphere";
                case PrimitiveKind::Cube:
                    return "cube";
                case PrimitiveKind::Cylinder:
                    return "cylinder";
                case PrimitiveKind::Cone:
                    return "cone";
                case PrimitiveKind::Tetrahedron:
                    return "tetrahedron";
                case PrimitiveKind::Torus:
                    return "torus";
                case PrimitiveKind::Plane:
                    return "plane";
                case PrimitiveKind::Empty:
                    return nullptr;
                default:
                    return "triangle";
            }
        default:
            return nullptr;
    }
}

// The feature of word `w` read inside a block `block` (the innermost of pigment, normal,
// finish, interior, light, fog, sky_sphere, material), or "".
std::string appearanceFeature(std::string_view w, std::string_view block) {
    static const std::set<std::string_view> pigmentPatterns = {
        "checker", "gradient", "onion", "leopard", "radial", "brick",    "hexagon",
        "bozo",    "granite",  "wood",  "marble",  "agate",  "wrinkles", "dents"};
    static const std::set<std::string_view> normalPatterns = {"bumps", "dents", "wrinkles",
                                                              "ripples", "waves"};
    static const std::set<std::string_view> same = {
        "frequency", "phase",           "turbulence", "brilliance", "specular", "metallic",
        "fresnel",   "conserve_energy", "ior",        "area_light", "spotlight"};
    if (block == "pigment" && w == "spotted") return "pigment_bozo";
    if (block == "pigment" && pigmentPatterns.count(w)) return "pigment_" + std::string(w);
    if (block == "normal" && normalPatterns.count(w)) return "normal_" + std::string(w);
    if ((block == "pigment" || block == "normal") &&
        (w == "scale" || w == "rotate" || w == "translate"))
        return "pattern_transform";
    if (w == "color_map" || w == "colour_map") return "color_map";
    if (w == "rgbf") return "filter";
    if (w == "rgbt") return "transmit";
    if (w == "fade_distance") return "fade";
    if (same.count(w)) return std::string(w);
    return "";
}

// Section 10's items, from the tokens: which word opens the blocks around each word.
void appearanceFeatures(const Source& src, const TokenStream& tokens, std::set<std::string>& out) {
    static const std::set<std::string_view> blocks = {
        "pigment", "normal", "finish", "interior", "light", "fog", "sky_sphere", "material"};
    std::vector<std::string_view> open;  // per open brace: its block word, or ""
    const std::vector<Token>& t = tokens.tokens;
    for (size_t i = 0; i < t.size(); ++i) {
        if (t[i].is(Tok::LBrace)) {
            const std::string_view w = i > 0 ? spelling(src, t[i - 1]) : std::string_view();
            open.push_back(blocks.count(w) ? w : std::string_view());
            if (w == "fog" || w == "sky_sphere") out.insert(std::string(w));
            continue;
        }
        if (t[i].is(Tok::RBrace)) {
            if (!open.empty()) open.pop_back();
            continue;
        }
        if (!t[i].is(Tok::Ident) && !t[i].is(Tok::Keyword)) continue;
        std::string_view block;
        for (auto it = open.rbegin(); it != open.rend() && block.empty(); ++it) block = *it;
        const std::string_view w = spelling(src, t[i]);
        if (w == "rgbft") {
            out.insert("filter");
            out.insert("transmit");
        } else if (std::string f = appearanceFeature(w, block); !f.empty()) {
            out.insert(std::move(f));
        }
    }
}

}  // namespace

std::set<std::string> featuresOf(std::string_view text) {
    Diagnostics diags;
    const uint32_t file = diags.addFile("features.pcsg", text);
    const Source src(text, file);
    const TokenStream tokens = lex(src, diags);
    const Ast ast = parse(src, tokens, diags);
    std::set<std::string> found;
    if (diags.hasErrors()) return found;
    for (const CsgNode& n : ast.csg)
        if (const char* f = csgFeature(n)) found.insert(f);
    for (const Stmt& s : ast.stmts) {
        if (s.kind == StmtKind::Module) found.insert("select");
        if (s.kind == StmtKind::RuleB || s.kind == StmtKind::AxiomB) found.insert("notation_b");
    }
    for (const ExNode& e : ast.exprs) {
        if (e.kind != ExKind::Call) continue;
        const Token& t = tokens.tokens[e.tok];
        if (t.isKw(Kw::Rand)) found.insert("rand");
        if (t.isKw(Kw::Choose)) found.insert("choose");
    }
    appearanceFeatures(src, tokens, found);
    return found;
}

}  // namespace pcsg::fuzz
