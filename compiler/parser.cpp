// The parser: recursive descent over the token stream of lexer.cpp. Each parse function
// is headed by the grammar rule it parses (EBNF: {x} repeats, [x] is optional).
#include "parser.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <numbers>

namespace pcsg {

int binaryPrecedence(Tok k, bool assignIsEq) {
    switch (k) {
        case Tok::OrOr:
            return 1;
        case Tok::AndAnd:
            return 2;
        case Tok::Eq:
        case Tok::Ne:
            return 3;
        case Tok::Assign:
            return assignIsEq ? 3 : 0;
        case Tok::Lt:
        case Tok::Le:
        case Tok::Gt:
        case Tok::Ge:
            return 4;
        case Tok::Plus:
        case Tok::Minus:
            return 5;
        case Tok::Star:
        case Tok::Slash:
        case Tok::Percent:
            return 6;
        default:
            return 0;
    }
}

namespace {

struct Abort {};  // thrown on a syntax error: unwinds to the statement level

bool isCsgOperator(Tok k) {
    return k == Tok::Union || k == Tok::Intersect || k == Tok::Difference;
}
bool isSeparator(Tok k) {
    return k == Tok::Newline || k == Tok::Semicolon || k == Tok::Comma;
}

bool isTransform(Kw k) {
    switch (k) {
        case Kw::Move:
        case Kw::Translate:
        case Kw::Scale:
        case Kw::UScale:
        case Kw::RotX:
        case Kw::RotY:
        case Kw::RotZ:
        case Kw::Rot:
        case Kw::ZShear:
        case Kw::FlipYZ:
        case Kw::FlipXZ:
        case Kw::FlipXY:
        case Kw::Matrix:
            return true;
        default:
            return false;
    }
}
TransformOp transformOp(Kw k) {
    switch (k) {
        case Kw::Move:
        case Kw::Translate:
            return TransformOp::Move;
        case Kw::Scale:
            return TransformOp::Scale;
        case Kw::UScale:
            return TransformOp::UScale;
        case Kw::RotX:
            return TransformOp::RotX;
        case Kw::RotY:
            return TransformOp::RotY;
        case Kw::RotZ:
            return TransformOp::RotZ;
        case Kw::Rot:
            return TransformOp::Rot;
        case Kw::ZShear:
            return TransformOp::ZShear;
        case Kw::FlipYZ:
            return TransformOp::FlipYZ;
        case Kw::FlipXZ:
            return TransformOp::FlipXZ;
        case Kw::FlipXY:
            return TransformOp::FlipXY;
        default:
            return TransformOp::Matrix;
    }
}
bool isFlip(Kw k) {
    return k == Kw::FlipYZ || k == Kw::FlipXZ || k == Kw::FlipXY;
}

bool isPrimitive(Kw k) {
    return k >= Kw::Sphere && k <= Kw::Triangle;
}
PrimitiveKind primitiveKind(Kw k) {
    return static_cast<PrimitiveKind>(static_cast<int>(k) - static_cast<int>(Kw::Sphere));
}
static_assert(static_cast<int>(Kw::Triangle) - static_cast<int>(Kw::Sphere) ==
              static_cast<int>(PrimitiveKind::Triangle));

bool isFunction(Kw k) {
    return k == Kw::If || k == Kw::Rand || k == Kw::Choose || (k >= Kw::Sin && k <= Kw::Clamp);
}
bool isDirective(Kw k) {
    return k >= Kw::Camera && k <= Kw::SkySphere;
}

const int kAdditive = binaryPrecedence(Tok::Plus, false);

class Parser {
  public:
    Parser(const Source& src, const TokenStream& ts, Diagnostics& diags)
        : src_(src), t_(ts.tokens), diags_(diags) {}

