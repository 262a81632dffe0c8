// pcsg fmt: the canonical layout of a scene. See formatter.h.
#include "formatter.h"

#include <fmt/format.h>

#include <algorithm>
#include <initializer_list>
#include <map>
#include <optional>
#include <vector>

#include "ast.h"
#include "compiler.h"
#include "lexer.h"
#include "parser.h"

namespace pcsg {

namespace {

constexpr char kBreak = '\x01';      // where a long statement may break: after an operator
constexpr char kBreakCalc = '\x04';  // after a C-node's `;`: only when its operand is too long

// The precedence level of a binary operator: the parser's (`=` of a notation-B condition
// is stored as Eq).
int level(Tok k) {
    return binaryPrecedence(k, true);
}
constexpr int kAtom = 99;
const int kAdditive = binaryPrecedence(Tok::Plus, false);

// Concatenation without `"literal" + std::string` (GCC 12 warns -Wrestrict on it).
std::string cat(std::initializer_list<std::string_view> parts) {
    std::string s;
    size_t n = 0;
    for (std::string_view p : parts) n += p.size();
    s.reserve(n);
    for (std::string_view p : parts) s.append(p);
    return s;
}

std::string paren(std::string_view s) {
    return cat({"(", s, ")"});
}

std::string_view rtrim(std::string_view s) {
    while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
    return s;
}

// Display width: UTF-8 code points.
size_t width(std::string_view s) {
    size_t w = 0;
    for (unsigned char c : s) w += (c & 0xC0) != 0x80;
    return w;
}

struct Span {
    uint32_t begin = 0, end = 0;
};

// The comments inside braces, by the token index of the `{`: such a C-node or directive
// is printed over several lines, one item a line, so that its comments stay with them.
using BraceComments = std::map<uint32_t, std::vector<Span>>;

// An assignment of a C-node or an item of a directive: its text and its source span.
struct Item {
    Span span;
    std::string text;
};

// The macro uses of a file as the printer sees them (lexer.h's MacroOrigins): the tokens
// each use expanded into, so that a construct made of exactly one use's tokens is printed
// as the macro's name. Every use must be printed so, once; what is left over is a use
// whose expansion is not a whole construct, which pcsg fmt cannot keep (unclaimed()).
class MacroUses {
  public:
    MacroUses(const Source& src, const std::vector<Token>& t, const MacroOrigins& o)
        : src_(src),
          t_(t),
          o_(o),
          first_(o.uses.size(), kNone),
          last_(o.uses.size(), kNone),
          claimed_(o.uses.size(), false) {
        for (uint32_t i = 0; i < o.useOf.size() && i < t.size(); ++i) {
            const uint32_t u = o.useOf[i];
            if (u == kNone) continue;
            if (first_[u] == kNone) first_[u] = i;
            last_[u] = i;
        }
    }

    // The use whose expansion is exactly the tokens [from, to], or that with the
    // parentheses around them, claimed: its name. Else nullopt.
    std::optional<std::string> whole(uint32_t from, uint32_t to) const {
        if (std::optional<uint32_t> u = exactly(from, to)) return claim(*u);
        if (from == 0 || to + 1 >= t_.size() || t_[from - 1].kind != Tok::LParen ||
            t_[to + 1].kind != Tok::RParen)
            return std::nullopt;
        if (std::optional<uint32_t> u = exactly(from - 1, to + 1)) return claim(*u);
        return std::nullopt;
    }
    // Whether the tokens [from, to] are exactly one use's (not claimed).
    bool covers(uint32_t from, uint32_t to) const { return exactly(from, to).has_value(); }
    // Where a token begins and ends in the file (a token of a use: where the use does).
    uint32_t begin(uint32_t tok) const {
        const uint32_t u = useOf(tok);
        return u == kNone ? t_[tok].offset : o_.uses[u].begin;
    }
    uint32_t end(uint32_t tok) const {
        const uint32_t u = useOf(tok);
        return u == kNone ? t_[tok].offset + t_[tok].length : o_.uses[u].end;
    }
    // A use not printed as its name (or that expands to nothing), if any.
    std::optional<uint32_t> unclaimed() const {
        for (uint32_t u = 0; u < claimed_.size(); ++u)
            if (!claimed_[u]) return u;
        return std::nullopt;
    }
    std::string name(uint32_t u) const {
        const MacroOrigins::Range r = o_.uses[u];
        return std::string(src_.text().substr(r.begin, r.end - r.begin));
    }
    uint32_t offset(uint32_t u) const { return o_.uses[u].begin; }

