// The builder: whole-file checks, then the Graph. See builder.h.
#include "builder.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "eval.h"

namespace pcsg {

namespace {

struct FuncInfo {
    Kw kw;
    Func func;
    uint8_t minArgs, maxArgs;  // maxArgs 255: any number
};

constexpr FuncInfo kFunctions[] = {
    {Kw::Sin, Func::Sin, 1, 1},     {Kw::Cos, Func::Cos, 1, 1},     {Kw::Tan, Func::Tan, 1, 1},
    {Kw::Asin, Func::Asin, 1, 1},   {Kw::Acos, Func::Acos, 1, 1},   {Kw::Atan, Func::Atan, 1, 1},
    {Kw::Atan2, Func::Atan2, 2, 2}, {Kw::Sqrt, Func::Sqrt, 1, 1},   {Kw::Exp, Func::Exp, 1, 1},
    {Kw::Ln, Func::Ln, 1, 1},       {Kw::Log10, Func::Log10, 1, 1}, {Kw::Pow, Func::Pow, 2, 2},
    {Kw::Abs, Func::Abs, 1, 1},     {Kw::Floor, Func::Floor, 1, 1}, {Kw::Ceil, Func::Ceil, 1, 1},
    {Kw::Min, Func::Min, 2, 255},   {Kw::Max, Func::Max, 2, 255},   {Kw::Mod, Func::Mod, 2, 2},
    {Kw::Clamp, Func::Clamp, 3, 3},
};

const FuncInfo* functionInfo(Kw k) {
    for (const auto& f : kFunctions)
        if (f.kw == k) return &f;
    return nullptr;
}

std::string argumentCount(uint32_t n) {
    return fmt::format("{} argument{}", n, n == 1 ? "" : "s");
}

struct TransformInfo {
    uint32_t args;
    const char* names;
};
TransformInfo transformInfo(TransformOp op) {
    switch (op) {
        case TransformOp::Move:
            return {3, "dx, dy, dz"};
        case TransformOp::Scale:
            return {3, "fx, fy, fz"};
        case TransformOp::UScale:
            return {1, "f"};
        case TransformOp::RotX:
        case TransformOp::RotY:
        case TransformOp::RotZ:
            return {1, "an angle in degrees"};
        case TransformOp::Rot:
            return {4, "ax, ay, az, angle"};
        case TransformOp::ZShear:
            return {2, "a, b"};
        case TransformOp::FlipYZ:
        case TransformOp::FlipXZ:
        case TransformOp::FlipXY:
            return {0, ""};
        case TransformOp::Matrix:
            return {12, "m11 ... m33, tx, ty, tz"};
    }
    return {0, ""};
}

uint32_t primitiveArgCount(PrimitiveKind k) {
    return k == PrimitiveKind::Torus ? 2 : k == PrimitiveKind::Triangle ? 9 : 0;
}

bool isTriangle(PrimitiveKind k) {
    return k == PrimitiveKind::Tri1 || k == PrimitiveKind::Tri2 || k == PrimitiveKind::Triangle;
}

class Builder {
  public:
    Builder(const Source& src, const TokenStream& ts, const Ast& ast, Diagnostics& diags)
        : src_(src), t_(ts.tokens), ast_(ast), diags_(diags) {}

    std::optional<Graph> run() {
        const size_t errorsBefore = diags_.count();
        g_.files = diags_.fileNames();
        reserve();
        for (uint32_t tok : ast_.droppedNames) dropped_.insert(text(tok));
        g_.materials.push_back(Material{"default"});
        directives();
        declarations();
        for (const Assign& a : ast_.assigns) assigned_.insert(text(a.nameTok));
        axioms();
        const std::vector<uint32_t> order = definitionOrder();
        buildGraph(order);
        triangles();
        if (g_.scene.lights.empty()) g_.scene.lights.push_back(Light{});
        if (diags_.count() != errorsBefore) return std::nullopt;
        return std::move(g_);
    }

  private:
    // Upper bounds from the AST, so that no array of the graph is copied while it grows.
    void reserve() {
        const size_t csg = ast_.csg.size(), exprs = ast_.exprs.size(), lists = ast_.lists.size();
        g_.nodes.reserve(csg + ast_.stmts.size() + 16);
        g_.edges.reserve(lists + csg + ast_.stmts.size() + 16);
        g_.exprs.reserve(exprs + 16);
        g_.code.reserve(2 * exprs + 3 * ast_.chainItems.size() + 16);
        g_.args.reserve(lists + 16);
        g_.assignments.reserve(ast_.assigns.size() + lists + 16);
        g_.calcs.reserve(csg + 16);
        g_.transforms.reserve(csg + 16);
        g_.primitives.reserve(csg + 16);
    }

    // --- helpers ---
    FileLoc loc(uint32_t tok) const { return src_.loc(t_[tok].offset); }
    std::string_view text(uint32_t tok) const { return spelling(src_, t_[tok]); }
    void error(uint32_t tok, std::string message) { diags_.error(loc(tok), std::move(message)); }
    // Whether a statement that failed to parse may have declared this name: then errors
    // about the name are echoes of the syntax error, and not reported.
    bool dropped(std::string_view name) const { return dropped_.count(name) != 0; }
    uint32_t line(uint32_t tok) const { return loc(tok).line; }

    // The source text of tokens [from, to], one space where the source had any gap.
    std::string sourceText(uint32_t from, uint32_t to) const {
        std::string s;
        for (uint32_t i = from; i <= to && i < t_.size(); ++i) {
            const Token& t = t_[i];
            if (t.kind == Tok::Newline || t.kind == Tok::End) continue;
            if (i > from) {
                const Token& p = t_[i - 1];
                if (p.offset + p.length != t.offset) s += ' ';
            }
            s += spelling(src_, t);
            if (s.size() > 200) {
                s.resize(200);
                s += "...";
                break;
            }
        }
        return s;
    }

    // --- scene directives (section 7) ---

