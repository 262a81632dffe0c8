// The lexer: scanning and the newline rule; #define is macros.cpp. See lexer.h.
#include "lexer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "macros.h"

namespace pcsg {

// ---------------------------------------------------------------------------------------
// Source

Source::Source(std::string_view text, uint32_t file)
    : text_(text), file_(file), lineStarts_(lineStartsOf(text)) {}

FileLoc Source::loc(uint32_t offset) const {
    // The last line start <= offset.
    auto it = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
    const size_t line = static_cast<size_t>(it - lineStarts_.begin());  // 1-based
    return FileLoc{file_, static_cast<uint32_t>(line), offset - lineStarts_[line - 1] + 1};
}

// ---------------------------------------------------------------------------------------
// Keywords

namespace {

struct KeywordEntry {
    std::string_view name;
    Kw kw;
};

constexpr KeywordEntry kKeywords[] = {
    {"camera", Kw::Camera},
    {"light", Kw::Light},
    {"background", Kw::Background},
    {"material", Kw::Material},
    {"sky_sphere", Kw::SkySphere},
    {"settings", Kw::Settings},
    {"fog", Kw::Fog},
    {"paint", Kw::Paint},
    {"move", Kw::Move},
    {"translate", Kw::Translate},
    {"scale", Kw::Scale},
    {"uscale", Kw::UScale},
    {"rotx", Kw::RotX},
    {"roty", Kw::RotY},
    {"rotz", Kw::RotZ},
    {"rot", Kw::Rot},
    {"zshear", Kw::ZShear},
    {"flipyz", Kw::FlipYZ},
    {"flipxz", Kw::FlipXZ},
    {"flipxy", Kw::FlipXY},
    {"matrix", Kw::Matrix},
    {"if", Kw::If},
    {"rand", Kw::Rand},
    {"choose", Kw::Choose},
    {"pi", Kw::Pi},
    {"e", Kw::E},
    {"clock", Kw::Clock},
    {"frame", Kw::Frame},
    {"sin", Kw::Sin},
    {"cos", Kw::Cos},
    {"tan", Kw::Tan},
    {"asin", Kw::Asin},
    {"acos", Kw::Acos},
    {"atan", Kw::Atan},
    {"atan2", Kw::Atan2},
    {"sqrt", Kw::Sqrt},
    {"exp", Kw::Exp},
    {"ln", Kw::Ln},
    {"log10", Kw::Log10},
    {"pow", Kw::Pow},
    {"abs", Kw::Abs},
    {"floor", Kw::Floor},
    {"ceil", Kw::Ceil},
    {"min", Kw::Min},
    {"max", Kw::Max},
    {"mod", Kw::Mod},
    {"clamp", Kw::Clamp},
};

const std::unordered_map<std::string_view, Kw>& keywordTable() {
    static const std::unordered_map<std::string_view, Kw> table = [] {
        std::unordered_map<std::string_view, Kw> t;
        for (const auto& e : kKeywords) t.emplace(e.name, e.kw);
        for (const PrimitiveInfo& p : kPrimitiveTable) t.emplace(p.name, primitiveKeyword(p.kind));
        return t;
    }();
    return table;
}

}  // namespace

Kw keywordOf(std::string_view word) {
    // Every keyword is 1..11 lower-case letters or digits: most identifiers fail fast.
    if (word.empty() || word.size() > 11 || word[0] < 'a' || word[0] > 'z') return Kw::None;
    const auto& t = keywordTable();
    auto it = t.find(word);
    return it == t.end() ? Kw::None : it->second;
}

std::string_view keywordName(Kw k) {
    for (const auto& e : kKeywords)
        if (e.kw == k) return e.name;
    for (const PrimitiveInfo& p : kPrimitiveTable)
        if (primitiveKeyword(p.kind) == k) return p.name;
    return "?";
}

std::string clip(std::string_view s) {
    if (s.size() <= 64) return std::string(s);
    size_t cut = 60;
    while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
    return std::string(s.substr(0, cut)) + "...";
}

std::string_view spelling(const Source& src, const Token& t) {
    if (t.kind == Tok::End || t.kind == Tok::Newline) return {};
    return src.text().substr(t.offset, t.length);
}

std::string describe(const Source& src, const Token& t) {
    switch (t.kind) {
        case Tok::End:
            return "end of file";
        case Tok::Newline:
            return (t.flags & kForced) ? "the start of a new rule" : "end of line";
        case Tok::Number:
            return fmt::format("number '{}'", spelling(src, t));
        default:
            break;
    }
    std::string_view s = spelling(src, t);
    if (s.size() > 40) return fmt::format("'{}...'", s.substr(0, 40));
    return fmt::format("'{}'", s);
}

// ---------------------------------------------------------------------------------------
// Step 1: scanning

namespace {

bool isDigit(unsigned char c) {
    return c >= '0' && c <= '9';
}
bool isIdentStart(unsigned char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool isIdentChar(unsigned char c) {
    return isIdentStart(c) || isDigit(c);
}

bool full(const Diagnostics& d) {
    return d.errors().size() >= Diagnostics::kMaxErrors;
}

// ASCII punctuation: the token of a character, and of it followed by `second`.
struct Punctuation {
    Tok one = Tok::End;  // End: not punctuation
    char second = '\0';
    Tok two = Tok::End;
};

struct PunctuationTable {
    Punctuation at[128];
    constexpr const Punctuation& operator[](unsigned char c) const { return at[c & 0x7f]; }
};

constexpr PunctuationTable makePunctuationTable() {
    PunctuationTable t;
    auto one = [&](char c, Tok k) { t.at[static_cast<int>(c)] = Punctuation{k}; };
    auto two = [&](char c, Tok k, char second, Tok pair) {
        t.at[static_cast<int>(c)] = Punctuation{k, second, pair};
    };
    one('(', Tok::LParen);
    one(')', Tok::RParen);
    one('{', Tok::LBrace);
    one('}', Tok::RBrace);
    one('[', Tok::LBracket);
    one(']', Tok::RBracket);
    one(',', Tok::Comma);
    one(';', Tok::Semicolon);
    one(':', Tok::Colon);
    one('+', Tok::Plus);
    one('*', Tok::Star);
    one('/', Tok::Slash);
    one('%', Tok::Percent);
    one('^', Tok::Caret);
    one('\\', Tok::Difference);
    two('-', Tok::Minus, '>', Tok::Arrow);
    two('|', Tok::Union, '|', Tok::OrOr);
    two('&', Tok::Intersect, '&', Tok::AndAnd);
    two('=', Tok::Assign, '=', Tok::Eq);
    two('!', Tok::Bang, '=', Tok::Ne);
    two('<', Tok::Lt, '=', Tok::Le);
    two('>', Tok::Gt, '=', Tok::Ge);
    return t;
}

constexpr PunctuationTable kPunctuation = makePunctuationTable();

class Scanner {
  public:
    Scanner(const Source& src, Diagnostics& diags, std::vector<Token>& out)
        : src_(src), diags_(diags), s_(src.text()), out_(out) {}

    void run() {
        size_t i = 0;
        const size_t n = s_.size();
        if (n >= 3 && s_.substr(0, 3) == "\xEF\xBB\xBF") i = 3;  // a UTF-8 byte-order mark
        while (i < n) {
            const unsigned char c = static_cast<unsigned char>(s_[i]);
            if (c == '\n') {
                lineStart_ = true;
                ++i;
                continue;
            }
            if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
                ++i;
                continue;
            }
            if (c == '/' && i + 1 < n && s_[i + 1] == '/') {
                const void* nl = std::memchr(s_.data() + i, '\n', n - i);
                i = nl ? static_cast<size_t>(static_cast<const char*>(nl) - s_.data()) : n;
                continue;
            }
            if (c == '/' && i + 1 < n && s_[i + 1] == '*') {
                const size_t close = s_.find("*/", i + 2);
                if (close == std::string_view::npos) {
                    error(i, "unterminated /* comment");
                    stop_ = true;
                    return;
                }
                // A comment spanning lines still separates the tokens around it by a line
                // break.
                if (std::memchr(s_.data() + i, '\n', close - i)) lineStart_ = true;
                i = close + 2;
                continue;
            }
            if (isDigit(c) ||
                (c == '.' && i + 1 < n && isDigit(static_cast<unsigned char>(s_[i + 1])))) {
                i = number(i);
            } else if (isIdentStart(c)) {
                size_t j = i + 1;
                while (j < n && isIdentChar(static_cast<unsigned char>(s_[j]))) ++j;
                const Kw kw = keywordOf(s_.substr(i, j - i));
                push(kw == Kw::None ? Tok::Ident : Tok::Keyword, i, j - i, kw);
                i = j;
            } else if (c < 0x80) {
                i = punctuation(i);
            } else {
                i = unicode(i);
            }
            if (stop_ || full(diags_)) return;
        }
    }

    bool stopped() const { return stop_ || full(diags_); }

  private:
    void error(size_t offset, std::string message) {
        diags_.error(src_.loc(static_cast<uint32_t>(offset)), std::move(message));
    }

    void push(Tok kind, size_t offset, size_t length, Kw kw = Kw::None, uint8_t flags = 0) {
        Token t;
        t.kind = kind;
        t.kw = kw;
        t.flags = static_cast<uint8_t>(flags | (lineStart_ ? kLineStart : 0));
        t.offset = static_cast<uint32_t>(offset);
        t.length = static_cast<uint32_t>(length);
        out_.push_back(t);
        lineStart_ = false;
    }

    // number -> digits [ '.' digits ] [ ('e'|'E') ['+'|'-'] digits ]  |  '.' digits ...
    size_t number(size_t i) {
        const size_t n = s_.size();
        const size_t start = i;
        bool integer = true;
        auto digit = [&](size_t k) { return k < n && isDigit(static_cast<unsigned char>(s_[k])); };
        while (digit(i)) ++i;
        if (i < n && s_[i] == '.') {
            integer = false;
            ++i;
            while (digit(i)) ++i;
        }
        bool bad = false;
        if (i < n && (s_[i] == 'e' || s_[i] == 'E')) {
            size_t j = i + 1;
            if (j < n && (s_[j] == '+' || s_[j] == '-')) ++j;
            if (digit(j)) {
                integer = false;
                i = j;
                while (digit(i)) ++i;
            } else {
                bad = true;
            }
        }
        if (i < n && (isIdentChar(static_cast<unsigned char>(s_[i])) || s_[i] == '.')) bad = true;
        if (bad) {
            size_t j = i;
            while (j < n &&
                   (isIdentChar(static_cast<unsigned char>(s_[j])) || s_[j] == '.' ||
                    ((s_[j] == '+' || s_[j] == '-') && (s_[j - 1] == 'e' || s_[j - 1] == 'E'))))
                ++j;
            error(start, fmt::format("malformed number '{}'",
                                     s_.substr(start, std::min<size_t>(j - start, 40))));
            push(Tok::Number, start, i - start, Kw::None, 0);
            return j;
        }
        push(Tok::Number, start, i - start, Kw::None, integer ? kInteger : 0);
        return i;
    }

    size_t punctuation(size_t i) {
        const size_t n = s_.size();
        const char c = s_[i];
        if (c == '#') return hash(i);
        const Punctuation& p = kPunctuation[static_cast<unsigned char>(c)];
        if (p.one != Tok::End) {
            if (p.second != '\0' && i + 1 < n && s_[i + 1] == p.second) {
                push(p.two, i, 2);
                return i + 2;
            }
            push(p.one, i, 1);
            return i + 1;
        }
        if (c == '\0') {
            error(i, "unexpected NUL byte: this does not look like a text file");
            stop_ = true;
            return n;
        }
        // Any other ASCII character: report a run of them once.
        size_t j = i + 1;
        while (j < n && static_cast<unsigned char>(s_[j]) < 0x80 && s_[j] != '\0' &&
               badAscii(static_cast<unsigned char>(s_[j])))
            ++j;
        const unsigned char u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f)
            error(i, fmt::format("unexpected character '{}'", c));
        else
            error(i, fmt::format("unexpected control character 0x{:02X}", u));
        return j;
    }