  private:
    static constexpr uint32_t kNone = MacroOrigins::kNone;
    uint32_t useOf(uint32_t tok) const { return tok < o_.useOf.size() ? o_.useOf[tok] : kNone; }
    // The use whose expansion is the tokens [from, to], if any.
    std::optional<uint32_t> exactly(uint32_t from, uint32_t to) const {
        const uint32_t u = useOf(from);
        if (u == kNone || first_[u] != from || last_[u] != to) return std::nullopt;
        return u;
    }
    std::string claim(uint32_t u) const {
        claimed_[u] = true;
        return name(u);
    }

    const Source& src_;
    const std::vector<Token>& t_;
    const MacroOrigins& o_;
    std::vector<uint32_t> first_, last_;  // per use: its first and last token
    mutable std::vector<bool> claimed_;
};

constexpr char kIndentMore = '\x02';  // a new line, indented one step more than the `{`'s
constexpr char kIndentSame = '\x03';  // a new line, indented as the `{`'s

class Printer {
  public:
    Printer(const Source& src, const std::vector<Token>& tokens, const Ast& ast,
            const BraceComments& braceComments, const MacroUses& uses)
        : src_(src),
          t_(tokens),
          ast_(ast),
          braceComments_(braceComments),
          uses_(uses),
          match_(matchParens(tokens)) {}

    // One statement, possibly over several lines, without a final newline.
    std::string statement(const Stmt& s) const {
        if (s.kind == StmtKind::Directive) return directive(s);
        return fill(flatStatement(s));
    }

  private:
    std::string text(uint32_t tok) const {
        if (std::optional<std::string> use = uses_.whole(tok, tok)) return *use;
        return std::string(spelling(src_, t_[tok]));
    }

    // --- arithmetic ---

    int exprLevel(uint32_t e) const {
        const ExNode& n = ast_.exprs[e];
        if (parenthesizedUse(n.from, n.to)) return kAtom;  // (`#define SUM (1+2)`: SUM * 4)
        return n.kind == ExKind::Chain ? level(ast_.chainItems[n.first].op) : kAtom;
    }
    // Whether the tokens [from, to] are one macro use's whole body, in parentheses of its
    // own: the use needs no more around it.
    bool parenthesizedUse(uint32_t from, uint32_t to) const {
        return t_[from].kind == Tok::LParen && match_[from] == to && uses_.covers(from, to);
    }
    bool parenthesizedUse(uint32_t c) const {
        const auto [from, to] = wrapped(c);
        return parenthesizedUse(from, to);
    }

    std::string list(uint32_t first, uint32_t count) const {
        std::string s;
        for (uint32_t k = 0; k < count; ++k) {
            if (k > 0) s += ", ";
            s += expr(ast_.lists[first + k]);
        }
        return s;
    }

    std::string expr(uint32_t e) const {
        const ExNode& n = ast_.exprs[e];
        if (std::optional<std::string> use = uses_.whole(n.from, n.to)) return *use;
        // (in parentheses the printer puts back where they are needed)
        if (t_[n.from].kind == Tok::LParen && n.to > n.from + 1)
            if (std::optional<std::string> use = uses_.whole(n.from + 1, n.to - 1)) return *use;
        switch (n.kind) {
            case ExKind::Number:
            case ExKind::Name:
            case ExKind::Time:
                return text(n.tok);
            case ExKind::Call:
                return text(n.tok) + "(" + list(n.first, n.count) + ")";
            case ExKind::Unary: {
                const ExKind k = ast_.exprs[n.a].kind;
                const std::string a = expr(n.a);
                return text(n.tok) + (k == ExKind::Chain || k == ExKind::Unary ? paren(a) : a);
            }
            case ExKind::Power: {
                const ExKind k = ast_.exprs[n.a].kind;
                const bool primary = k != ExKind::Chain && k != ExKind::Unary && k != ExKind::Power;
                const std::string b = expr(n.b);
                return (primary ? expr(n.a) : paren(expr(n.a))) + "^" +
                       (ast_.exprs[n.b].kind == ExKind::Chain ? paren(b) : b);
            }
            case ExKind::Chain:
                break;
        }
        // A chain keeps its grouping: an operand of its own level or looser was in
        // parentheses (the left one too, or it would join this chain).
        const int own = exprLevel(e);
        std::string s = exprLevel(n.a) <= own ? paren(expr(n.a)) : expr(n.a);
        for (uint32_t k = 0; k < n.count; ++k) {
            const ChainItem& item = ast_.chainItems[n.first + k];
            const std::string x = expr(item.operand);
            s += cat({" ", text(item.tok), " ", exprLevel(item.operand) <= own ? paren(x) : x});
        }
        return s;
    }