    // file -> { statement (NEWLINE | ';' | EOF) }
    Ast file() {
        // Upper bounds from the token count, so that no array is copied while it grows
        // (untouched reserved memory costs nothing).
        const size_t n = t_.size();
        ast_.exprs.reserve(n / 2 + 16);
        ast_.csg.reserve(n / 2 + 16);
        ast_.lists.reserve(n / 2 + 16);
        ast_.chainItems.reserve(n / 2 + 16);
        ast_.assigns.reserve(n / 3 + 16);
        ast_.stmts.reserve(n / 2 + 16);
        while (!at(Tok::End)) {
            if (at(Tok::Newline) || at(Tok::Semicolon)) {
                ++p_;
                continue;
            }
            if (diags_.errors().size() >= Diagnostics::kMaxErrors) break;
            const size_t start = p_;
            const size_t statements = ast_.stmts.size();
            try {
                depth_ = 0;
                assignIsEq_ = false;
                statement();
                if (!at(Tok::Newline) && !at(Tok::Semicolon) && !at(Tok::End))
                    fail(p_, fmt::format("expected the end of the statement, found {}",
                                         describe(src_, tok())));
            } catch (const Abort&) {
                // Panic mode: drop the statement, resume after its end.
                ast_.stmts.resize(statements);
                dropped(start);
                while (!at(Tok::End) &&
                       !((at(Tok::Newline) || at(Tok::Semicolon)) && (tok().flags & kTopLevel)))
                    ++p_;
            }
        }
        return std::move(ast_);
    }

  private:
    // Records what a statement that failed to parse may have declared.
    void dropped(size_t start) {
        ++ast_.dropped;
        const Token& a = t_[start];
        const Token& b = start + 1 < t_.size() ? t_[start + 1] : t_.back();
        const Token& c = start + 2 < t_.size() ? t_[start + 2] : t_.back();
        if ((a.kind == Tok::Ident || a.kind == Tok::Number) && b.kind == Tok::Colon) {
            if (c.kind == Tok::Ident) ast_.droppedNames.push_back(static_cast<uint32_t>(start + 2));
        } else if (a.kind == Tok::Ident && !isCsgOperator(b.kind)) {
            ast_.droppedNames.push_back(static_cast<uint32_t>(start));  // definition or module
        } else if (a.isKw(Kw::Material) && b.kind == Tok::Ident) {
            ast_.droppedNames.push_back(static_cast<uint32_t>(start + 1));
        }
    }

    // --- tokens ---
    const Token& tok(size_t k = 0) const {
        const size_t i = p_ + k;
        return i < t_.size() ? t_[i] : t_.back();
    }
    bool at(Tok k) const { return tok().kind == k; }
    bool atKw(Kw k) const { return tok().isKw(k); }
    uint32_t pos() const { return static_cast<uint32_t>(p_); }
    std::string_view text(uint32_t i) const { return spelling(src_, t_[i]); }

    [[noreturn]] void fail(size_t tokenIndex, std::string message) {
        const Token& t = t_[std::min(tokenIndex, t_.size() - 1)];
        diags_.error(src_.loc(t.offset), std::move(message));
        throw Abort{};
    }
    void expect(Tok k, std::string_view what) {
        if (!at(k)) fail(p_, fmt::format("expected {}, found {}", what, describe(src_, tok())));
        ++p_;
    }
    // One more level of nesting; the guard gives it back.
    struct Nest {
        explicit Nest(Parser& p) : parser(p) {
            if (++parser.depth_ > kMaxNesting) {
                --parser.depth_;
                parser.fail(parser.p_, fmt::format("nesting deeper than {} levels (parentheses, "
                                                   "braces and prefix operators)",
                                                   kMaxNesting));
            }
        }
        ~Nest() { --parser.depth_; }
        Parser& parser;
    };

    // --- statements ---

    // statement -> directive | ruleA | ruleB | axiomB | definition | module | axiomA
    void statement() {
        const Token& a = tok();
        const Token& b = tok(1);
        if (a.kind == Tok::Keyword && isDirective(a.kw)) return directive();
        if (a.kind == Tok::Number && b.kind == Tok::Colon) return ruleA();
        if (a.kind == Tok::Ident && b.kind == Tok::Colon) {
            if (arrowAhead()) return ruleB();
            return axiomB();
        }
        if (a.kind == Tok::Ident && b.kind == Tok::Assign) return definition();
        if (isCsgOperator(a.kind)) failLeadingOperator();
        if (a.kind == Tok::Keyword && b.kind == Tok::Assign)
            fail(p_, fmt::format("'{}' is a keyword and cannot name a definition", text(pos())));
        if (a.kind == Tok::Ident && !isCsgOperator(b.kind) && b.kind != Tok::Newline &&
            b.kind != Tok::Semicolon && b.kind != Tok::End)
            return moduleDecl();
        return axiomA();
    }

