// The macro processor: #define and macro expansion (docs/language.md section 1,
// "#define"). See macros.h.
#include "macros.h"

#include <fmt/format.h>

#include <algorithm>
#include <unordered_map>

namespace pcsg {

namespace {

class MacroProcessor {
  public:
    MacroProcessor(const Source& src, Diagnostics& diags, const std::vector<Token>& raw,
                   std::vector<Token>& out, MacroOrigins* origins)
        : src_(src), diags_(diags), raw_(raw), out_(out), origins_(origins) {}

    void run() {
        collect();
        const size_t n = raw_.size() - 1;  // the last token is End
        out_.reserve(n + n / 2 + 16);
        size_t i = 0;
        while (i < n && !stop_) {
            const Token& t = raw_[i];
            if (t.kind == Tok::Hash) {
                i = directive(i);
                continue;
            }
            if (macroAt_[i] != kNotMacro) {
                if (origins_) origins_->uses.push_back({t.offset, t.offset + t.length});
                use(macroAt_[i], t, t.flags & kLineStart);
                if (origins_) origins_->useOf.resize(out_.size(), origins_->uses.size() - 1);
                ++i;
                continue;
            }
            emit(t);
            if (origins_) origins_->useOf.resize(out_.size(), MacroOrigins::kNone);
            ++i;
        }
        out_.push_back(raw_.back());
        if (origins_) origins_->useOf.push_back(MacroOrigins::kNone);
    }

    bool stopped() const { return stop_; }

  private:
    struct Macro {
        std::string_view name;
        uint32_t hash = 0;                    // raw index of its '#'
        uint32_t bodyBegin = 0, bodyEnd = 0;  // raw indices
        bool defined = false;                 // its #define has been passed
        bool reported = false;                // its self-expansion was reported
    };
    struct Frame {
        uint32_t macro;
        uint32_t pos;
        bool lineStart;
    };
    // Where a #define's body lies: raw tokens [begin, end); the next line starts at next.
    struct Body {
        size_t begin, end, next;
    };

    void error(const Token& t, std::string message) {
        diags_.error(src_.loc(t.offset), std::move(message));
    }

    bool sameLine(size_t i) const {
        return i < raw_.size() && raw_[i].kind != Tok::End && !(raw_[i].flags & kLineStart);
    }

    // The first #define of every name, so that a use before it can be recognised.
    void collect() {
        const size_t n = raw_.size() - 1;
        for (size_t i = 0; i + 2 < n; ++i) {
            if (raw_[i].kind != Tok::Hash || !(raw_[i].flags & kLineStart)) continue;
            if (!sameLine(i + 1) || raw_[i + 1].kind != Tok::Ident ||
                spelling(src_, raw_[i + 1]) != "define")
                continue;
            if (!sameLine(i + 2) || raw_[i + 2].kind != Tok::Ident) continue;
            const std::string_view name = spelling(src_, raw_[i + 2]);
            if (byName_.count(name)) continue;
            Macro m;
            m.name = name;
            m.hash = static_cast<uint32_t>(i);
            byName_.emplace(name, static_cast<uint32_t>(macros_.size()));
            macros_.push_back(m);
        }
        active_.assign(macros_.size(), 0);
        // Which raw identifiers name a macro: one look-up per token, whatever expands.
        macroAt_.assign(raw_.size(), kNotMacro);
        if (macros_.empty()) return;
        for (size_t i = 0; i < raw_.size(); ++i) {
            if (raw_[i].kind != Tok::Ident) continue;
            auto it = byName_.find(spelling(src_, raw_[i]));
            if (it != byName_.end()) macroAt_[i] = it->second;
        }
    }

    size_t skipLine(size_t i) const {
        while (i < raw_.size() - 1 && !(raw_[i].flags & kLineStart)) ++i;
        return i;
    }