    // A constant value: compiled, evaluated and dropped from the graph's code.
    std::optional<double> constant(uint32_t e) {
        const size_t codeSize = g_.code.size(), exprCount = g_.exprs.size();
        const uint32_t sites = g_.randCallSites;
        constantOnly_ = true;
        const size_t errors = diags_.count();
        const ExprId id = compile(e);
        constantOnly_ = false;
        std::optional<double> value;
        if (diags_.count() != errors) {
            // reported already (a parameter, rand(), a syntax error): nothing to evaluate
        } else if (!g_.exprs[id].constant) {
            // compile() reports every way to be non-constant; should it miss one, this
            // error stands in for it, as evaluating needs a frame there is none of
            error(ast_.exprs[e].from, fmt::format("'{}' is not a constant", g_.exprs[id].text));
        } else {
            const double v = evalExpr(g_, id, EvalState{nullptr, kRootPath});
            if (std::isfinite(v))
                value = v;
            else
                error(ast_.exprs[e].from,
                      fmt::format("'{}' is {}, not a finite number", g_.exprs[id].text, v));
        }
        g_.code.resize(codeSize);
        g_.exprs.resize(exprCount);
        g_.randCallSites = sites;
        return value;
    }

    std::optional<Vec3> vectorValue(const DirectiveItem& item) {
        Vec3 v;
        bool ok = true;
        for (int i = 0; i < 3; ++i) {
            const auto c = constant(item.e[i]);
            if (c)
                v[i] = *c;
            else
                ok = false;
        }
        if (!ok) return std::nullopt;
        return v;
    }

    // Reads a directive's items through `set(name, item)`, which returns false for an
    // unknown name.
    template <class F>
    void items(const Stmt& s, const char* what, const char* known, F set) {
        for (uint32_t i = 0; i < s.count; ++i) {
            const DirectiveItem& item = ast_.items[s.first + i];
            if (!set(text(item.nameTok), item))
                error(item.nameTok, fmt::format("unknown {} setting '{}' ({} takes {})", what,
                                                clip(text(item.nameTok)), what, known));
        }
    }

    std::optional<Vec3> wantVector(const DirectiveItem& item) {
        if (!item.vector) {
            error(item.nameTok,
                  fmt::format("'{}' takes a vector '<x, y, z>'", clip(text(item.nameTok))));
            return std::nullopt;
        }
        return vectorValue(item);
    }
    std::optional<double> wantScalar(const DirectiveItem& item) {
        if (item.vector) {
            error(item.nameTok,
                  fmt::format("'{}' takes a number, not a vector", clip(text(item.nameTok))));
            return std::nullopt;
        }
        return constant(item.e[0]);
    }

    void directives() {
        // Settings first: rand(x) in later constants uses the seed.
        for (const Stmt& s : ast_.stmts)
            if (s.kind == StmtKind::Directive && s.directive == Kw::Settings) settings(s);
        for (const Stmt& s : ast_.stmts)
            if (s.kind == StmtKind::Directive && s.directive == Kw::Material) materialName(s);
        for (const Stmt& s : ast_.stmts) {
            if (s.kind != StmtKind::Directive) continue;
            switch (s.directive) {
                case Kw::Camera:
                    camera(s);
                    break;
                case Kw::Light:
                    light(s);
                    break;
                case Kw::Background:
                    background(s);
                    break;
                case Kw::Material:
                    material(s);
                    break;
                default:
                    break;
            }
        }
    }

    bool once(uint32_t& seen, const Stmt& s, const char* what) {
        if (seen != kNoNode) {
            error(s.tok,
                  fmt::format("a second {} directive (the first is at line {})", what, line(seen)));
            return false;
        }
        seen = s.tok;
        return true;
    }

    void settings(const Stmt& s) {
        if (!once(settingsSeen_, s, "settings")) return;
        Settings& st = g_.scene.settings;
        items(s, "settings", "seed, max_depth", [&](std::string_view n, const DirectiveItem& item) {
            if (n == "seed") {
                if (auto v = wantScalar(item)) {
                    if (*v < 0 || *v != std::floor(*v) || *v > 9007199254740992.0)
                        error(item.nameTok,
                              fmt::format("seed must be a whole number from 0 to 2^53, found {}",
                                          *v));
                    else
                        st.seed = static_cast<uint64_t>(*v);
                }
            } else if (n == "max_depth") {
                if (auto v = wantScalar(item)) {
                    if (*v < 1 || *v != std::floor(*v) || *v > kMaxMaxDepth)
                        error(item.nameTok,
                              fmt::format("max_depth must be a whole number from 1 to {}, found {}",
                                          kMaxMaxDepth, *v));
                    else
                        st.maxDepth = static_cast<uint32_t>(*v);
                }
            } else {
                return false;
            }
            return true;
        });
    }

    void camera(const Stmt& s) {
        if (!once(cameraSeen_, s, "camera")) return;
        Camera& c = g_.scene.camera;
        bool ok = true;
        items(
            s, "camera", "location, look_at, sky, angle",
            [&](std::string_view n, const DirectiveItem& item) {
                std::optional<Vec3> v;
                if (n == "location") {
                    if ((v = wantVector(item))) c.location = *v;
                } else if (n == "look_at") {
                    if ((v = wantVector(item))) c.lookAt = *v;
                } else if (n == "sky") {
                    if ((v = wantVector(item))) c.sky = *v;
                } else if (n == "angle") {
                    if (auto a = wantScalar(item)) {
                        if (!(*a > 0 && *a < 180)) {
                            error(
                                item.nameTok,
                                fmt::format(
                                    "the camera angle must be between 0 and 180 degrees, found {}",
                                    *a));
                            ok = false;
                        } else {
                            c.angle = *a;
                        }
                    }
                } else {
                    return false;
                }
                return true;
            });
        if (!ok) return;
        const Vec3 dir = c.lookAt - c.location;
        if (length(dir) == 0)
            error(s.tok, "the camera's location and look_at are the same point");
        else if (length(c.sky) == 0 ||
                 length(cross(dir, c.sky)) <= 1e-12 * length(dir) * length(c.sky))
            error(s.tok, "the camera's sky vector is zero or parallel to its viewing direction");
    }