    // '#': a directive. Only #define exists; the line of any other is skipped here (the
    // macro processor, macros.cpp, reports it), so that `#include "x"` gets one error, not one per
    // quote.
    size_t hash(size_t i) {
        const size_t n = s_.size();
        const bool first = lineStart_;
        push(Tok::Hash, i, 1);
        size_t j = i + 1;
        while (j < n && (s_[j] == ' ' || s_[j] == '\t')) ++j;
        size_t k = j;
        while (k < n && isIdentChar(static_cast<unsigned char>(s_[k]))) ++k;
        if (!first || k == j || s_.substr(j, k - j) == "define") return i + 1;
        push(Tok::Ident, j, k - j);
        const void* nl = std::memchr(s_.data() + k, '\n', n - k);
        return nl ? static_cast<size_t>(static_cast<const char*>(nl) - s_.data()) : n;
    }

    static bool badAscii(unsigned char c) {
        if (isIdentChar(c) || c == ' ' || c == '\t' || c == '\n' || c == '\r') return false;
        return std::strchr("(){},;:+-*/%^\\#|&=!<>.", c) == nullptr || c == 0;
    }

    // Multi-byte UTF-8: the Unicode operators, or an error.
    size_t unicode(size_t i) {
        const size_t n = s_.size();
        const unsigned char c = static_cast<unsigned char>(s_[i]);
        size_t len = 0;
        uint32_t cp = 0;
        if (c >= 0xC2 && c <= 0xDF)
            len = 2, cp = c & 0x1F;
        else if (c >= 0xE0 && c <= 0xEF)
            len = 3, cp = c & 0x0F;
        else if (c >= 0xF0 && c <= 0xF4)
            len = 4, cp = c & 0x07;
        bool ok = len != 0 && i + len <= n;
        for (size_t k = 1; ok && k < len; ++k) {
            const unsigned char cc = static_cast<unsigned char>(s_[i + k]);
            if ((cc & 0xC0) != 0x80) ok = false;
            cp = (cp << 6) | (cc & 0x3F);
        }
        if (ok && ((len == 3 && cp < 0x800) || (len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
                   (cp >= 0xD800 && cp <= 0xDFFF)))
            ok = false;
        if (!ok) {
            error(i, fmt::format("invalid UTF-8 byte 0x{:02X}", c));
            // Skip the rest of a run of bytes that are not ASCII.
            size_t j = i + 1;
            while (j < n && static_cast<unsigned char>(s_[j]) >= 0x80) ++j;
            return j;
        }
        switch (cp) {
            case 0x222A:
                push(Tok::Union, i, len);
                return i + len;  // ∪
            case 0x2229:
                push(Tok::Intersect, i, len);
                return i + len;  // ∩
            case 0x2216:
                push(Tok::Difference, i, len);
                return i + len;  // ∖ (set minus)
            case 0x2192:
                push(Tok::Arrow, i, len);
                return i + len;  // →
            default:
                break;
        }
        if (cp == 0xA0 || cp == 0x2009 || cp == 0x202F || cp == 0x200B) return i + len;  // spaces
        error(i, fmt::format("unexpected character '{}' (U+{:04X})", s_.substr(i, len), cp));
        return i + len;
    }

    const Source& src_;
    Diagnostics& diags_;
    std::string_view s_;
    std::vector<Token>& out_;
    bool lineStart_ = true;
    bool stop_ = false;
};

// ---------------------------------------------------------------------------------------
// Step 3: the newline rule

bool isDirectiveKeyword(const Token& t) {
    return t.kind == Tok::Keyword &&
           (t.kw == Kw::Camera || t.kw == Kw::Light || t.kw == Kw::Background ||
            t.kw == Kw::Material || t.kw == Kw::Settings || t.kw == Kw::Fog ||
            t.kw == Kw::SkySphere);
}

// Whether a statement (or an item inside braces) may end after this token.
bool canEnd(const Token& t, bool directive) {
    switch (t.kind) {
        case Tok::Number:
        case Tok::Ident:
        case Tok::Keyword:
        case Tok::RParen:
            return true;
        // A directive's '}' and a vector's '>' end an item; a C-node's '}' needs its operand.
        case Tok::RBrace:
        case Tok::RBracket:
        case Tok::Gt:
            return directive;
        default:
            return false;
    }
}

void applyNewlineRule(const std::vector<Token>& in, std::vector<Token>& out) {
    out.reserve(in.size() + in.size() / 2 + 1);
    std::vector<uint8_t> brackets;  // '(' or '{', innermost last
    bool directive = false, statementStart = true;
    Token prev;  // the last token pushed (kind End: none yet)
    bool any = false;
    auto newline = [&](uint8_t flags) {
        Token nl;
        nl.kind = Tok::Newline;
        nl.flags = flags;
        nl.offset = prev.offset + prev.length;
        out.push_back(nl);
    };
    for (size_t i = 0; i < in.size(); ++i) {
        Token t = in[i];
        if ((t.flags & kLineStart) && any && t.kind != Tok::End) {
            const bool ruleStart =
                (t.kind == Tok::Ident || (t.kind == Tok::Number && (t.flags & kInteger))) &&
                i + 1 < in.size() && in[i + 1].kind == Tok::Colon;
            if (!brackets.empty() && ruleStart) {
                // Unbalanced brackets before a line that starts a rule: end the statement
                // there, so that one missing ')' costs one error, not the rest of the file.
                newline(kTopLevel | kForced);
                brackets.clear();
                statementStart = true;
            } else if (canEnd(prev, directive)) {
                if (brackets.empty()) {
                    newline(kTopLevel);
                    statementStart = true;
                } else if (brackets.back() == '{') {
                    newline(0);
                }
            }
        }
        if (t.kind == Tok::End) {
            out.push_back(t);
            break;
        }
        if (statementStart && brackets.empty()) {
            directive = isDirectiveKeyword(t);
            statementStart = false;
        }
        switch (t.kind) {
            case Tok::LParen:
                brackets.push_back('(');
                break;
            case Tok::LBrace:
                brackets.push_back('{');
                break;
            case Tok::LBracket:
                brackets.push_back('[');
                break;
            case Tok::RParen:
            case Tok::RBrace:
            case Tok::RBracket:
                if (!brackets.empty()) brackets.pop_back();
                break;
            case Tok::Semicolon:
                if (brackets.empty()) {
                    t.flags |= kTopLevel;
                    statementStart = true;
                }
                break;
            default:
                break;
        }
        out.push_back(t);
        prev = t;
        any = true;
    }
}

// The uses of the tokens after the newline rule, from those before it (`useOf`): the rule
// only inserts Newline tokens, and one between two tokens of the same use is that use's.
std::vector<uint32_t> usesAfterNewlines(const std::vector<Token>& out,
                                        const std::vector<uint32_t>& useOf) {
    std::vector<uint32_t> after;
    after.reserve(out.size());
    size_t j = 0;  // the next token before the rule
    for (const Token& t : out) {
        if (t.kind != Tok::Newline) {
            after.push_back(useOf[j++]);
            continue;
        }
        const bool inside = j > 0 && j < useOf.size() && useOf[j - 1] == useOf[j];
        after.push_back(inside ? useOf[j] : MacroOrigins::kNone);
    }
    return after;
}

}  // namespace

TokenStream lex(const Source& src, Diagnostics& diags, MacroOrigins* origins) {
    // Fresh memory is the main cost of lexing a large file, so every stage reserves what
    // it may need once (untouched reserved pages cost nothing) and is freed when done.
    std::vector<Token> raw;
    raw.reserve(src.text().size() / 2 + 16);
    Scanner scanner(src, diags, raw);
    scanner.run();
    Token end;
    end.kind = Tok::End;
    end.flags = kLineStart;
    end.offset = static_cast<uint32_t>(src.text().size());
    raw.push_back(end);

    TokenStream ts;
    ts.complete = !scanner.stopped();
    const bool hasDirectives =
        std::any_of(raw.begin(), raw.end(), [](const Token& t) { return t.kind == Tok::Hash; });
    std::vector<Token> afterMacros;
    if (hasDirectives) {
        ts.complete = expandMacros(src, diags, raw, afterMacros, origins) && ts.complete;
        std::vector<Token>().swap(raw);
    } else {
        afterMacros.swap(raw);
        if (origins) origins->useOf.assign(afterMacros.size(), MacroOrigins::kNone);
    }
    applyNewlineRule(afterMacros, ts.tokens);
    if (origins) origins->useOf = usesAfterNewlines(ts.tokens, origins->useOf);
    return ts;
}

}  // namespace pcsg
