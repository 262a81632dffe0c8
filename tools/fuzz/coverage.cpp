// Features of a scene, from its syntax tree: see coverage.h.
#include "coverage.h"

#include "ast.h"
#include "parser.h"

namespace pcsg::fuzz {

const std::vector<std::string>& featureNames() {
    static const std::vector<std::string> names = {
        "select",     "transform", "calc",     "paint",      "union", "intersection",
        "difference", "sphere",    "cube",     "cylinder",   "cone",  "tetrahedron",
        "torus",      "plane",     "triangle", "notation_b", "rand",  "choose"};
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
    return found;
}

}  // namespace pcsg::fuzz