    // --- CSG ---

    std::string operatorCsg(const CsgNode& n) const {
        const char* sep = n.csgOp == CsgOp::Union          ? " ∪ \x01"
                          : n.csgOp == CsgOp::Intersection ? " ∩ \x01"
                                                           : " \\ \x01";
        std::string s;
        for (uint32_t k = 0; k < n.count; ++k) {
            const uint32_t c = ast_.lists[n.first + k];
            const CsgNode& o = ast_.csg[c];
            bool wrap = false;
            if (o.kind == CsgKind::Operator) {
                if (n.csgOp == CsgOp::Union)
                    wrap = o.csgOp == CsgOp::Union;
                else
                    wrap = k > 0 || o.csgOp == CsgOp::Union || o.csgOp == n.csgOp;
            }
            if (k > 0) s += sep;
            s += wrap && !parenthesizedUse(c) ? paren(csg(c)) : csg(c);
        }
        return s;
    }

    // The operand of a prefix: an operator needs its parentheses back.
    std::string child(uint32_t c) const {
        const std::string s = csg(c);
        return ast_.csg[c].kind == CsgKind::Operator && !parenthesizedUse(c) ? paren(s) : s;
    }

    std::string comment(Span c) const {
        return std::string(src_.text().substr(c.begin, c.end - c.begin));
    }

    uint32_t endOf(uint32_t tok) const { return uses_.end(tok); }
    uint32_t beginOf(uint32_t tok) const { return uses_.begin(tok); }

    // A CSG term's first and last token: parentheses around it not included, those
    // around its parts included.
    uint32_t firstTok(uint32_t c) const {
        const CsgNode& n = ast_.csg[c];
        if (n.kind == CsgKind::Operator) return wrapped(ast_.lists[n.first]).first;
        return n.kind == CsgKind::Name || n.kind == CsgKind::Call ? n.nameTok : n.tok;
    }
    uint32_t lastTok(uint32_t c) const {
        const CsgNode& n = ast_.csg[c];
        switch (n.kind) {
            case CsgKind::Operator:
                return wrapped(ast_.lists[n.first + n.count - 1]).second;
            case CsgKind::Transform:
            case CsgKind::Calc:
            case CsgKind::Paint:
                return wrapped(n.child).second;
            case CsgKind::Name:
                return n.nameTok;
            case CsgKind::Primitive:
            case CsgKind::Call: {
                const uint32_t head = n.kind == CsgKind::Call ? n.nameTok : n.tok;
                if (head + 1 >= t_.size() || t_[head + 1].kind != Tok::LParen) return head;
                return match_[head + 1];
            }
        }
        return n.tok;
    }
    // A term's tokens with the parentheses around it.
    std::pair<uint32_t, uint32_t> wrapped(uint32_t c) const {
        uint32_t a = firstTok(c), b = lastTok(c);
        while (a > 0 && t_[a - 1].kind == Tok::LParen && match_[a - 1] == b + 1) --a, ++b;
        return {a, b};
    }
    // The matching parenthesis of each '(' and ')' (else kNoNode).
    static std::vector<uint32_t> matchParens(const std::vector<Token>& t) {
        std::vector<uint32_t> match(t.size(), kNoNode), open;
        for (uint32_t i = 0; i < t.size(); ++i) {
            if (t[i].kind == Tok::LParen) open.push_back(i);
            if (t[i].kind != Tok::RParen || open.empty()) continue;
            match[i] = open.back();
            match[open.back()] = i;
            open.pop_back();
        }
        return match;
    }

    // The lines of a braced list with comments: each item on a line of its own, a comment
    // after an item on its line, other comments on lines of their own before the next
    // item or the `}`.
    std::vector<std::string> itemLines(const std::vector<Item>& items,
                                       const std::vector<Span>& cs) const {
        const std::string_view text = src_.text();
        std::vector<std::string> lines;
        size_t ci = 0;
        for (const Item& item : items) {
            for (; ci < cs.size() && cs[ci].begin < item.span.begin; ++ci)
                lines.push_back(comment(cs[ci]));
            std::string line = item.text;
            const uint32_t end = item.span.end;
            for (; ci < cs.size() && cs[ci].begin >= end &&
                   text.substr(end, cs[ci].begin - end).find('\n') == std::string_view::npos;
                 ++ci)
                line += cat({" ", comment(cs[ci])});
            lines.push_back(std::move(line));
        }
        for (; ci < cs.size(); ++ci) lines.push_back(comment(cs[ci]));
        return lines;
    }