    // The index just past the '}' matching the '{' at i, or 0 when it is not closed.
    size_t matchBrace(size_t i) const {
        size_t depth = 0;
        for (size_t k = i; k < raw_.size() - 1; ++k) {
            if (raw_[k].kind == Tok::LBrace)
                ++depth;
            else if (raw_[k].kind == Tok::RBrace && --depth == 0)
                return k + 1;
            else if (raw_[k].kind == Tok::Hash && (raw_[k].flags & kLineStart))
                return 0;
        }
        return 0;
    }

    // #define NAME body. Returns the raw index after it.
    size_t directive(size_t i) {
        if (const size_t resume = badHeader(i)) return resume;
        const Token& nameTok = raw_[i + 2];
        const std::string_view name = spelling(src_, nameTok);
        Body b;
        if (!body(i + 3, name, b)) {
            stop_ = true;
            return raw_.size() - 1;
        }
        define(i, nameTok, b);
        if (origins_) {
            const Token& last = raw_[std::max(b.end, i + 3) - 1];
            origins_->defines.push_back({raw_[i].offset, last.offset + last.length});
        }
        return b.next;
    }

    // Whether the '#' at i starts `#define NAME`: 0 when it does, else the raw index to
    // resume at after reporting what is wrong.
    size_t badHeader(size_t i) {
        const Token& hash = raw_[i];
        if (!(hash.flags & kLineStart)) {
            error(hash, "'#' must be the first thing on its line");
            return skipLine(i + 1);
        }
        if (!sameLine(i + 1) || spelling(src_, raw_[i + 1]) != "define") {
            if (sameLine(i + 1))
                error(raw_[i + 1], fmt::format("unknown directive '#{}': only #define is supported",
                                               clip(spelling(src_, raw_[i + 1]))));
            else
                error(hash, "expected 'define' after '#'");
            return skipLine(i + 1);
        }
        if (!sameLine(i + 2) ||
            (raw_[i + 2].kind != Tok::Ident && raw_[i + 2].kind != Tok::Keyword)) {
            error(sameLine(i + 2) ? raw_[i + 2] : raw_[i + 1],
                  "expected a macro name after #define");
            return skipLine(i + 2);
        }
        if (raw_[i + 2].kind == Tok::Keyword) {
            error(raw_[i + 2], fmt::format("'{}' is a keyword and cannot be a macro name",
                                           clip(spelling(src_, raw_[i + 2]))));
            return skipLine(i + 3);
        }
        return 0;
    }

    // The body of a #define that starts at raw index `begin`: the rest of the line; or a
    // `{ }` block that opens there and closes on a later line; or, when the name stands
    // alone, a block that opens on the next line (the paper's figure 8). False when a
    // block is never closed (reported).
    bool body(size_t begin, std::string_view name, Body& b) {
        b = Body{begin, begin, begin};
        if (sameLine(begin)) {
            const size_t lineEnd = skipLine(begin);
            if (raw_[begin].kind != Tok::LBrace) {
                b.end = b.next = lineEnd;
                return true;
            }
            const size_t close = matchBrace(begin);
            if (close == 0) return unclosed(begin, name);
            if (close > lineEnd && sameLine(close)) {
                afterBlock(close, name);
                b.end = close;
                b.next = skipLine(close);
            } else {
                b.end = b.next = std::max(close, lineEnd);
            }
        } else if (begin < raw_.size() - 1 && raw_[begin].kind == Tok::LBrace) {
            const size_t close = matchBrace(begin);
            if (close == 0) return unclosed(begin, name);
            b.end = b.next = close;
            if (sameLine(close)) {
                afterBlock(close, name);
                b.next = skipLine(close);
            }
        }
        return true;
    }

    bool unclosed(size_t brace, std::string_view name) {
        error(raw_[brace], fmt::format("the '{{' of #define {} is never closed", clip(name)));
        return false;
    }

    void afterBlock(size_t k, std::string_view name) {
        error(raw_[k], fmt::format("unexpected {} after the block of #define {}",
                                   describe(src_, raw_[k]), clip(name)));
    }