    // A statement that starts with a CSG operator: the usual cause is a rule continued on
    // a line that begins with the operator (as many L-system texts write it), where the
    // line break before it had ended the statement (section 2).
    [[noreturn]] void failLeadingOperator() {
        const std::string op(text(pos()));
        size_t q = p_;
        while (q > 0 && t_[q - 1].kind == Tok::Newline) --q;
        if (q == 0) fail(p_, fmt::format("a statement cannot start with '{}'", op));
        if (t_[q - 1].kind == Tok::Semicolon)
            fail(p_, fmt::format("a statement cannot start with '{}': the ';' before it ended the "
                                 "statement",
                                 op));
        const uint32_t line = src_.loc(t_[q - 1].offset).line;
        fail(p_, fmt::format("a statement cannot start with '{0}': the line break after line {1} "
                             "ended the statement there; to continue it, end line {1} with '{0}' "
                             "instead, or put the whole expression in parentheses",
                             op, line));
    }

    bool arrowAhead() const {
        for (size_t i = p_; i < t_.size(); ++i) {
            const Token& t = t_[i];
            if (t.kind == Tok::Arrow) return true;
            if (t.kind == Tok::End) return false;
            if ((t.kind == Tok::Newline || t.kind == Tok::Semicolon) && (t.flags & kTopLevel))
                return false;
        }
        return false;
    }

    uint32_t name(std::string_view what) {
        if (at(Tok::Keyword) && (tok().kw == Kw::Clock || tok().kw == Kw::Frame))
            fail(p_, fmt::format("'{}' is the time of the frame, read-only: it cannot name {}",
                                 text(pos()), what));
        if (at(Tok::Keyword))
            fail(p_, fmt::format("'{}' is a keyword and cannot name {}", text(pos()), what));
        if (!at(Tok::Ident))
            fail(p_, fmt::format("expected the name of {}, found {}", what, describe(src_, tok())));
        return static_cast<uint32_t>(p_++);
    }

    void arrow() {
        if (at(Tok::Arrow)) {
            ++p_;
            return;
        }
        fail(p_, fmt::format("expected '->' or '→', found {}", describe(src_, tok())));
    }

    // ruleA -> INTEGER ':' IDENT ARROW csg
    void ruleA() {
        Stmt s;
        s.kind = StmtKind::RuleA;
        s.tok = s.labelTok = pos();
        const Token& n = tok();
        const std::string_view digits = text(pos());
        double value = 0;
        std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (!(n.flags & kInteger) || value < 1)
            fail(p_, fmt::format("a rule number must be a whole number from 1 up, found '{}'",
                                 clip(digits)));
        if (value > kMaxRuleNumber)
            fail(p_, fmt::format("rule number {} is too large (at most {})", clip(digits),
                                 kMaxRuleNumber));
        s.number = static_cast<uint32_t>(value);
        p_ += 2;
        s.nameTok = name("a module");
        if (at(Tok::LParen))
            fail(p_,
                 "a numbered rule (notation A) has no parameter list; notation-B rules are "
                 "labelled by a name, as in 'p1: S(c) -> ...'");
        arrow();
        s.body = csg();
        ast_.stmts.push_back(s);
    }

    // ruleB -> IDENT ':' IDENT [ '(' [ IDENT { ',' IDENT } ] ')' ] [ ':' expr ] ARROW csg
    void ruleB() {
        Stmt s;
        s.kind = StmtKind::RuleB;
        s.tok = s.labelTok = pos();
        p_ += 2;
        s.nameTok = name("a module");
        std::vector<uint32_t> formals;
        if (at(Tok::LParen)) {
            ++p_;
            s.hasFormals = true;
            if (!at(Tok::RParen)) {
                formals.push_back(name("a parameter"));
                while (at(Tok::Comma)) {
                    ++p_;
                    formals.push_back(name("a parameter"));
                }
            }
            expect(Tok::RParen, "')' after the formal parameters");
        }
        if (at(Tok::Colon)) {
            ++p_;
            assignIsEq_ = true;  // the paper's `c=0`
            s.expr = expr();
            assignIsEq_ = false;
        }
        arrow();
        s.body = csg();
        s.first = static_cast<uint32_t>(ast_.lists.size());
        s.count = static_cast<uint32_t>(formals.size());
        ast_.lists.insert(ast_.lists.end(), formals.begin(), formals.end());
        ast_.stmts.push_back(s);
    }