    // A C-node with comments: one assignment a line (see itemLines).
    std::string calcLines(const CsgNode& n, const std::vector<Span>& cs) const {
        std::vector<Item> items;
        for (uint32_t k = 0; k < n.count; ++k) {
            const Assign& a = ast_.assigns[n.first + k];
            items.push_back({{beginOf(a.nameTok), endOf(ast_.exprs[a.value].to)},
                             cat({text(a.nameTok), " = ", expr(a.value)})});
        }
        std::string s = "{";
        for (const std::string& line : itemLines(items, cs))
            s += cat({std::string_view(&kIndentMore, 1), line});
        return cat({s, std::string_view(&kIndentSame, 1), "} ", child(n.child)});
    }

    std::string calc(uint32_t c) const {
        const CsgNode& n = ast_.csg[c];
        // A macro whose body is the C-node's block (the paper's figure 8)
        uint32_t close = wrapped(n.child).first - 1;
        while (close > n.tok && t_[close].kind == Tok::Newline) --close;
        if (std::optional<std::string> use = uses_.whole(n.tok, close))
            return cat({*use, " ", child(n.child)});
        if (auto it = braceComments_.find(n.tok); it != braceComments_.end())
            return calcLines(n, it->second);
        std::string s = "{";
        for (uint32_t k = 0; k < n.count; ++k) {
            const Assign& a = ast_.assigns[n.first + k];
            if (k > 0) s += "; \x04";  // a long C-node may break here too
            s += text(a.nameTok) + " = " + expr(a.value);
        }
        return s + "} " + child(n.child);
    }

    std::string csg(uint32_t c) const {
        const CsgNode& n = ast_.csg[c];
        if (std::optional<std::string> use = uses_.whole(firstTok(c), lastTok(c))) return *use;
        switch (n.kind) {
            case CsgKind::Operator:
                return operatorCsg(n);
            case CsgKind::Transform: {
                const bool flip = n.op == TransformOp::FlipYZ || n.op == TransformOp::FlipXZ ||
                                  n.op == TransformOp::FlipXY;
                return cat(
                    {text(n.tok), flip ? "" : paren(list(n.first, n.count)), " ", child(n.child)});
            }
            case CsgKind::Calc:
                return calc(c);
            case CsgKind::Paint:
                return cat({"paint(", text(n.nameTok), ") ", child(n.child)});
            case CsgKind::Primitive: {
                const bool args = n.tok + 1 < t_.size() && t_[n.tok + 1].kind == Tok::LParen;
                return cat({text(n.tok), args ? paren(list(n.first, n.count)) : ""});
            }
            case CsgKind::Name:
                return text(n.nameTok);
            case CsgKind::Call:
                return text(n.nameTok) + "(" + list(n.first, n.count) + ")";
        }
        return {};
    }

    // --- statements ---

    std::string flatStatement(const Stmt& s) const {
        switch (s.kind) {
            case StmtKind::RuleA:
                return text(s.labelTok) + ": " + text(s.nameTok) + " -> " + csg(s.body);
            case StmtKind::RuleB: {
                std::string h = text(s.labelTok) + ": " + text(s.nameTok);
                if (s.hasFormals) {
                    h += "(";
                    for (uint32_t k = 0; k < s.count; ++k)
                        h += cat({k > 0 ? ", " : "", text(ast_.lists[s.first + k])});
                    h += ")";
                }
                if (s.expr != kNoNode) h += cat({" : ", expr(s.expr)});
                return h + " -> " + csg(s.body);
            }
            case StmtKind::AxiomB:
                return text(s.labelTok) + ": " + csg(s.body);
            case StmtKind::Definition:
                return text(s.nameTok) + " = " + csg(s.body);
            case StmtKind::Module:
                return text(s.nameTok) + " " + expr(s.expr);
            default:
                return csg(s.body);
        }
    }