    void light(const Stmt& s) {
        Light l;
        items(s, "light", "position, color", [&](std::string_view n, const DirectiveItem& item) {
            if (n == "position") {
                if (auto v = wantVector(item)) l.position = *v;
            } else if (n == "color" || n == "colour") {
                if (auto v = wantVector(item)) l.color = *v;
            } else {
                return false;
            }
            return true;
        });
        g_.scene.lights.push_back(l);
    }

    void background(const Stmt& s) {
        if (!once(backgroundSeen_, s, "background")) return;
        if (auto v = vectorValue(ast_.items[s.first])) g_.scene.background = *v;
    }

    // Registers material names before any paint() is built (materials may come later).
    void materialName(const Stmt& s) {
        const std::string_view name = text(s.nameTok);
        if (name == "default") {
            if (defaultMaterialSeen_ != kNoNode) {
                error(s.nameTok, fmt::format("material 'default' is already given at line {}",
                                             line(defaultMaterialSeen_)));
                return;
            }
            defaultMaterialSeen_ = s.nameTok;
            materialIndex_[s.nameTok] = 0;
            return;
        }
        auto [it, inserted] =
            materialByName_.emplace(name, static_cast<uint32_t>(g_.materials.size()));
        if (!inserted) {
            error(s.nameTok, fmt::format("material '{}' is already defined at line {}", clip(name),
                                         line(materialTok_[it->second])));
            return;
        }
        Material m;
        m.name = std::string(name);
        materialTok_[static_cast<uint32_t>(g_.materials.size())] = s.nameTok;
        materialIndex_[s.nameTok] = static_cast<uint32_t>(g_.materials.size());
        g_.materials.push_back(m);
    }

    void material(const Stmt& s) {
        auto it = materialIndex_.find(s.nameTok);
        if (it == materialIndex_.end()) return;  // a duplicate, reported
        Material& m = g_.materials[it->second];
        items(s, "material", "color, ambient, diffuse, phong, phong_size, reflection",
              [&](std::string_view n, const DirectiveItem& item) {
                  if (n == "color" || n == "colour") {
                      if (auto v = wantVector(item)) m.color = *v;
                      return true;
                  }
                  double* target = n == "ambient"      ? &m.ambient
                                   : n == "diffuse"    ? &m.diffuse
                                   : n == "phong"      ? &m.phong
                                   : n == "phong_size" ? &m.phongSize
                                   : n == "reflection" ? &m.reflection
                                                       : nullptr;
                  if (!target) return false;
                  if (auto v = wantScalar(item)) *target = *v;
                  return true;
              });
    }

    // --- modules, rules, definitions (sections 2 and 4) ---

    struct ModuleInfo {
        std::string_view name;
        uint32_t firstTok;        // where it first appears
        uint32_t decl = kNoNode;  // notation A: the declaration statement
        bool notationB = false;
        bool hasRules = false;
        std::vector<uint32_t> rules;     // statement indices, in file order
        std::vector<uint32_t> formals;   // notation B: token indices of the first rule's formals
        uint32_t formalsRule = kNoNode;  // the rule statement they come from
        std::vector<Slot> formalSlots;
        NodeId node = kNone;
    };

    uint32_t moduleFor(uint32_t nameTok) {
        const std::string_view name = text(nameTok);
        auto [it, inserted] = moduleByName_.emplace(name, static_cast<uint32_t>(modules_.size()));
        if (inserted) {
            ModuleInfo m;
            m.name = name;
            m.firstTok = nameTok;
            modules_.push_back(std::move(m));
        }
        return it->second;
    }

    void declarations() {
        for (uint32_t si = 0; si < ast_.stmts.size(); ++si) {
            const Stmt& s = ast_.stmts[si];
            switch (s.kind) {
                case StmtKind::Module: {
                    ModuleInfo& m = modules_[moduleFor(s.nameTok)];
                    if (m.decl != kNoNode) {
                        error(s.nameTok,
                              fmt::format("module {} is already declared at line {}", clip(m.name),
                                          line(ast_.stmts[m.decl].nameTok)));
                    } else if (m.notationB) {
                        error(s.nameTok,
                              fmt::format("module {} has notation-B rules (line {}), which "
                                          "select by their conditions: it cannot also have a "
                                          "selection function (to start from {}, write the "
                                          "axiom with a label: 'w: {}(...)')",
                                          clip(m.name), line(ast_.stmts[m.rules[0]].nameTok),
                                          clip(m.name), clip(m.name)));
                    } else {
                        m.decl = si;
                    }
                    break;
                }
                case StmtKind::RuleA: {
                    ModuleInfo& m = modules_[moduleFor(s.nameTok)];
                    if (m.notationB) {
                        error(s.tok,
                              fmt::format("module {} uses notation B (rule at line {}); one module "
                                          "uses one notation",
                                          clip(m.name), line(ast_.stmts[m.rules[0]].tok)));
                        break;
                    }
                    m.hasRules = true;
                    m.rules.push_back(si);
                    break;
                }
                case StmtKind::RuleB: {
                    ModuleInfo& m = modules_[moduleFor(s.nameTok)];
                    if (m.decl != kNoNode || (m.hasRules && !m.notationB)) {
                        const uint32_t where =
                            m.decl != kNoNode ? ast_.stmts[m.decl].tok : ast_.stmts[m.rules[0]].tok;
                        error(s.tok,
                              fmt::format("module {} uses notation A (line {}); one module uses "
                                          "one notation",
                                          clip(m.name), line(where)));
                        break;
                    }
                    formals(m, si);
                    m.notationB = true;
                    m.hasRules = true;
                    m.rules.push_back(si);
                    break;
                }
                case StmtKind::Definition: {
                    const std::string_view name = text(s.nameTok);
                    auto [it, inserted] = definitionByName_.emplace(name, si);
                    if (!inserted)
                        error(s.nameTok,
                              fmt::format("'{}' is already defined at line {}", clip(name),
                                          line(ast_.stmts[it->second].nameTok)));
                    break;
                }
                default:
                    break;
            }
        }
        for (ModuleInfo& m : modules_) {
            if (definitionByName_.count(m.name)) {
                const Stmt& d = ast_.stmts[definitionByName_.at(m.name)];
                error(d.nameTok,
                      fmt::format("'{}' is a module (line {}) and cannot also be a definition",
                                  clip(m.name), line(m.firstTok)));
            }
            if (m.notationB || dropped(m.name)) continue;
            if (m.decl == kNoNode) {
                error(ast_.stmts[m.rules[0]].nameTok,
                      fmt::format("module {} is not declared: add a line '{} <selection function>' "
                                  "that chooses among its rules",
                                  clip(m.name), clip(m.name)));
                continue;
            }
            if (m.rules.empty()) {
                error(ast_.stmts[m.decl].nameTok,
                      fmt::format("module {} has no rules", clip(m.name)));
                continue;
            }
            // Rules 1..n, each exactly once; the S-node's children in rule order.
            std::stable_sort(m.rules.begin(), m.rules.end(), [&](uint32_t a, uint32_t b) {
                return ast_.stmts[a].number < ast_.stmts[b].number;
            });
            bool ok = true;
            for (size_t i = 1; i < m.rules.size(); ++i) {
                const Stmt& a = ast_.stmts[m.rules[i - 1]];
                const Stmt& b = ast_.stmts[m.rules[i]];
                if (a.number == b.number) {
                    error(b.labelTok,
                          fmt::format("rule {} of module {} is already given at line {}", b.number,
                                      clip(m.name), line(a.labelTok)));
                    ok = false;
                }
            }
            if (!ok) continue;
            for (size_t i = 0; i < m.rules.size(); ++i) {
                const Stmt& r = ast_.stmts[m.rules[i]];
                if (r.number != i + 1) {
                    error(r.labelTok,
                          fmt::format("module {} has no rule {}: its rules must be numbered "
                                      "1 to {} without gaps",
                                      clip(m.name), i + 1, m.rules.size()));
                    break;
                }
            }
        }
    }