    // axiomB -> IDENT ':' csg
    void axiomB() {
        Stmt s;
        s.kind = StmtKind::AxiomB;
        s.tok = s.labelTok = pos();
        p_ += 2;
        s.body = csg();
        ast_.stmts.push_back(s);
    }

    // definition -> IDENT '=' csg
    void definition() {
        Stmt s;
        s.kind = StmtKind::Definition;
        s.tok = s.nameTok = pos();
        p_ += 2;
        s.body = csg();
        ast_.stmts.push_back(s);
    }

    // module -> IDENT expr
    void moduleDecl() {
        Stmt s;
        s.kind = StmtKind::Module;
        s.tok = s.nameTok = pos();
        ++p_;
        if (at(Tok::Arrow))
            fail(p_,
                 "a rule needs a number (notation A: '1: S -> ...') or a label (notation B: "
                 "'p1: S -> ...')");
        s.expr = expr();
        if (isCsgOperator(tok().kind))
            fail(p_,
                 fmt::format("expected the end of the statement, found {}: this line declares "
                             "module {} (a name followed by its selection function); an axiom "
                             "that calls a notation-B module needs a label, as in 'w: {}(...)'",
                             describe(src_, tok()), clip(text(s.nameTok)), clip(text(s.nameTok))));
        ast_.stmts.push_back(s);
    }

    // axiomA -> csg
    void axiomA() {
        Stmt s;
        s.kind = StmtKind::AxiomA;
        s.tok = pos();
        s.body = csg();
        ast_.stmts.push_back(s);
    }

    // directive -> ('camera' | 'light' | 'settings') block | 'background' vector
    //            | 'material' IDENT block | 'sky_sphere' block
    void directive() {
        Stmt s;
        s.kind = StmtKind::Directive;
        s.tok = s.nameTok = pos();
        s.directive = tok().kw;
        ++p_;
        std::vector<DirectiveItem> items;
        if (s.directive == Kw::Background) {
            DirectiveItem item;
            item.nameTok = s.tok;
            if (!at(Tok::Lt))
                fail(p_, fmt::format("expected a colour '<r, g, b>' after 'background', found {}",
                                     describe(src_, tok())));
            vector(item);
            items.push_back(item);
        } else if (s.directive == Kw::Material || s.directive == Kw::SkySphere) {
            if (s.directive == Kw::Material) s.nameTok = name("a material");
            if (!at(Tok::LBrace))
                fail(p_, fmt::format("expected '{{', found {}", describe(src_, tok())));
            const Atom body = atom();
            s.first = body.first;
            s.count = body.count;
            s.last = body.end;
            ast_.stmts.push_back(s);
            return;
        } else {
            block(items);
        }
        s.first = static_cast<uint32_t>(ast_.items.size());
        s.count = static_cast<uint32_t>(items.size());
        ast_.items.insert(ast_.items.end(), items.begin(), items.end());
        ast_.stmts.push_back(s);
    }

    // block -> '{' { item | separator } '}'
    // item  -> IDENT [value { ',' value }]      value -> vector | expr
    // A name followed by '}', a separator or another name is a flag (`spotlight`).
    void block(std::vector<DirectiveItem>& items) {
        expect(Tok::LBrace, "'{'");
        for (;;) {
            while (isSeparator(tok().kind) && !(tok().flags & kForced)) ++p_;
            if (at(Tok::RBrace)) break;
            if (!at(Tok::Ident))
                fail(p_, fmt::format("expected a setting name or '}}', found {}",
                                     describe(src_, tok())));
            DirectiveItem item;
            item.nameTok = pos();
            ++p_;
            if (at(Tok::RBrace) || at(Tok::Ident) || isSeparator(tok().kind)) {
                item.flag = true;
                items.push_back(item);
                continue;
            }
            const size_t head = items.size();
            itemValue(item);
            items.push_back(item);
            // A comma before another value continues the item; before a name it separates.
            while (at(Tok::Comma) && startsValue(tok(1)) && items[head].more < 255) {
                ++p_;
                DirectiveItem next;
                next.nameTok = item.nameTok;
                itemValue(next);
                items.push_back(next);
                ++items[head].more;
            }
        }
        ++p_;
    }

