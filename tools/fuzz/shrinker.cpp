// Shrinking on the syntax tree: see shrinker.h.
#include "shrinker.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <set>
#include <unordered_set>

#include "ast.h"
#include "formatter.h"
#include "parser.h"

namespace pcsg::fuzz {

namespace {

// A parsed scene that edits may change: its text grows by the spellings of the tokens
// edits add (after the End token), so that the printer finds them.
struct Tree {
    std::string text;
    std::vector<Token> tokens;
    Ast ast;

    std::string_view spelled(uint32_t tok) const {
        return std::string_view(text).substr(tokens[tok].offset, tokens[tok].length);
    }
    uint32_t addToken(Tok kind, Kw kw, std::string_view spelling) {
        text += '\n';
        Token t;
        t.kind = kind;
        t.kw = kw;
        t.offset = uint32_t(text.size());
        t.length = uint32_t(spelling.size());
        text += spelling;
        tokens.push_back(t);
        return uint32_t(tokens.size() - 1);
    }
};

std::optional<Tree> parseTree(const std::string& text) {
    Tree t;
    t.text = text;
    Diagnostics diags;
    const Source src(t.text, diags.addFile("shrink.pcsg", t.text));
    TokenStream tokens = lex(src, diags);
    t.ast = parse(src, tokens, diags);
    if (diags.hasErrors()) return std::nullopt;
    t.tokens = std::move(tokens.tokens);
    return t;
}

// The edited tree printed and formatted; nothing when it does not compile.
std::optional<std::string> printTree(const Tree& t) {
    const Source src(t.text, 0);
    const std::string printed = printSyntaxTree(src, t.tokens, t.ast);
    Diagnostics diags;
    return formatScene("shrink.pcsg", printed, diags);
}

using Edit = std::function<void(Tree&)>;

// Dropping statements: every one but the axiom and the camera; a module with its rules.
void statementEdits(const Tree& base, std::vector<Edit>& edits) {
    for (size_t i = 0; i < base.ast.stmts.size(); ++i) {
        const Stmt& s = base.ast.stmts[i];
        if (s.kind == StmtKind::AxiomA || s.kind == StmtKind::AxiomB || s.kind == StmtKind::RuleA)
            continue;
        if (s.kind == StmtKind::Directive && s.directive == Kw::Camera) continue;
        const bool module = s.kind == StmtKind::Module;
        const std::string name(base.spelled(s.nameTok));
        edits.push_back([i, module, name](Tree& t) {
            std::vector<Stmt> kept;
            for (size_t k = 0; k < t.ast.stmts.size(); ++k) {
                const Stmt& x = t.ast.stmts[k];
                const bool rule = x.kind == StmtKind::RuleA || x.kind == StmtKind::RuleB;
                if (k == i || (module && rule && t.spelled(x.nameTok) == name)) continue;
                kept.push_back(x);
            }
            t.ast.stmts = std::move(kept);
        });
    }
}

// Edits of CSG nodes, from the last built to the first (in a statement, the outermost
// first).
void nodeEdits(const Tree& base, std::vector<Edit>& edits) {
    for (size_t x = base.ast.csg.size(); x-- > 0;) {
        const CsgNode& n = base.ast.csg[x];
        if (!(n.kind == CsgKind::Primitive && n.prim == PrimitiveKind::Empty))
            edits.push_back([x](Tree& t) {
                CsgNode e{.kind = CsgKind::Primitive};
                e.prim = PrimitiveKind::Empty;
                e.tok = t.addToken(Tok::Keyword, Kw::Empty, "empty");
                t.ast.csg[x] = e;
            });
        if (n.kind == CsgKind::Operator) {
            for (uint32_t k = 0; k < n.count; ++k) {
                const uint32_t operand = base.ast.lists[n.first + k];
                edits.push_back([x, operand](Tree& t) { t.ast.csg[x] = t.ast.csg[operand]; });
                if (n.count < 3) continue;
                edits.push_back([x, k](Tree& t) {
                    CsgNode& m = t.ast.csg[x];
                    const uint32_t first = uint32_t(t.ast.lists.size());
                    for (uint32_t j = 0; j < m.count; ++j)
                        if (j != k) t.ast.lists.push_back(t.ast.lists[m.first + j]);
                    m.first = first;
                    m.count -= 1;
                });
            }
        } else if (n.child != kNoNode && (n.kind == CsgKind::Transform || n.kind == CsgKind::Calc ||
                                          n.kind == CsgKind::Paint)) {
            const uint32_t child = n.child;
            edits.push_back([x, child](Tree& t) { t.ast.csg[x] = t.ast.csg[child]; });
        }
    }
}

// Simpler numbers: a small whole number lowered by one, a fraction rounded.
void numberEdits(const Tree& base, std::vector<Edit>& edits) {
    for (size_t e = 0; e < base.ast.exprs.size(); ++e) {
        const ExNode& n = base.ast.exprs[e];
        if (n.kind != ExKind::Number) continue;
        const std::string spelled(base.spelled(n.tok));
        const double v = std::strtod(spelled.c_str(), nullptr);
        std::vector<std::string> simpler;
        if (v == std::floor(v)) {
            if (v >= 1 && v <= 10) simpler.push_back(fmt::format("{}", v - 1));
        } else {
            const double tenth = std::round(v * 10) / 10;
            if (tenth != v && tenth != std::round(v)) simpler.push_back(fmt::format("{}", tenth));
            simpler.push_back(fmt::format("{}", std::round(v)));
        }
        for (const std::string& s : simpler)
            edits.push_back(
                [e, s](Tree& t) { t.ast.exprs[e].tok = t.addToken(Tok::Number, Kw::None, s); });
    }
}

// The module, definition and material names the CSG under `root` names.
void namesUnder(const Tree& t, uint32_t root, std::set<std::string>& names) {
    std::vector<uint32_t> stack = {root};
    while (!stack.empty()) {
        const CsgNode& n = t.ast.csg[stack.back()];
        stack.pop_back();
        if (n.kind == CsgKind::Name || n.kind == CsgKind::Call || n.kind == CsgKind::Paint)
            names.insert(std::string(t.spelled(n.nameTok)));
        if (n.kind == CsgKind::Operator)
            for (uint32_t k = 0; k < n.count; ++k) stack.push_back(t.ast.lists[n.first + k]);
        else if (n.child != kNoNode)
            stack.push_back(n.child);
    }
}

bool isAxiom(const Stmt& s) {
    return s.kind == StmtKind::AxiomA || s.kind == StmtKind::AxiomB;
}

// What the axiom reaches: the names of modules, definitions and materials it uses,
// directly or through the rules and definitions it uses.
std::set<std::string> reachedNames(const Tree& t) {
    std::set<std::string> names = {"default"};
    size_t before = 0;
    do {
        before = names.size();
        for (const Stmt& s : t.ast.stmts) {
            if (s.body == kNoNode || s.kind == StmtKind::Directive) continue;
            if (isAxiom(s) || names.count(std::string(t.spelled(s.nameTok))))
                namesUnder(t, s.body, names);
        }
    } while (names.size() != before);
    return names;
}

// One edit that drops every module, definition and material the axiom does not reach
// (which may still change the picture: rand() call sites are numbered in file order).
std::optional<std::string> dropUnreached(const std::string& text) {
    std::optional<Tree> t = parseTree(text);
    if (!t) return std::nullopt;
    const std::set<std::string> reached = reachedNames(*t);
    std::vector<Stmt> kept;
    for (const Stmt& s : t->ast.stmts) {
        const bool named = s.kind == StmtKind::Module || s.kind == StmtKind::RuleA ||
                           s.kind == StmtKind::RuleB || s.kind == StmtKind::Definition ||
                           (s.kind == StmtKind::Directive && s.directive == Kw::Material);
        if (!named || reached.count(std::string(t->spelled(s.nameTok)))) kept.push_back(s);
    }
    if (kept.size() == t->ast.stmts.size()) return std::nullopt;
    t->ast.stmts = std::move(kept);
    return printTree(*t);
}

}  // namespace

std::vector<std::string> shrinkCandidates(const std::string& text) {
    const std::optional<Tree> base = parseTree(text);
    if (!base) return {};
    std::vector<Edit> edits;
    statementEdits(*base, edits);
    nodeEdits(*base, edits);
    numberEdits(*base, edits);
    std::vector<std::string> out;
    std::set<std::string> seen = {text};
    if (std::optional<std::string> pruned = dropUnreached(text)) {
        seen.insert(*pruned);
        out.push_back(std::move(*pruned));
    }
    for (const Edit& edit : edits) {
        Tree t = *base;
        edit(t);
        std::optional<std::string> printed = printTree(t);
        if (printed && seen.insert(*printed).second) out.push_back(std::move(*printed));
    }
    return out;
}

ShrinkResult shrinkSystem(const std::string& text, const StillFails& stillFails,
                          const ShrinkOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const auto outOfTime = [&] {
        const std::chrono::duration<double> spent = std::chrono::steady_clock::now() - start;
        return options.maxSeconds > 0 && spent.count() > options.maxSeconds;
    };
    ShrinkResult r;
    Diagnostics diags;
    r.text = formatScene("shrink.pcsg", text, diags).value_or(text);
    std::vector<std::string> candidates = shrinkCandidates(r.text);
    std::unordered_set<std::string> rejected;
    size_t next = 0, sinceProgress = 0;
    while (!candidates.empty() && sinceProgress < candidates.size() && r.tries < options.maxTries &&
           !outOfTime()) {
        const std::string& c = candidates[next % candidates.size()];
        ++next;
        ++sinceProgress;
        if (rejected.count(c)) continue;
        ++r.tries;
        if (!stillFails(c)) {
            rejected.insert(c);
            continue;
        }
        r.text = c;
        ++r.accepted;
        sinceProgress = 0;
        candidates = shrinkCandidates(r.text);
        // Dropping what is no longer reached (the first candidate when there is any) is
        // worth trying at once after every step.
        if (!candidates.empty() && dropUnreached(r.text) == candidates.front()) next = 0;
    }
    return r;
}

}  // namespace pcsg::fuzz