    // Appends a chunk to the current line; a C-node's line marks start new lines,
    // indented from the line its `{` is on.
    static void append(std::string& out, std::string& line, std::string_view chunk) {
        size_t base = std::string::npos;
        for (char ch : chunk) {
            if (ch != kIndentMore && ch != kIndentSame) {
                line += ch;
                continue;
            }
            if (base == std::string::npos) base = line.find_first_not_of(' ');
            if (base == std::string::npos) base = 0;
            out.append(rtrim(line)).append("\n");
            line.assign(base + (ch == kIndentMore ? kFormatIndent : 0), ' ');
        }
    }

    // Whether `line` followed by the chunks [k, m) (up to a C-node's first line break)
    // fits in the width; stops reading once it does not.
    static bool fits(const std::string& line, const std::vector<std::string_view>& chunks, size_t k,
                     size_t m) {
        std::string s = line;
        for (size_t i = k; i < m; ++i) {
            const size_t special = chunks[i].find_first_of("\x02\x03");
            s += chunks[i].substr(0, special);
            if (special != std::string_view::npos || width(rtrim(s)) > kFormatWidth) break;
        }
        return width(rtrim(s)) <= kFormatWidth;
    }

    // Breaks a flat statement at its break marks, filling each line up to the width: an
    // operator's operand goes on the next line when it does not fit on this one, and a
    // C-node's `;` breaks only inside an operand too long for a line.
    static std::string fill(const std::string& flat) {
        std::vector<std::string_view> chunks;
        std::vector<bool> calc;  // chunk k follows a C-node's break
        size_t start = 0;
        for (size_t i = 0; i <= flat.size(); ++i) {
            if (i == flat.size() || flat[i] == kBreak || flat[i] == kBreakCalc) {
                chunks.push_back(std::string_view(flat).substr(start, i - start));
                calc.push_back(start > 0 && flat[start - 1] == kBreakCalc);
                start = i + 1;
            }
        }
        std::string out, line;
        append(out, line, chunks[0]);
        for (size_t k = 1; k < chunks.size(); ++k) {
            size_t m = k + 1;  // the end of this operand
            while (m < chunks.size() && calc[m]) ++m;
            const bool fitting = calc[k] ? fits(line, chunks, k, k + 1) : fits(line, chunks, k, m);
            // Break only a line that holds something; at a C-node's `;`, a short head
            // stays with the rest, which would not fit on a line of its own either.
            const size_t least = calc[k] ? kFormatWidth / 2 : kFormatIndent + 1;
            if (!fitting && width(rtrim(line)) >= least) {
                out.append(rtrim(line)).append("\n");
                line.assign(kFormatIndent, ' ');
            }
            append(out, line, chunks[k]);
        }
        return out + line;
    }

    std::string vector(const DirectiveItem& item) const {
        std::string s = "<";
        for (int k = 0; k < 3; ++k) {
            if (k > 0) s += ", ";
            const std::string x = expr(item.e[k]);
            s += exprLevel(item.e[k]) < kAdditive ? paren(x) : x;
        }
        return s + ">";
    }

    std::string value(const DirectiveItem& item) const {
        return item.vector ? vector(item) : expr(item.e[0]);
    }
    // A vector ends at its '>', the token after its last component.
    uint32_t lastToken(const DirectiveItem& item) const {
        return item.vector ? ast_.exprs[item.e[2]].to + 1 : ast_.exprs[item.e[0]].to;
    }

    // `camera { location <4, -6, 3>  look_at <0, 0, 0.5> }` on one line when it fits,
    // else one item per line.
    std::string directive(const Stmt& s) const {
        std::string head = text(s.tok);
        if (s.directive == Kw::Background) return head + " " + vector(ast_.items[s.first]);
        std::vector<Item> list;
        const bool atoms = s.directive == Kw::Material || s.directive == Kw::SkySphere;
        if (s.directive == Kw::Material) head += cat({" ", text(s.nameTok)});
        if (atoms) list = materialItems(s);
        for (uint32_t k = 0; !atoms && k < s.count; ++k) {
            const DirectiveItem& item = ast_.items[s.first + k];
            if (item.flag) {
                list.push_back({{beginOf(item.nameTok), endOf(item.nameTok)},
                                std::string(text(item.nameTok))});
                continue;
            }
            // An item's values: this one and those after commas.
            std::string line = cat({text(item.nameTok), " ", value(item)});
            const DirectiveItem* last = &item;
            for (uint32_t m = 0; m < item.more && k + 1 < s.count; ++m) {
                last = &ast_.items[s.first + ++k];
                line += cat({", ", value(*last)});
            }
            list.push_back({{beginOf(item.nameTok), endOf(lastToken(*last))}, line});
        }
        uint32_t open = s.tok;
        while (t_[open].kind != Tok::LBrace) ++open;
        if (auto it = braceComments_.find(open); it != braceComments_.end())
            return lines(head, itemLines(list, it->second));
        std::vector<std::string> items;
        for (Item& item : list) items.push_back(std::move(item.text));
        if (items.empty()) return head + " {}";
        std::string one = head + " {";
        for (size_t k = 0; k < items.size(); ++k) one += cat({k > 0 ? "  " : " ", items[k]});
        one += " }";
        if (width(one) <= kFormatWidth) return one;
        return lines(head, items);
    }