    static bool startsValue(const Token& t) {
        return !(t.kind == Tok::Ident || t.kind == Tok::RBrace || t.kind == Tok::End ||
                 isSeparator(t.kind));
    }

    void itemValue(DirectiveItem& item) {
        if (at(Tok::Lt))
            vector(item);
        else
            item.e[0] = expr();
    }

    // A material's body, in POV-Ray's free syntax (ast.h's Atom):
    // atom -> WORD | sum | '<' sum { ',' sum } '>' | '{' { atom | sep } '}' | '[' { atom | sep }
    // ']'
    Atom atom() {
        Atom a;
        a.tok = a.end = pos();
        const Token& t = tok();
        if (at(Tok::LBrace) || at(Tok::LBracket)) {
            const Nest nest(*this);
            const bool brace = at(Tok::LBrace);
            a.kind = brace ? AtomKind::Block : AtomKind::Bracket;
            const Tok close = brace ? Tok::RBrace : Tok::RBracket;
            ++p_;
            std::vector<Atom> inner;
            for (;;) {
                while ((isSeparator(tok().kind) || at(Tok::Comma)) && !(tok().flags & kForced))
                    ++p_;
                if (at(close)) break;
                if (at(Tok::End) || at(Tok::RBrace) || at(Tok::RBracket) || (tok().flags & kForced))
                    fail(p_, fmt::format("expected {}, found {}", brace ? "'}'" : "']'",
                                         describe(src_, tok())));
                inner.push_back(atom());
            }
            a.end = pos();
            ++p_;
            a.first = static_cast<uint32_t>(ast_.atoms.size());
            a.count = static_cast<uint32_t>(inner.size());
            ast_.atoms.insert(ast_.atoms.end(), inner.begin(), inner.end());
        } else if (at(Tok::Lt)) {
            a.kind = AtomKind::Vector;
            ++p_;
            std::vector<uint32_t> parts{expr(kAdditive)};
            while (at(Tok::Comma)) {
                ++p_;
                parts.push_back(expr(kAdditive));
            }
            if (parts.size() > 5) fail(a.tok, "a vector has at most five components");
            expect(Tok::Gt,
                   "'>' closing the vector (a comparison inside a vector needs parentheses)");
            a.end = pos() - 1;
            a.first = static_cast<uint32_t>(ast_.lists.size());
            a.count = static_cast<uint32_t>(parts.size());
            ast_.lists.insert(ast_.lists.end(), parts.begin(), parts.end());
        } else if ((t.kind == Tok::Ident && tok(1).kind != Tok::LParen) ||
                   (t.kind == Tok::Keyword && !isFunction(t.kw) && !t.isKw(Kw::Pi) &&
                    !t.isKw(Kw::E) && !t.isKw(Kw::Clock) && !t.isKw(Kw::Frame))) {
            a.kind = AtomKind::Word;
            ++p_;
        } else {
            a.kind = AtomKind::Number;
            a.expr = expr(kAdditive);
            a.end = ast_.exprs[a.expr].to;
        }
        return a;
    }

    // vector -> '<' sum ',' sum ',' sum '>'     (sum: an expression without comparisons)
    void vector(DirectiveItem& item) {
        expect(Tok::Lt, "'<'");
        item.vector = true;
        for (int i = 0; i < 3; ++i) {
            if (i > 0) expect(Tok::Comma, "',' between the components of a vector '<x, y, z>'");
            item.e[i] = expr(kAdditive);
        }
        if (at(Tok::Comma)) fail(p_, "a vector has three components '<x, y, z>'");
        expect(Tok::Gt, "'>' closing the vector (a comparison inside a vector needs parentheses)");
    }

    // --- CSG expressions ---

