// The builder's name phase: modules, rules in notations A and B, definitions and their
// order, materials, the axiom (docs/language.md sections 2, 4 and 7). See build_names.h.
#include "build_names.h"

#include <fmt/format.h>

#include <algorithm>

namespace pcsg {

namespace {

class NameResolver {
  public:
    NameResolver(BuildContext& ctx, Names& names) : ctx_(ctx), ast_(ctx.ast), names_(names) {}

    void run() {
        declarations();
        for (ModuleInfo& m : names_.modules) checkModule(m);
        assignedParameters();
        axiom();
        definitionOrder();
    }

  private:
    uint32_t moduleFor(uint32_t nameTok);
    void declarations();
    void declaration(uint32_t si);
    void ruleA(uint32_t si);
    void ruleB(uint32_t si);
    void definition(uint32_t si);
    void formals(ModuleInfo& m, uint32_t si);
    void checkModule(ModuleInfo& m);
    void checkRuleNumbers(ModuleInfo& m);
    void assignedParameters();
    void axiom();
    void namedDefinitions(uint32_t c, std::vector<uint32_t>& out) const;
    void definitionOrder();
    void reportCycle(const std::vector<uint32_t>& stack, uint32_t d);

    const Stmt& stmt(uint32_t si) const { return ast_.stmts[si]; }