    // A material's body: each word with the values and blocks that follow it is an item.
    std::vector<Item> materialItems(const Stmt& s) const {
        std::vector<Item> list;
        for (uint32_t k = s.first; k < s.first + s.count;) {
            const uint32_t from = k++;
            while (k < s.first + s.count && ast_.atoms[k].kind != AtomKind::Word) ++k;
            const Atom &a = ast_.atoms[from], &b = ast_.atoms[k - 1];
            list.push_back({{beginOf(a.tok), endOf(b.end)}, atoms(from, k)});
        }
        return list;
    }

    // Atoms [from, to) on one line; consecutive numbers keep a comma between them.
    std::string atoms(uint32_t from, uint32_t to) const {
        std::string s;
        for (uint32_t k = from; k < to; ++k) {
            if (k > from)
                s += ast_.atoms[k].kind == AtomKind::Number &&
                             ast_.atoms[k - 1].kind == AtomKind::Number
                         ? ", "
                         : " ";
            s += atom(ast_.atoms[k]);
        }
        return s;
    }

    std::string atom(const Atom& a) const {
        switch (a.kind) {
            case AtomKind::Word:
                return std::string(text(a.tok));
            case AtomKind::Number:
                return expr(a.expr);
            case AtomKind::Vector: {
                std::string s = "<";
                for (uint32_t k = 0; k < a.count; ++k) {
                    const uint32_t e = ast_.lists[a.first + k];
                    s += cat(
                        {k > 0 ? ", " : "", exprLevel(e) < kAdditive ? paren(expr(e)) : expr(e)});
                }
                return s + ">";
            }
            case AtomKind::Block:
            case AtomKind::Bracket: {
                const bool brace = a.kind == AtomKind::Block;
                if (a.count == 0) return brace ? "{}" : "[]";
                const std::string inner = atoms(a.first, a.first + a.count);
                return brace ? cat({"{ ", inner, " }"}) : cat({"[", inner, "]"});
            }
        }
        return {};
    }

    static std::string lines(const std::string& head, const std::vector<std::string>& items) {
        std::string many = head + " {\n";
        for (const std::string& item : items) many += std::string(kFormatIndent, ' ') + item + "\n";
        return many + "}";
    }

    const Source& src_;
    const std::vector<Token>& t_;
    const Ast& ast_;
    const BraceComments& braceComments_;
    const MacroUses& uses_;
    const std::vector<uint32_t> match_;
};

// The comments of a text, in order.
std::vector<Span> scanComments(std::string_view s) {
    std::vector<Span> comments;
    size_t i = s.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
    while (i < s.size()) {
        if (s[i] == '/' && i + 1 < s.size() && (s[i + 1] == '/' || s[i + 1] == '*')) {
            const bool line = s[i + 1] == '/';
            size_t end = line ? s.find('\n', i) : s.find("*/", i + 2);
            end = end == std::string_view::npos ? s.size() : end + (line ? 0 : 2);
            comments.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(end)});
            i = end;
            continue;
        }
        ++i;
    }
    return comments;
}

// Whether no comment holds one of the control characters that mark the printer's breaks
// and indents (kBreak ... kBreakCalc); reports the first that does.
bool plainComments(const Source& src, const std::vector<Span>& comments, Diagnostics& diags) {
    for (const Span& c : comments) {
        const std::string_view body = src.text().substr(c.begin, c.end - c.begin);
        const size_t at = body.find_first_of("\x01\x02\x03\x04");
        if (at == std::string_view::npos) continue;
        diags.error(src.loc(c.begin + static_cast<uint32_t>(at)),
                    fmt::format("pcsg fmt cannot format a comment with the control character "
                                "0x{:02x}",
                                static_cast<int>(body[at])));
        return false;
    }
    return true;
}