    uint32_t addCsg(const CsgNode& n) {
        ast_.csg.push_back(n);
        return static_cast<uint32_t>(ast_.csg.size() - 1);
    }
    uint32_t addOperator(CsgOp op, uint32_t opTok, const std::vector<uint32_t>& operands) {
        CsgNode n;
        n.kind = CsgKind::Operator;
        n.csgOp = op;
        n.tok = opTok;
        n.first = static_cast<uint32_t>(ast_.lists.size());
        n.count = static_cast<uint32_t>(operands.size());
        ast_.lists.insert(ast_.lists.end(), operands.begin(), operands.end());
        return addCsg(n);
    }

    // csg -> term { UNION term }
    uint32_t csg() {
        const uint32_t first = term();
        if (!at(Tok::Union)) return first;
        const uint32_t opTok = pos();
        std::vector<uint32_t> operands{first};
        while (at(Tok::Union)) {
            ++p_;
            operands.push_back(term());
        }
        return addOperator(CsgOp::Union, opTok, operands);
    }

    // term -> unary { (INTERSECT | DIFFERENCE) unary }     (left-associative; a run of
    // one operator becomes one n-ary node)
    uint32_t term() {
        uint32_t left = unary();
        std::vector<uint32_t> operands;
        CsgOp kind = CsgOp::Union;  // Union: no run yet
        uint32_t opTok = 0;
        while (at(Tok::Intersect) || at(Tok::Difference)) {
            const CsgOp k = at(Tok::Intersect) ? CsgOp::Intersection : CsgOp::Difference;
            const uint32_t here = pos();
            ++p_;
            const uint32_t right = unary();
            if (kind == k) {
                operands.push_back(right);
                continue;
            }
            if (kind != CsgOp::Union) left = addOperator(kind, opTok, operands);
            operands = {left, right};
            kind = k;
            opTok = here;
        }
        if (kind != CsgOp::Union) left = addOperator(kind, opTok, operands);
        return left;
    }

    // unary -> transform unary | cnode unary | 'paint' '(' IDENT ')' unary | operand
    // transform -> (move | scale | ... | matrix) args | flipyz | flipxz | flipxy
    uint32_t unary() {
        Nest nest(*this);
        const Token& t = tok();
        if (t.kind == Tok::Keyword && isTransform(t.kw)) {
            CsgNode n;
            n.kind = CsgKind::Transform;
            n.op = transformOp(t.kw);
            n.tok = pos();
            ++p_;
            if (!isFlip(t.kw)) {
                if (!at(Tok::LParen))
                    fail(p_, fmt::format("expected '(' after '{}', found {}", text(n.tok),
                                         describe(src_, tok())));
                args(n.first, n.count);
            }
            n.child = unary();
            return addCsg(n);
        }
        if (t.kind == Tok::LBrace) {
            CsgNode n;
            n.kind = CsgKind::Calc;
            n.tok = pos();
            cnode(n.first, n.count);
            n.child = unary();
            return addCsg(n);
        }
        if (t.isKw(Kw::Paint)) {
            CsgNode n;
            n.kind = CsgKind::Paint;
            n.tok = pos();
            ++p_;
            expect(Tok::LParen, "'(' after 'paint'");
            n.nameTok = name("a material");
            expect(Tok::RParen, "')' after the material name");
            n.child = unary();
            return addCsg(n);
        }
        return operand();
    }

    // operand -> primitive [ args ] | IDENT args | IDENT | '(' csg ')'
    uint32_t operand() {
        const Token& t = tok();
        if (t.kind == Tok::Keyword && isPrimitive(t.kw)) {
            CsgNode n;
            n.kind = CsgKind::Primitive;
            n.prim = primitiveKind(t.kw);
            n.tok = pos();
            ++p_;
            if (at(Tok::LParen)) args(n.first, n.count);
            return addCsg(n);
        }
        if (t.kind == Tok::Ident) {
            CsgNode n;
            n.kind = CsgKind::Name;
            n.tok = n.nameTok = pos();
            ++p_;
            if (at(Tok::LParen)) {
                n.kind = CsgKind::Call;
                args(n.first, n.count);
            }
            return addCsg(n);
        }
        if (t.kind == Tok::LParen) {
            ++p_;
            const uint32_t inner = csg();
            expect(Tok::RParen, "')'");
            return inner;
        }
        if (t.kind == Tok::Keyword && !isFunction(t.kw) && t.kw != Kw::Paint)
            fail(p_, fmt::format("'{}' is a keyword and cannot name a module or definition",
                                 text(pos())));
        std::string hint;
        if (t.kind == Tok::Newline || t.kind == Tok::End || t.kind == Tok::Semicolon)
            hint =
                " (an operator at the end of a line continues the statement; a prefix needs its "
                "operand)";
        fail(p_,
             fmt::format("expected a primitive, a module or definition name, or '(', found {}{}",
                         describe(src_, t), hint));
    }