    // Notation B: every rule of a module lists the same formal parameters.
    void formals(ModuleInfo& m, uint32_t si) {
        const Stmt& s = ast_.stmts[si];
        std::vector<uint32_t> mine(ast_.lists.begin() + s.first,
                                   ast_.lists.begin() + s.first + s.count);
        for (size_t i = 0; i < mine.size(); ++i)
            for (size_t j = 0; j < i; ++j)
                if (text(mine[i]) == text(mine[j]))
                    error(mine[i],
                          fmt::format("parameter '{}' is listed twice", clip(text(mine[i]))));
        if (m.formalsRule == kNoNode) {
            m.formals = mine;
            m.formalsRule = si;
            return;
        }
        bool same = m.formals.size() == mine.size();
        for (size_t i = 0; same && i < mine.size(); ++i) same = text(mine[i]) == text(m.formals[i]);
        if (!same)
            error(s.nameTok,
                  fmt::format("rule '{}' gives module {} the parameters ({}), but its rule at "
                              "line {} gives ({})",
                              clip(text(s.labelTok)), clip(m.name), formalList(mine),
                              line(ast_.stmts[m.formalsRule].tok), formalList(m.formals)));
    }

    std::string formalList(const std::vector<uint32_t>& toks) const {
        std::string s;
        for (size_t i = 0; i < toks.size(); ++i) {
            if (i) s += ", ";
            s += clip(text(toks[i]));
        }
        return s;
    }

    void axioms() {
        for (const Stmt& s : ast_.stmts) {
            if (s.kind != StmtKind::AxiomA && s.kind != StmtKind::AxiomB) continue;
            if (axiom_ == nullptr) {
                axiom_ = &s;
                continue;
            }
            error(s.tok,
                  fmt::format("a second axiom (the first is at line {}): a file has exactly one",
                              line(axiom_->tok)));
        }
        if (!axiom_ && ast_.dropped == 0)
            diags_.error(FileLoc{src_.file(), 1, 1},
                         "the file has no axiom: a statement that is the object itself, such as "
                         "'{c = 6} S' or 'w: S(6)'");
    }

    // --- definitions: the order to build them in, and cycles ---

    // The definitions a CSG expression names directly (through definitions only: a module
    // name ends the search, since S-nodes may form cycles).
    void namedDefinitions(uint32_t c, std::vector<uint32_t>& out) const {
        const CsgNode& n = ast_.csg[c];
        switch (n.kind) {
            case CsgKind::Operator:
                for (uint32_t i = 0; i < n.count; ++i)
                    namedDefinitions(ast_.lists[n.first + i], out);
                break;
            case CsgKind::Transform:
            case CsgKind::Calc:
            case CsgKind::Paint:
                namedDefinitions(n.child, out);
                break;
            case CsgKind::Name: {
                const std::string_view name = text(n.nameTok);
                if (moduleByName_.count(name)) break;
                auto it = definitionByName_.find(name);
                if (it != definitionByName_.end()) out.push_back(it->second);
                break;
            }
            default:
                break;
        }
    }