// The comments inside #defines, which are printed as written, marked.
std::vector<bool> insideDefines(const std::vector<Span>& comments, const MacroOrigins& origins) {
    std::vector<bool> inside(comments.size(), false);
    for (const MacroOrigins::Range& d : origins.defines)
        for (size_t k = 0; k < comments.size(); ++k)
            if (comments[k].begin >= d.begin && comments[k].begin < d.end) inside[k] = true;
    return inside;
}

// The comments inside braces (C-nodes and directives); `used` marks them.
BraceComments braceComments(const std::vector<Token>& t, const MacroOrigins& origins,
                            const std::vector<Span>& comments, std::vector<bool>& used) {
    BraceComments result;
    if (comments.empty()) return result;
    for (uint32_t i = 0; i < t.size(); ++i) {
        if (t[i].kind != Tok::LBrace) continue;
        if (i < origins.useOf.size() && origins.useOf[i] != MacroOrigins::kNone) continue;
        size_t j = i + 1;
        for (int depth = 1; depth > 0 && t[j].kind != Tok::End; ++j)
            depth += t[j].kind == Tok::LBrace ? 1 : t[j].kind == Tok::RBrace ? -1 : 0;
        const uint32_t open = t[i].offset, close = t[j - 1].offset;
        auto it = std::lower_bound(comments.begin(), comments.end(), open,
                                   [](const Span& s, uint32_t at) { return s.begin < at; });
        for (; it != comments.end() && it->begin < close; ++it) {
            if (used[static_cast<size_t>(it - comments.begin())]) continue;
            result[i].push_back(*it);
            used[static_cast<size_t>(it - comments.begin())] = true;
        }
    }
    return result;
}

// Each statement's text: its first token to its last.
std::vector<Span> statementSpans(const Ast& ast, const std::vector<Token>& t,
                                 const MacroUses& uses) {
    std::vector<Span> spans;
    for (const Stmt& s : ast.stmts) {
        size_t j = s.tok;
        while (t[j].kind != Tok::End &&
               !((t[j].kind == Tok::Newline || t[j].kind == Tok::Semicolon) &&
                 (t[j].flags & kTopLevel)))
            ++j;
        spans.push_back({uses.begin(s.tok), uses.end(static_cast<uint32_t>(j - 1))});
    }
    return spans;
}

// Where each comment goes: inside statement k (moved before it), after statement k on
// its last line, or on lines of its own (before the next statement).
struct Placement {
    std::vector<std::vector<Span>> inner, trailing;
    std::vector<Span> standalone;
};

Placement placeComments(std::string_view text, const std::vector<Span>& stmts,
                        const std::vector<Span>& comments) {
    Placement p;
    p.inner.resize(stmts.size());
    p.trailing.resize(stmts.size());
    size_t si = 0;
    for (const Span& c : comments) {
        while (si < stmts.size() && stmts[si].end <= c.begin) ++si;
        if (si < stmts.size() && stmts[si].begin <= c.begin) {
            p.inner[si].push_back(c);
        } else if (si > 0 &&
                   text.substr(stmts[si - 1].end, c.begin - stmts[si - 1].end).find('\n') ==
                       std::string_view::npos) {
            p.trailing[si - 1].push_back(c);
        } else {
            p.standalone.push_back(c);
        }
    }
    return p;
}

class Emitter {
  public:
    explicit Emitter(std::string_view text) : text_(text) {}

    // Starts an item at `begin`: one blank line if the text had any since the last item.
    void start(uint32_t begin) {
        const auto gap = text_.substr(last_, begin > last_ ? begin - last_ : 0);
        if (!out_.empty() && std::count(gap.begin(), gap.end(), '\n') >= 2) out_ += "\n";
    }
    void comment(Span c) {
        start(c.begin);
        line(c);
        last_ = c.end;
    }
    void line(Span c) { out_ += std::string(text_.substr(c.begin, c.end - c.begin)) + "\n"; }
    void statement(Span s, const std::string& body, const std::vector<Span>& inner,
                   const std::vector<Span>& trailing) {
        start(s.begin);
        for (const Span& c : inner) line(c);
        out_ += body;
        last_ = s.end;
        for (const Span& c : trailing) {
            out_ += cat({" ", text_.substr(c.begin, c.end - c.begin)});
            last_ = c.end;
        }
        out_ += "\n";
    }
    std::string take() { return std::move(out_); }