    // cnode -> '{' { separator } [ assignment { separator { separator } assignment } ]
    //          { separator } '}'          assignment -> IDENT '=' expr
    void cnode(uint32_t& first, uint32_t& count) {
        Nest nest(*this);
        const uint32_t open = pos();
        expect(Tok::LBrace, "'{'");
        std::vector<Assign> assigns;
        bool needSeparator = false;
        for (;;) {
            if (isSeparator(tok().kind) && !(tok().flags & kForced)) {
                ++p_;
                needSeparator = false;
                continue;
            }
            if (at(Tok::RBrace)) break;
            if (at(Tok::End) || (tok().flags & kForced)) fail(open, "this '{' is never closed");
            if (needSeparator)
                fail(p_,
                     fmt::format(
                         "expected ';', ',', a line break or '}}' after the assignment, found {}",
                         describe(src_, tok())));
            Assign a;
            a.nameTok = name("a parameter");
            if (at(Tok::Eq)) fail(p_, "expected '=' in the assignment ('==' compares)");
            expect(Tok::Assign, "'=' after the parameter name");
            a.value = expr();
            assigns.push_back(a);
            needSeparator = true;
        }
        ++p_;
        first = static_cast<uint32_t>(ast_.assigns.size());
        count = static_cast<uint32_t>(assigns.size());
        ast_.assigns.insert(ast_.assigns.end(), assigns.begin(), assigns.end());
    }

    // args -> '(' [ expr { ',' expr } ] ')'
    void args(uint32_t& first, uint32_t& count) {
        Nest nest(*this);
        expect(Tok::LParen, "'('");
        std::vector<uint32_t> list;
        if (!at(Tok::RParen)) {
            list.push_back(expr());
            while (at(Tok::Comma)) {
                ++p_;
                list.push_back(expr());
            }
        }
        if (!at(Tok::RParen))
            fail(p_, fmt::format("expected ',' or ')' in the argument list, found {}",
                                 describe(src_, tok())));
        ++p_;
        first = static_cast<uint32_t>(ast_.lists.size());
        count = static_cast<uint32_t>(list.size());
        ast_.lists.insert(ast_.lists.end(), list.begin(), list.end());
    }

    // --- arithmetic expressions ---

    uint32_t addExpr(const ExNode& e) {
        ast_.exprs.push_back(e);
        return static_cast<uint32_t>(ast_.exprs.size() - 1);
    }

    // expr -> unaryExpr { BINOP unaryExpr }, by precedence climbing over the table above;
    // a run of operators of one level becomes one Chain node.
    uint32_t expr(int minPrec = 1) {
        uint32_t left = unaryExpr();
        int level = 0;
        std::vector<ChainItem> items;
        for (;;) {
            if (at(Tok::Assign) && !assignIsEq_)
                fail(p_, "'=' assigns only inside a C-node '{...}'; to compare, write '=='");
            const int prec = binaryPrecedence(tok().kind, assignIsEq_);
            if (prec == 0 || prec < minPrec) break;
            ChainItem item;
            item.op = tok().kind == Tok::Assign ? Tok::Eq : tok().kind;
            item.tok = pos();
            ++p_;
            item.operand = expr(prec + 1);
            if (prec != level) {
                if (level != 0) left = chain(left, items);
                items.clear();
                level = prec;
            }
            items.push_back(item);
        }
        if (level != 0) left = chain(left, items);
        return left;
    }

    uint32_t chain(uint32_t left, const std::vector<ChainItem>& items) {
        ExNode n;
        n.kind = ExKind::Chain;
        n.tok = n.from = ast_.exprs[left].from;
        n.to = ast_.exprs[items.back().operand].to;
        n.a = left;
        n.first = static_cast<uint32_t>(ast_.chainItems.size());
        n.count = static_cast<uint32_t>(items.size());
        ast_.chainItems.insert(ast_.chainItems.end(), items.begin(), items.end());
        return addExpr(n);
    }