    // Definitions in an order where each comes after those it names. A definition that
    // refers to itself through definitions only is an error (it would be infinite).
    std::vector<uint32_t> definitionOrder() {
        std::vector<uint32_t> order;
        std::unordered_map<uint32_t, uint8_t> state;  // 1: on the stack, 2: done
        struct Frame {
            uint32_t stmt;
            std::vector<uint32_t> deps;
            size_t next = 0;
        };
        std::vector<Frame> stack;
        for (uint32_t si = 0; si < ast_.stmts.size(); ++si) {
            if (ast_.stmts[si].kind != StmtKind::Definition || state[si]) continue;
            if (definitionByName_.at(text(ast_.stmts[si].nameTok)) != si) continue;  // duplicate
            auto enter = [&](uint32_t s) {
                Frame f{s, {}, 0};
                namedDefinitions(ast_.stmts[s].body, f.deps);
                state[s] = 1;
                stack.push_back(std::move(f));
            };
            enter(si);
            while (!stack.empty()) {
                Frame& f = stack.back();
                if (f.next == f.deps.size()) {
                    state[f.stmt] = 2;
                    order.push_back(f.stmt);
                    stack.pop_back();
                    continue;
                }
                const uint32_t d = f.deps[f.next++];
                if (state[d] == 2) continue;
                if (state[d] == 1) {
                    // A cycle: the stack from d up to here.
                    std::string path;
                    size_t k = 0;
                    while (stack[k].stmt != d) ++k;
                    for (size_t j = k; j < stack.size(); ++j)
                        path +=
                            fmt::format("{} -> ", clip(text(ast_.stmts[stack[j].stmt].nameTok)));
                    path += text(ast_.stmts[d].nameTok);
                    if (!cyclic_.count(d)) {
                        error(ast_.stmts[d].nameTok,
                              fmt::format(
                                  "definition '{}' refers to itself ({}): only a module can be "
                                  "recursive",
                                  clip(text(ast_.stmts[d].nameTok)), path));
                    }
                    for (size_t j = k; j < stack.size(); ++j) cyclic_.insert(stack[j].stmt);
                    continue;
                }
                enter(d);
            }
        }
        return order;
    }

    // --- the graph ---

    void buildGraph(const std::vector<uint32_t>& definitionOrder) {
        // One S-node per module, its children filled in once the rules are built.
        for (ModuleInfo& m : modules_) {
            Module mod;
            mod.name = std::string(m.name);
            mod.notationB = m.notationB;
            mod.loc = loc(m.decl != kNoNode ? ast_.stmts[m.decl].nameTok : m.firstTok);
            const uint32_t index = static_cast<uint32_t>(g_.modules.size());
            m.node = g_.addNode(NodeKind::Select, index, std::vector<NodeId>(m.rules.size(), kNone),
                                mod.loc);
            mod.node = m.node;
            for (uint32_t f : m.formals) {
                m.formalSlots.push_back(slotOf(text(f)));
                assigned_.insert(text(f));
            }
            mod.formals = m.formalSlots;
            g_.modules.push_back(std::move(mod));
        }
        for (uint32_t mi = 0; mi < modules_.size(); ++mi) {
            ModuleInfo& m = modules_[mi];
            if (m.notationB) {
                for (uint32_t r : m.rules) {
                    const uint32_t c = ast_.stmts[r].expr;
                    const ExprId e = c == kNoNode ? kNone : compile(c);
                    g_.modules[mi].conditions.push_back(e);
                }
            } else if (m.decl != kNoNode) {
                g_.modules[mi].select = compile(ast_.stmts[m.decl].expr);
            }
        }
        for (uint32_t d : definitionOrder) {
            if (cyclic_.count(d)) continue;
            definitionNode_[d] = csg(ast_.stmts[d].body);
        }
        for (ModuleInfo& m : modules_) {
            for (size_t k = 0; k < m.rules.size(); ++k) {
                const NodeId body = csg(ast_.stmts[m.rules[k]].body);
                g_.edges[g_.nodes[m.node].firstChild + k] = body;
            }
        }
        if (axiom_) g_.axiom = csg(axiom_->body);
        // Modules whose rules were rejected keep no dangling edges.
        for (ModuleInfo& m : modules_)
            for (size_t k = 0; k < m.rules.size(); ++k)
                if (g_.edges[g_.nodes[m.node].firstChild + k] == kNone)
                    g_.edges[g_.nodes[m.node].firstChild + k] = placeholder();
    }

    // The slot of a parameter (Graph::slot searches linearly: fine for a handful of
    // names, not for a generated file with thousands).
    Slot slotOf(std::string_view name) {
        auto it = slots_.find(name);
        if (it != slots_.end()) return it->second;
        const Slot s = g_.slot(std::string(name));
        slots_.emplace(name, s);
        return s;
    }

    NodeId placeholder() {
        if (placeholder_ == kNone) {
            Primitive p;
            p.kind = PrimitiveKind::Empty;
            g_.primitives.push_back(p);
            placeholder_ = g_.addNode(NodeKind::Primitive,
                                      static_cast<uint32_t>(g_.primitives.size() - 1), {});
        }
        return placeholder_;
    }

    NodeId csg(uint32_t c) {
        const CsgNode& n = ast_.csg[c];
        const FileLoc where = loc(n.tok);
        switch (n.kind) {
            case CsgKind::Operator: {
                std::vector<NodeId> children;
                children.reserve(n.count);
                for (uint32_t i = 0; i < n.count; ++i)
                    children.push_back(csg(ast_.lists[n.first + i]));
                return g_.addOperator(n.csgOp, children, where);
            }
            case CsgKind::Transform:
                return transform(n);
            case CsgKind::Calc: {
                const NodeId child = csg(n.child);
                if (n.count == 0) return child;  // `{}` assigns nothing
                Calc calc;
                calc.first = static_cast<uint32_t>(g_.assignments.size());
                calc.count = n.count;
                // Compile all values first: compile() may not interleave with the list.
                std::vector<Assignment> list;
                for (uint32_t i = 0; i < n.count; ++i) {
                    const Assign& a = ast_.assigns[n.first + i];
                    const ExprId value = compile(a.value);
                    list.push_back(Assignment{slotOf(text(a.nameTok)), value});
                }
                calc.first = static_cast<uint32_t>(g_.assignments.size());
                g_.assignments.insert(g_.assignments.end(), list.begin(), list.end());
                g_.calcs.push_back(calc);
                return g_.addNode(NodeKind::Calc, static_cast<uint32_t>(g_.calcs.size() - 1),
                                  {child}, where);
            }
            case CsgKind::Paint: {
                const NodeId child = csg(n.child);
                const std::string_view name = text(n.nameTok);
                uint32_t material = 0;
                if (name != "default") {
                    auto it = materialByName_.find(name);
                    if (it == materialByName_.end()) {
                        if (!dropped(name))
                            error(n.nameTok,
                                  fmt::format(
                                      "unknown material '{}'{}", clip(name),
                                      materialByName_.empty() ? " (no material is defined)" : ""));
                        return child;
                    }
                    material = it->second;
                }
                return g_.addNode(NodeKind::Paint, material, {child}, where);
            }
            case CsgKind::Primitive:
                return primitive(n);
            case CsgKind::Name:
                return name(n);
            case CsgKind::Call:
                return call(n);
        }
        return placeholder();
    }