  private:
    std::string_view text_;
    std::string out_;
    uint32_t last_ = 0;
};

// What the file is printed as: each statement and each #define, with its text, in the
// file's order.
struct Piece {
    Span span;
    std::string text;
    bool define = false;
};

// A #define as written, without the spaces at the ends of its lines.
std::string defineText(std::string_view text, Span d) {
    std::string out;
    std::string_view rest = text.substr(d.begin, d.end - d.begin);
    for (;;) {
        const size_t nl = rest.find('\n');
        out += rtrim(rest.substr(0, nl));
        if (nl == std::string_view::npos) return out;
        out += '\n';
        rest.remove_prefix(nl + 1);
    }
}

// Why the file cannot be formatted with its macros kept, if it cannot: a #define inside a
// statement, or a use of a macro that is not a whole construct (MacroUses).
bool macrosKept(const Source& src, const std::vector<Piece>& pieces, const MacroUses& uses,
                Diagnostics& diags) {
    for (size_t k = 1; k < pieces.size(); ++k) {
        const Piece &a = pieces[k - 1], &b = pieces[k];
        if (b.span.begin >= a.span.end) continue;
        diags.error(src.loc((b.define ? b : a).span.begin),
                    "pcsg fmt cannot format a #define inside a statement");
        return false;
    }
    if (const std::optional<uint32_t> u = uses.unclaimed()) {
        diags.error(src.loc(uses.offset(*u)),
                    fmt::format("pcsg fmt cannot keep this use of macro '{}': its body is not a "
                                "whole C-node block, expression or CSG term here",
                                uses.name(*u)));
        return false;
    }
    return true;
}

}  // namespace

std::optional<std::string> formatScene(std::string_view fileName, std::string_view text,
                                       Diagnostics& diags) {
    if (!compileSource(fileName, text, diags)) return std::nullopt;
    const uint32_t file = static_cast<uint32_t>(diags.fileNames().size() - 1);
    const Source src(text, file);
    const std::vector<Span> comments = scanComments(text);
    if (!plainComments(src, comments, diags)) return std::nullopt;
    Diagnostics quiet;  // the file compiled: lexing and parsing it again report nothing
    MacroOrigins origins;
    const TokenStream tokens = lex(src, quiet, &origins);
    const Ast ast = parse(src, tokens, quiet);
    const MacroUses uses(src, tokens.tokens, origins);
    std::vector<bool> used = insideDefines(comments, origins);
    const BraceComments inBraces = braceComments(tokens.tokens, origins, comments, used);
    std::vector<Span> others;
    for (size_t k = 0; k < comments.size(); ++k)
        if (!used[k]) others.push_back(comments[k]);
    const Printer printer(src, tokens.tokens, ast, inBraces, uses);
    const std::vector<Span> spans = statementSpans(ast, tokens.tokens, uses);
    std::vector<Piece> pieces;
    for (size_t k = 0; k < ast.stmts.size(); ++k)
        pieces.push_back({spans[k], printer.statement(ast.stmts[k])});
    for (const MacroOrigins::Range& d : origins.defines)
        pieces.push_back({{d.begin, d.end}, defineText(text, {d.begin, d.end}), true});
    std::stable_sort(pieces.begin(), pieces.end(),
                     [](const Piece& a, const Piece& b) { return a.span.begin < b.span.begin; });
    if (!macrosKept(src, pieces, uses, diags)) return std::nullopt;
    std::vector<Span> sorted;
    for (const Piece& p : pieces) sorted.push_back(p.span);
    const Placement place = placeComments(text, sorted, others);
    Emitter out(text);
    size_t ci = 0;
    for (size_t i = 0; i < pieces.size(); ++i) {
        while (ci < place.standalone.size() && place.standalone[ci].begin < sorted[i].begin)
            out.comment(place.standalone[ci++]);
        out.statement(sorted[i], pieces[i].text, place.inner[i], place.trailing[i]);
    }
    while (ci < place.standalone.size()) out.comment(place.standalone[ci++]);
    return out.take();
}

std::string printSyntaxTree(const Source& src, const std::vector<Token>& tokens, const Ast& ast) {
    const BraceComments none;
    const MacroOrigins noMacros;
    const MacroUses uses(src, tokens, noMacros);
    const Printer printer(src, tokens, ast, none, uses);
    std::string out;
    for (const Stmt& s : ast.stmts) out += printer.statement(s) + "\n";
    return out;
}

}  // namespace pcsg