    // unaryExpr -> ('-' | '!' | '+') unaryExpr | power
    uint32_t unaryExpr() {
        Nest nest(*this);
        if (at(Tok::Minus) || at(Tok::Bang) || at(Tok::Plus)) {
            ExNode n;
            n.kind = ExKind::Unary;
            n.op = tok().kind;
            n.tok = n.from = pos();
            ++p_;
            n.a = unaryExpr();
            n.to = ast_.exprs[n.a].to;
            return addExpr(n);
        }
        return power();
    }

    // power -> primary [ '^' unaryExpr ]          (right-associative: 2^3^2 = 2^9)
    uint32_t power() {
        const uint32_t base = primary();
        if (!at(Tok::Caret)) return base;
        ++p_;
        ExNode n;
        n.kind = ExKind::Power;
        n.tok = n.from = ast_.exprs[base].from;
        n.a = base;
        n.b = unaryExpr();
        n.to = ast_.exprs[n.b].to;
        return addExpr(n);
    }

    // primary -> NUMBER | 'pi' | 'e' | 'clock' | 'frame' | IDENT | (FUNCTION | IDENT) args | '('
    // expr ')'
    uint32_t primary() {
        const Token& t = tok();
        ExNode n;
        n.tok = n.from = n.to = pos();
        if (t.kind == Tok::Number) {
            n.kind = ExKind::Number;
            n.value = number(pos());
            ++p_;
            return addExpr(n);
        }
        if (t.isKw(Kw::Pi) || t.isKw(Kw::E)) {
            n.kind = ExKind::Number;
            n.value = t.kw == Kw::Pi ? std::numbers::pi : std::numbers::e;
            ++p_;
            return addExpr(n);
        }
        if (t.isKw(Kw::Clock) || t.isKw(Kw::Frame)) {
            n.kind = ExKind::Time;
            ++p_;
            return addExpr(n);
        }
        if ((t.kind == Tok::Keyword && isFunction(t.kw)) ||
            (t.kind == Tok::Ident && tok(1).kind == Tok::LParen)) {
            n.kind = ExKind::Call;
            ++p_;
            if (!at(Tok::LParen))
                fail(p_, fmt::format("expected '(' after '{}', found {}", text(n.tok),
                                     describe(src_, tok())));
            const bool saved = assignIsEq_;
            args(n.first, n.count);
            assignIsEq_ = saved;
            n.to = pos() - 1;
            return addExpr(n);
        }
        if (t.kind == Tok::Ident) {
            n.kind = ExKind::Name;
            ++p_;
            return addExpr(n);
        }
        if (t.kind == Tok::LParen) {
            ++p_;
            const uint32_t inner = expr();
            expect(Tok::RParen, "')'");
            // The node's source text includes its parentheses.
            ast_.exprs[inner].from = n.tok;
            ast_.exprs[inner].to = pos() - 1;
            return inner;
        }
        if (t.kind == Tok::Keyword)
            fail(p_, fmt::format("'{}' cannot be used in an arithmetic expression", text(pos())));
        fail(p_, fmt::format("expected an expression, found {}", describe(src_, t)));
    }

    double number(uint32_t i) {
        const std::string_view s = text(i);
        double v = 0;
        const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        if (r.ec == std::errc::result_out_of_range) {
            // Underflow reads as zero; overflow is an error.
            if (s.find("e-") != std::string_view::npos || s.find("E-") != std::string_view::npos)
                return 0;
            fail(i, fmt::format("number '{}' is too large", s.substr(0, 40)));
        }
        return v;
    }

    const Source& src_;
    const std::vector<Token>& t_;
    Diagnostics& diags_;
    Ast ast_;
    size_t p_ = 0;
    uint32_t depth_ = 0;
    bool assignIsEq_ = false;
};

}  // namespace

Ast parse(const Source& src, const TokenStream& tokens, Diagnostics& diags) {
    return Parser(src, tokens, diags).file();
}

}  // namespace pcsg