    NodeId name(const CsgNode& n) {
        const std::string_view name = text(n.nameTok);
        auto m = moduleByName_.find(name);
        if (m != moduleByName_.end()) return modules_[m->second].node;
        auto d = definitionByName_.find(name);
        if (d != definitionByName_.end()) {
            auto built = definitionNode_.find(d->second);
            return built != definitionNode_.end() ? built->second : placeholder();
        }
        if (dropped(name)) return placeholder();
        if (assigned_.count(name))
            error(n.nameTok,
                  fmt::format("'{}' is a parameter, not a module or definition", clip(name)));
        else
            error(n.nameTok, fmt::format("unknown module or definition '{}'", clip(name)));
        return placeholder();
    }

    NodeId call(const CsgNode& n) {
        const std::string_view name = text(n.nameTok);
        auto it = moduleByName_.find(name);
        if (it == moduleByName_.end()) {
            if (dropped(name)) return placeholder();
            if (definitionByName_.count(name))
                error(n.nameTok, fmt::format("definition '{}' takes no arguments", clip(name)));
            else
                error(n.nameTok, fmt::format("unknown module '{}'", clip(name)));
            return placeholder();
        }
        const ModuleInfo& m = modules_[it->second];
        if (!m.notationB) {
            error(n.nameTok,
                  fmt::format("module {} uses notation A and has no parameter list; set its "
                              "parameters with a C-node, as in '{{c = ...}} {}'",
                              clip(name), clip(name)));
            return placeholder();
        }
        if (n.count != m.formals.size()) {
            error(n.nameTok, fmt::format("module {} takes {} ({}), found {}", clip(name),
                                         argumentCount(static_cast<uint32_t>(m.formals.size())),
                                         formalList(m.formals), n.count));
            return placeholder();
        }
        if (n.count == 0) return m.node;
        std::vector<Assignment> list;
        for (uint32_t i = 0; i < n.count; ++i)
            list.push_back(Assignment{m.formalSlots[i], compile(ast_.lists[n.first + i])});
        Calc calc;
        calc.first = static_cast<uint32_t>(g_.assignments.size());
        calc.count = n.count;
        calc.simultaneous = true;
        g_.assignments.insert(g_.assignments.end(), list.begin(), list.end());
        g_.calcs.push_back(calc);
        return g_.addNode(NodeKind::Calc, static_cast<uint32_t>(g_.calcs.size() - 1), {m.node},
                          loc(n.nameTok));
    }

    // Compiles a list of arguments; returns whether all are constant and finite, with
    // their values.
    bool arguments(const CsgNode& n, uint32_t& firstArg, std::vector<double>& values) {
        std::vector<ExprId> ids;
        for (uint32_t i = 0; i < n.count; ++i) ids.push_back(compile(ast_.lists[n.first + i]));
        firstArg = static_cast<uint32_t>(g_.args.size());
        g_.args.insert(g_.args.end(), ids.begin(), ids.end());
        bool constant = true;
        for (ExprId id : ids) {
            if (!g_.exprs[id].constant) {
                constant = false;
                continue;
            }
            const double v = evalExpr(g_, id, EvalState{nullptr, kRootPath});
            if (!std::isfinite(v)) constant = false;  // left to the run-time check
            values.push_back(v);
        }
        return constant;
    }

    NodeId transform(const CsgNode& n) {
        const TransformInfo info = transformInfo(n.op);
        const NodeId child = csg(n.child);
        if (n.count != info.args) {
            error(n.tok, fmt::format("{} takes {} ({}), found {}", clip(text(n.tok)),
                                     argumentCount(info.args), info.names, n.count));
            return child;
        }
        Transform tr;
        tr.op = n.op;
        tr.argCount = n.count;
        std::vector<double> values;
        const bool constant = arguments(n, tr.firstArg, values);
        if (constant) {
            if (const std::optional<Affine> m = constantTransform(n.op, values.data())) {
                tr.constant = true;
                tr.matrix = *m;
            }
        }
        g_.transforms.push_back(tr);
        return g_.addNode(NodeKind::Transform, static_cast<uint32_t>(g_.transforms.size() - 1),
                          {child}, loc(n.tok));
    }

    NodeId primitive(const CsgNode& n) {
        const uint32_t want = primitiveArgCount(n.prim);
        if (n.count != want) {
            if (want == 0)
                error(n.tok, fmt::format("{} takes no arguments", clip(text(n.tok))));
            else
                error(n.tok, fmt::format("{} takes {} ({}), found {}", clip(text(n.tok)),
                                         argumentCount(want),
                                         want == 2 ? "R, r" : "x1, y1, z1, x2, y2, z2, x3, y3, z3",
                                         n.count));
            return placeholder();
        }
        Primitive p;
        p.kind = n.prim;
        p.argCount = n.count;
        std::vector<double> values;
        p.constant = arguments(n, p.firstArg, values);
        if (p.constant) p.values = std::move(values);
        g_.primitives.push_back(std::move(p));
        return g_.addNode(NodeKind::Primitive, static_cast<uint32_t>(g_.primitives.size() - 1), {},
                          loc(n.tok));
    }

    // --- expressions: the stack code of graph.h ---

    struct CodeGen {
        uint32_t depth = 0, maxDepth = 0;
        bool readsSlot = false, usesPath = false;
        void push(uint32_t k = 1) {
            depth += k;
            maxDepth = std::max(maxDepth, depth);
        }
        void pop(uint32_t k = 1) { depth -= k; }
    };