    // Gives the macro of the #define at raw index `hash` its body, unless it is a second
    // #define of the name; a '#' ends the body, a use of the name in it is reported.
    void define(size_t hash, const Token& nameTok, Body b) {
        const std::string_view name = spelling(src_, nameTok);
        Macro& m = macros_[byName_.at(name)];
        if (m.hash != hash) {
            error(nameTok, fmt::format("macro '{}' is already defined at line {}", clip(name),
                                       src_.loc(raw_[m.hash].offset).line));
            return;
        }
        for (size_t k = b.begin; k < b.end; ++k) {
            if (raw_[k].kind == Tok::Hash) {
                error(raw_[k], fmt::format("'#' inside the body of #define {}", clip(name)));
                b.end = k;
                break;
            }
            if (raw_[k].kind == Tok::Ident && spelling(src_, raw_[k]) == name && !m.reported) {
                error(raw_[k], fmt::format("macro '{}' expands into itself", clip(name)));
                m.reported = true;
            }
        }
        m.bodyBegin = static_cast<uint32_t>(b.begin);
        m.bodyEnd = static_cast<uint32_t>(b.end);
        m.defined = true;
    }

    void emit(Token t) {
        if (out_.size() >= raw_.size() + kMaxMacroTokens) {
            if (!stop_)
                error(t, fmt::format("macro expansion makes more than {} tokens", out_.size()));
            stop_ = true;
            return;
        }
        out_.push_back(t);
    }

    // Expands one use of a macro, iteratively (a chain of macros never deepens the stack).
    void use(uint32_t index, const Token& at, bool lineStart) {
        // A macro that cannot expand here is reported and dropped: leaving its name
        // would only add echoes ("unknown module ...") of the same error.
        if (!usable(index, at)) return;
        frames_.clear();
        push(index, lineStart);
        while (!frames_.empty() && !stop_) {
            Frame& f = frames_.back();
            const Macro& m = macros_[f.macro];
            if (f.pos >= m.bodyEnd) {
                active_[f.macro] = 0;
                frames_.pop_back();
                continue;
            }
            const uint32_t rawIndex = f.pos;
            Token t = raw_[f.pos];
            const bool first = f.pos == m.bodyBegin;
            ++f.pos;
            const bool ls = first ? f.lineStart : (t.flags & kLineStart) != 0;
            t.flags = static_cast<uint8_t>((t.flags & ~kLineStart) | (ls ? kLineStart : 0));
            const uint32_t inner = macroAt_[rawIndex];
            if (inner != kNotMacro) {
                if (usable(inner, t)) push(inner, ls);  // invalidates f
                continue;
            }
            emit(t);
        }
        for (const Frame& f : frames_) active_[f.macro] = 0;
        frames_.clear();
    }

    // Whether a macro may be expanded here; reports why not.
    bool usable(uint32_t index, const Token& at) {
        Macro& m = macros_[index];
        if (!m.defined) {
            error(at, fmt::format("macro '{}' is used before its #define at line {}", clip(m.name),
                                  src_.loc(raw_[m.hash].offset).line));
            return false;
        }
        if (active_[index]) {
            if (!m.reported) error(at, fmt::format("macro '{}' expands into itself", clip(m.name)));
            m.reported = true;
            return false;
        }
        return true;
    }

    void push(uint32_t index, bool lineStart) {
        active_[index] = 1;
        frames_.push_back(Frame{index, macros_[index].bodyBegin, lineStart});
    }

    const Source& src_;
    Diagnostics& diags_;
    const std::vector<Token>& raw_;
    std::vector<Token>& out_;
    MacroOrigins* origins_;
    std::vector<Macro> macros_;
    std::unordered_map<std::string_view, uint32_t> byName_;
    static constexpr uint32_t kNotMacro = UINT32_MAX;
    std::vector<uint32_t> macroAt_;  // raw index -> macro, or kNotMacro
    std::vector<uint8_t> active_;
    std::vector<Frame> frames_;
    bool stop_ = false;
};

}  // namespace

bool expandMacros(const Source& src, Diagnostics& diags, const std::vector<Token>& raw,
                  std::vector<Token>& out, MacroOrigins* origins) {
    MacroProcessor macros(src, diags, raw, out, origins);
    macros.run();
    return !macros.stopped();
}

}  // namespace pcsg