    BuildContext& ctx_;
    const Ast& ast_;
    Names& names_;
};

// The module of a name, created where it first appears.
uint32_t NameResolver::moduleFor(uint32_t nameTok) {
    const std::string_view name = ctx_.text(nameTok);
    auto [it, inserted] =
        names_.moduleByName.emplace(name, static_cast<uint32_t>(names_.modules.size()));
    if (inserted) {
        ModuleInfo m;
        m.name = name;
        m.firstTok = nameTok;
        names_.modules.push_back(std::move(m));
    }
    return it->second;
}

void NameResolver::declarations() {
    for (uint32_t si = 0; si < ast_.stmts.size(); ++si) {
        switch (stmt(si).kind) {
            case StmtKind::Module:
                declaration(si);
                break;
            case StmtKind::RuleA:
                ruleA(si);
                break;
            case StmtKind::RuleB:
                ruleB(si);
                break;
            case StmtKind::Definition:
                definition(si);
                break;
            default:
                break;
        }
    }
}

// Notation A: `S expr` declares S and its selection function.
void NameResolver::declaration(uint32_t si) {
    const Stmt& s = stmt(si);
    ModuleInfo& m = names_.modules[moduleFor(s.nameTok)];
    if (m.decl != kNoNode) {
        ctx_.error(s.nameTok, fmt::format("module {} is already declared at line {}", clip(m.name),
                                          ctx_.line(stmt(m.decl).nameTok)));
    } else if (m.notationB) {
        ctx_.error(s.nameTok, fmt::format("module {} has notation-B rules (line {}), which "
                                          "select by their conditions: it cannot also have a "
                                          "selection function (to start from {}, write the "
                                          "axiom with a label: 'w: {}(...)')",
                                          clip(m.name), ctx_.line(stmt(m.rules[0]).nameTok),
                                          clip(m.name), clip(m.name)));
    } else {
        m.decl = si;
    }
}

void NameResolver::ruleA(uint32_t si) {
    const Stmt& s = stmt(si);
    ModuleInfo& m = names_.modules[moduleFor(s.nameTok)];
    if (m.notationB) {
        ctx_.error(s.tok, fmt::format("module {} uses notation B (rule at line {}); one module "
                                      "uses one notation",
                                      clip(m.name), ctx_.line(stmt(m.rules[0]).tok)));
        return;
    }
    m.hasRules = true;
    m.rules.push_back(si);
}

void NameResolver::ruleB(uint32_t si) {
    const Stmt& s = stmt(si);
    ModuleInfo& m = names_.modules[moduleFor(s.nameTok)];
    if (m.decl != kNoNode || (m.hasRules && !m.notationB)) {
        const uint32_t where = m.decl != kNoNode ? stmt(m.decl).tok : stmt(m.rules[0]).tok;
        ctx_.error(s.tok, fmt::format("module {} uses notation A (line {}); one module uses "
                                      "one notation",
                                      clip(m.name), ctx_.line(where)));
        return;
    }
    formals(m, si);
    m.notationB = true;
    m.hasRules = true;
    m.rules.push_back(si);
}

void NameResolver::definition(uint32_t si) {
    const Stmt& s = stmt(si);
    const std::string_view name = ctx_.text(s.nameTok);
    auto [it, inserted] = names_.definitionByName.emplace(name, si);
    if (!inserted)
        ctx_.error(s.nameTok, fmt::format("'{}' is already defined at line {}", clip(name),
                                          ctx_.line(stmt(it->second).nameTok)));
}

// Notation B: every rule of a module lists the same formal parameters.
void NameResolver::formals(ModuleInfo& m, uint32_t si) {
    const Stmt& s = stmt(si);
    std::vector<uint32_t> mine(ast_.lists.begin() + s.first,
                               ast_.lists.begin() + s.first + s.count);
    for (size_t i = 0; i < mine.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            if (ctx_.text(mine[i]) == ctx_.text(mine[j]))
                ctx_.error(mine[i],
                           fmt::format("parameter '{}' is listed twice", clip(ctx_.text(mine[i]))));
    if (m.formalsRule == kNoNode) {
        m.formals = mine;
        m.formalsRule = si;
        return;
    }
    bool same = m.formals.size() == mine.size();
    for (size_t i = 0; same && i < mine.size(); ++i)
        same = ctx_.text(mine[i]) == ctx_.text(m.formals[i]);
    if (!same)
        ctx_.error(s.nameTok,
                   fmt::format("rule '{}' gives module {} the parameters ({}), but its rule at "
                               "line {} gives ({})",
                               clip(ctx_.text(s.labelTok)), clip(m.name), formalList(ctx_, mine),
                               ctx_.line(stmt(m.formalsRule).tok), formalList(ctx_, m.formals)));
}

// A module's name is not also a definition's; a notation-A module is declared and has
// its rules.
void NameResolver::checkModule(ModuleInfo& m) {
    if (names_.definitionByName.count(m.name)) {
        const Stmt& d = stmt(names_.definitionByName.at(m.name));
        ctx_.error(d.nameTok,
                   fmt::format("'{}' is a module (line {}) and cannot also be a definition",
                               clip(m.name), ctx_.line(m.firstTok)));
    }
    if (m.notationB || names_.dropped(m.name)) return;
    if (m.decl == kNoNode) {
        ctx_.error(stmt(m.rules[0]).nameTok,
                   fmt::format("module {} is not declared: add a line '{} <selection function>' "
                               "that chooses among its rules",
                               clip(m.name), clip(m.name)));
        return;
    }
    if (m.rules.empty()) {
        ctx_.error(stmt(m.decl).nameTok, fmt::format("module {} has no rules", clip(m.name)));
        return;
    }
    checkRuleNumbers(m);
}

// Rules 1..n, each exactly once; the S-node's children in rule order.
void NameResolver::checkRuleNumbers(ModuleInfo& m) {
    std::stable_sort(m.rules.begin(), m.rules.end(),
                     [&](uint32_t a, uint32_t b) { return stmt(a).number < stmt(b).number; });
    bool ok = true;
    for (size_t i = 1; i < m.rules.size(); ++i) {
        const Stmt& a = stmt(m.rules[i - 1]);
        const Stmt& b = stmt(m.rules[i]);
        if (a.number == b.number) {
            ctx_.error(b.labelTok, fmt::format("rule {} of module {} is already given at line {}",
                                               b.number, clip(m.name), ctx_.line(a.labelTok)));
            ok = false;
        }
    }
    if (!ok) return;
    for (size_t i = 0; i < m.rules.size(); ++i) {
        const Stmt& r = stmt(m.rules[i]);
        if (r.number != i + 1) {
            ctx_.error(r.labelTok, fmt::format("module {} has no rule {}: its rules must be "
                                               "numbered 1 to {} without gaps",
                                               clip(m.name), i + 1, m.rules.size()));
            break;
        }
    }
}

// The parameters that a C-node or a notation-B formal assigns.
void NameResolver::assignedParameters() {
    for (const Assign& a : ast_.assigns) names_.assigned.insert(ctx_.text(a.nameTok));
    for (const ModuleInfo& m : names_.modules)
        for (uint32_t f : m.formals) names_.assigned.insert(ctx_.text(f));
}

void NameResolver::axiom() {
    for (const Stmt& s : ast_.stmts) {
        if (s.kind != StmtKind::AxiomA && s.kind != StmtKind::AxiomB) continue;
        if (names_.axiom == nullptr) {
            names_.axiom = &s;
            continue;
        }
        ctx_.error(s.tok,
                   fmt::format("a second axiom (the first is at line {}): a file has exactly one",
                               ctx_.line(names_.axiom->tok)));
    }
    if (!names_.axiom && ast_.dropped == 0)
        ctx_.diags.error(FileLoc{ctx_.src.file(), 1, 1},
                         "the file has no axiom: a statement that is the object itself, such as "
                         "'{c = 6} S' or 'w: S(6)'");
}

// The definitions a CSG expression names directly (through definitions only: a module
// name ends the search, since S-nodes may form cycles).
void NameResolver::namedDefinitions(uint32_t c, std::vector<uint32_t>& out) const {
    const CsgNode& n = ast_.csg[c];
    switch (n.kind) {
        case CsgKind::Operator:
            for (uint32_t i = 0; i < n.count; ++i) namedDefinitions(ast_.lists[n.first + i], out);
            break;
        case CsgKind::Transform:
        case CsgKind::Calc:
        case CsgKind::Paint:
            namedDefinitions(n.child, out);
            break;
        case CsgKind::Name: {
            const std::string_view name = ctx_.text(n.nameTok);
            if (names_.moduleByName.count(name)) break;
            auto it = names_.definitionByName.find(name);
            if (it != names_.definitionByName.end()) out.push_back(it->second);
            break;
        }
        default:
            break;
    }
}

// Definitions in an order where each comes after those it names (a depth-first search
// with an explicit stack). A definition that refers to itself through definitions only
// is an error (it would be infinite).
void NameResolver::definitionOrder() {
    std::unordered_map<uint32_t, uint8_t> state;  // 1: on the stack, 2: done
    struct Frame {
        uint32_t stmt;
        std::vector<uint32_t> deps;
        size_t next = 0;
    };
    std::vector<Frame> stack;
    std::vector<uint32_t> onStack;  // the statements of `stack`, for reportCycle
    auto enter = [&](uint32_t s) {
        Frame f{s, {}, 0};
        namedDefinitions(stmt(s).body, f.deps);
        state[s] = 1;
        stack.push_back(std::move(f));
        onStack.push_back(s);
    };
    for (uint32_t si = 0; si < ast_.stmts.size(); ++si) {
        if (stmt(si).kind != StmtKind::Definition || state[si]) continue;
        if (names_.definitionByName.at(ctx_.text(stmt(si).nameTok)) != si) continue;  // duplicate
        enter(si);
        while (!stack.empty()) {
            Frame& f = stack.back();
            if (f.next == f.deps.size()) {
                state[f.stmt] = 2;
                names_.definitionOrder.push_back(f.stmt);
                stack.pop_back();
                onStack.pop_back();
                continue;
            }
            const uint32_t d = f.deps[f.next++];
            if (state[d] == 2) continue;
            if (state[d] == 1) {
                reportCycle(onStack, d);
                continue;
            }
            enter(d);
        }
    }
}

// A cycle: the stack from d up to its top. Reported once, where the search closes it.
void NameResolver::reportCycle(const std::vector<uint32_t>& stack, uint32_t d) {
    std::string path;
    size_t k = 0;
    while (stack[k] != d) ++k;
    for (size_t j = k; j < stack.size(); ++j)
        path += fmt::format("{} -> ", clip(ctx_.text(stmt(stack[j]).nameTok)));
    path += ctx_.text(stmt(d).nameTok);
    if (!names_.cyclic.count(d)) {
        ctx_.error(stmt(d).nameTok,
                   fmt::format("definition '{}' refers to itself ({}): only a module can be "
                               "recursive",
                               clip(ctx_.text(stmt(d).nameTok)), path));
    }
    for (size_t j = k; j < stack.size(); ++j) names_.cyclic.insert(stack[j]);
}

}  // namespace

void declareMaterials(BuildContext& ctx, Names& names) {
    Graph& g = ctx.g;
    uint32_t defaultSeen = kNoNode;
    std::unordered_map<uint32_t, uint32_t> nameTok;  // material -> its name token
    for (const Stmt& s : ctx.ast.stmts) {
        if (s.kind != StmtKind::Directive || s.directive != Kw::Material) continue;
        const std::string_view name = ctx.text(s.nameTok);
        if (name == "default") {
            if (defaultSeen != kNoNode) {
                ctx.error(s.nameTok, fmt::format("material 'default' is already given at line {}",
                                                 ctx.line(defaultSeen)));
                continue;
            }
            defaultSeen = s.nameTok;
            names.materialOfName[s.nameTok] = 0;
            continue;
        }
        const uint32_t index = static_cast<uint32_t>(g.materials.size());
        auto [it, inserted] = names.materialByName.emplace(name, index);
        if (!inserted) {
            ctx.error(s.nameTok, fmt::format("material '{}' is already defined at line {}",
                                             clip(name), ctx.line(nameTok[it->second])));
            continue;
        }
        Material m;
        m.name = std::string(name);
        nameTok[index] = s.nameTok;
        names.materialOfName[s.nameTok] = index;
        g.materials.push_back(m);
    }
}

void resolveNames(BuildContext& ctx, Names& names) {
    NameResolver(ctx, names).run();
}

std::string formalList(const BuildContext& ctx, const std::vector<uint32_t>& toks) {
    std::string s;
    for (size_t i = 0; i < toks.size(); ++i) {
        if (i) s += ", ";
        s += clip(ctx.text(toks[i]));
    }
    return s;
}

}  // namespace pcsg