    uint32_t emit(Op op, uint32_t a = 0, double imm = 0, uint8_t argc = 0) {
        g_.code.push_back(Instr{op, argc, a, imm});
        return static_cast<uint32_t>(g_.code.size() - 1);
    }
    uint32_t here() const { return static_cast<uint32_t>(g_.code.size()); }

    ExprId compile(uint32_t e) {
        CodeGen cg;
        Expr x;
        x.begin = here();
        gen(e, cg);
        x.end = here();
        x.maxStack = cg.maxDepth;
        x.usesPath = cg.usesPath;
        x.constant = !cg.readsSlot && !cg.usesPath;
        const ExNode& n = ast_.exprs[e];
        x.loc = loc(n.from);
        x.text = sourceText(n.from, n.to);
        g_.exprs.push_back(std::move(x));
        const ExprId id = static_cast<ExprId>(g_.exprs.size() - 1);
        Expr& added = g_.exprs[id];
        if (added.constant && added.end - added.begin > 1) {
            // Fold a constant expression into one instruction.
            const double v = evalExpr(g_, id, EvalState{nullptr, kRootPath});
            g_.code.resize(added.begin);
            emit(Op::Const, 0, v);
            added.end = here();
            added.maxStack = 1;
        }
        return id;
    }

    void gen(uint32_t e, CodeGen& cg) {
        const ExNode& n = ast_.exprs[e];
        switch (n.kind) {
            case ExKind::Number:
                emit(Op::Const, 0, n.value);
                cg.push();
                return;
            case ExKind::Name: {
                const std::string_view name = text(n.tok);
                if (constantOnly_) {
                    error(
                        n.tok,
                        fmt::format("'{}': the values of a directive are constants, not parameters",
                                    clip(name)));
                } else if (!assigned_.count(name) && ast_.dropped == 0 &&
                           reportedUnknown_.insert(name).second) {
                    error(n.tok,
                          fmt::format(
                              "unknown parameter '{}': no C-node or formal parameter assigns it",
                              clip(name)));
                }
                emit(Op::Load, slotOf(name));
                cg.readsSlot = true;
                cg.push();
                return;
            }
            case ExKind::Unary:
                gen(n.a, cg);
                if (n.op == Tok::Minus)
                    emit(Op::Neg);
                else if (n.op == Tok::Bang)
                    emit(Op::Not);
                return;
            case ExKind::Power:
                gen(n.a, cg);
                gen(n.b, cg);
                emit(Op::Pow);
                cg.pop();
                return;
            case ExKind::Chain:
                return chain(n, cg);
            case ExKind::Call:
                return call(n, cg);
        }
    }

    void chain(const ExNode& n, CodeGen& cg) {
        const ChainItem* items = ast_.chainItems.data() + n.first;
        const Tok level = items[0].op;
        if (level == Tok::AndAnd || level == Tok::OrOr) {
            // Short-circuit: only the operands needed are evaluated.
            const bool isAnd = level == Tok::AndAnd;
            const uint32_t base = cg.depth;
            std::vector<uint32_t> patches;  // jumps to the end (||) or to "false" (&&)
            for (uint32_t i = 0; i <= n.count; ++i) {
                const uint32_t operand = i == 0 ? n.a : items[i - 1].operand;
                gen(operand, cg);
                if (i == n.count) {
                    emit(Op::ToBool);
                    break;
                }
                const uint32_t skip = emit(Op::JumpIfZero);
                cg.pop();
                if (isAnd) {
                    patches.push_back(skip);
                } else {
                    emit(Op::Const, 0, 1.0);
                    cg.push();
                    patches.push_back(emit(Op::Jump));
                    cg.pop();
                    g_.code[skip].a = here();
                }
            }
            if (isAnd) {
                const uint32_t toEnd = emit(Op::Jump);
                for (uint32_t p : patches) g_.code[p].a = here();
                emit(Op::Const, 0, 0.0);
                g_.code[toEnd].a = here();
            } else {
                for (uint32_t p : patches) g_.code[p].a = here();
            }
            cg.depth = base + 1;
            return;
        }
        gen(n.a, cg);
        for (uint32_t i = 0; i < n.count; ++i) {
            gen(items[i].operand, cg);
            Op op = Op::Add;
            switch (items[i].op) {
                case Tok::Plus:
                    op = Op::Add;
                    break;
                case Tok::Minus:
                    op = Op::Sub;
                    break;
                case Tok::Star:
                    op = Op::Mul;
                    break;
                case Tok::Slash:
                    op = Op::Div;
                    break;
                case Tok::Percent:
                    op = Op::Mod;
                    break;
                case Tok::Lt:
                    op = Op::Lt;
                    break;
                case Tok::Le:
                    op = Op::Le;
                    break;
                case Tok::Gt:
                    op = Op::Gt;
                    break;
                case Tok::Ge:
                    op = Op::Ge;
                    break;
                case Tok::Eq:
                    op = Op::Eq;
                    break;
                case Tok::Ne:
                    op = Op::Ne;
                    break;
                default:
                    break;
            }
            emit(op);
            cg.pop();
        }
    }

    void call(const ExNode& n, CodeGen& cg) {
        const Token& f = t_[n.tok];
        const std::string_view name = text(n.tok);
        const uint32_t* args = ast_.lists.data() + n.first;
        auto wrongCount = [&](const std::string& want) {
            error(n.tok, fmt::format("{}() takes {}, found {}", clip(name), want, n.count));
            emit(Op::Const, 0, 0.0);
            cg.push();
        };
        if (f.kind != Tok::Keyword) {
            error(n.tok, fmt::format("unknown function '{}'", clip(name)));
            emit(Op::Const, 0, 0.0);
            cg.push();
            return;
        }
        switch (f.kw) {
            case Kw::If: {
                if (n.count != 3) return wrongCount("3 arguments (condition, then, else)");
                gen(args[0], cg);
                const uint32_t toElse = emit(Op::JumpIfZero);
                cg.pop();
                const uint32_t base = cg.depth;
                gen(args[1], cg);
                const uint32_t toEnd = emit(Op::Jump);
                g_.code[toElse].a = here();
                cg.depth = base;
                gen(args[2], cg);
                g_.code[toEnd].a = here();
                return;
            }
            case Kw::Rand:
                if (n.count == 0) {
                    if (constantOnly_)
                        error(n.tok, "rand() depends on the instance: it is not a constant");
                    emit(Op::Rand0, g_.randCallSites++);
                    cg.usesPath = true;
                    cg.push();
                    return;
                }
                if (n.count != 1) return wrongCount("no argument or 1");
                gen(args[0], cg);
                emit(Op::Call, static_cast<uint32_t>(Func::Rand1), 0, 1);
                return;
            case Kw::Choose: {
                if (n.count < 1 || n.count > 255) return wrongCount("1 to 255 weights");
                if (constantOnly_)
                    error(n.tok, "choose() depends on the instance: it is not a constant");
                for (uint32_t i = 0; i < n.count; ++i) gen(args[i], cg);
                emit(Op::Choose, g_.randCallSites++, 0, static_cast<uint8_t>(n.count));
                cg.usesPath = true;
                cg.pop(n.count - 1);
                return;
            }
            default:
                break;
        }
        const FuncInfo* info = functionInfo(f.kw);
        if (!info) {
            error(n.tok, fmt::format("'{}' is not a function", clip(name)));
            emit(Op::Const, 0, 0.0);
            cg.push();
            return;
        }
        if (n.count < info->minArgs || n.count > info->maxArgs) {
            if (info->maxArgs == 255) return wrongCount(fmt::format("2 to 255 arguments"));
            return wrongCount(argumentCount(info->minArgs));
        }
        for (uint32_t i = 0; i < n.count; ++i) gen(args[i], cg);
        emit(Op::Call, static_cast<uint32_t>(info->func), 0, static_cast<uint8_t>(n.count));
        cg.pop(n.count - 1);
    }

    // --- triangles under intersections and differences (section 5) ---

    void triangles() {
        const size_t count = g_.nodes.size();
        std::vector<NodeId> source(count, kNone);  // a triangle reachable from the node
        std::vector<NodeId> queue;
        for (NodeId i = 0; i < count; ++i) {
            const Node& n = g_.nodes[i];
            if (n.kind == NodeKind::Primitive && isTriangle(g_.primitives[n.payload].kind)) {
                source[i] = i;
                queue.push_back(i);
            }
        }
        if (queue.empty()) return;
        // Parents, as a compressed adjacency list.
        std::vector<uint32_t> start(count + 1, 0);
        for (NodeId i = 0; i < count; ++i)
            for (uint32_t k = 0; k < g_.nodes[i].childCount; ++k) {
                const NodeId c = g_.child(i, k);
                if (c < count) ++start[c + 1];
            }
        for (size_t i = 0; i < count; ++i) start[i + 1] += start[i];
        std::vector<NodeId> parents(start[count]);
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (NodeId i = 0; i < count; ++i)
            for (uint32_t k = 0; k < g_.nodes[i].childCount; ++k) {
                const NodeId c = g_.child(i, k);
                if (c < count) parents[fill[c]++] = i;
            }
        for (size_t q = 0; q < queue.size(); ++q) {
            const NodeId n = queue[q];
            for (uint32_t k = start[n]; k < start[n + 1]; ++k) {
                const NodeId p = parents[k];
                if (source[p] != kNone) continue;
                source[p] = source[n];
                queue.push_back(p);
            }
        }
        for (NodeId i = 0; i < count; ++i) {
            const Node& n = g_.nodes[i];
            if (n.kind != NodeKind::Operator || n.op() == CsgOp::Union) continue;
            for (uint32_t k = 0; k < n.childCount; ++k) {
                const NodeId c = g_.child(i, k);
                if (c >= count || source[c] == kNone) continue;
                const Node& tri = g_.nodes[source[c]];
                diags_.error(
                    n.loc, fmt::format("a triangle ({} at line {}) is reachable as an operand of "
                                       "this {}: triangles are surfaces without an inside, "
                                       "so only '∪' may combine them",
                                       primitiveName(g_.primitives[tri.payload].kind), tri.loc.line,
                                       csgOpName(n.op())));
                break;
            }
        }
    }

    static const char* primitiveName(PrimitiveKind k) {
        switch (k) {
            case PrimitiveKind::Tri1:
                return "tri1";
            case PrimitiveKind::Tri2:
                return "tri2";
            default:
                return "triangle";
        }
    }

    const Source& src_;
    const std::vector<Token>& t_;
    const Ast& ast_;
    Diagnostics& diags_;
    Graph g_;

    uint32_t settingsSeen_ = kNoNode, cameraSeen_ = kNoNode, backgroundSeen_ = kNoNode;
    uint32_t defaultMaterialSeen_ = kNoNode;
    std::unordered_map<std::string_view, uint32_t> materialByName_;  // -> Graph::materials
    std::unordered_map<uint32_t, uint32_t> materialTok_;             // material -> its name token
    std::unordered_map<uint32_t, uint32_t> materialIndex_;           // name token -> material

    std::vector<ModuleInfo> modules_;
    std::unordered_map<std::string_view, uint32_t> moduleByName_;
    std::unordered_map<std::string_view, uint32_t> definitionByName_;  // -> statement
    std::unordered_map<uint32_t, NodeId> definitionNode_;              // statement -> node
    std::unordered_set<uint32_t> cyclic_;
    std::unordered_set<std::string_view> assigned_;
    std::unordered_set<std::string_view> reportedUnknown_;
    std::unordered_set<std::string_view> dropped_;
    std::unordered_map<std::string_view, Slot> slots_;
    const Stmt* axiom_ = nullptr;
    NodeId placeholder_ = kNone;
    bool constantOnly_ = false;
};

}  // namespace

std::optional<Graph> build(const Source& src, const TokenStream& tokens, const Ast& ast,
                           Diagnostics& diags) {
    return Builder(src, tokens, ast, diags).run();
}

}  // namespace pcsg
