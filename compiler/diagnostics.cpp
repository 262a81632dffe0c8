// Compile-time diagnostics: collected while compiling, printed like a C compiler's.
#include "diagnostics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

namespace pcsg {

uint32_t Diagnostics::addFile(std::string name, std::string_view text) {
    names_.push_back(std::move(name));
    texts_.push_back(text);
    return static_cast<uint32_t>(names_.size() - 1);
}

void Diagnostics::error(FileLoc loc, std::string message) {
    // A message quotes names from the input, which may be megabytes long.
    constexpr size_t kMaxMessage = 400;
    if (message.size() > kMaxMessage) {
        size_t cut = kMaxMessage;
        while (cut > 0 && (static_cast<unsigned char>(message[cut]) & 0xC0) == 0x80) --cut;
        message.resize(cut);
        message += "...";
    }
    ++reported_;
    if (errors_.size() + 1 < kMaxErrors) {
        errors_.push_back(Diagnostic{loc, std::move(message)});
    } else if (errors_.size() + 1 == kMaxErrors) {
        errors_.push_back(Diagnostic{
            loc, fmt::format("{} (too many errors: stopping after {})", message, kMaxErrors)});
    }
}

namespace {

// The length of the valid UTF-8 sequence starting at s[i], or 0.
size_t utf8Length(std::string_view s, size_t i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    size_t len = 0;
    if (c >= 0xC2 && c <= 0xDF)
        len = 2;
    else if (c >= 0xE0 && c <= 0xEF)
        len = 3;
    else if (c >= 0xF0 && c <= 0xF4)
        len = 4;
    if (len == 0 || i + len > s.size()) return 0;
    for (size_t k = 1; k < len; ++k)
        if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
    return len;
}

// Appends the source line and a caret under `column` (1-based, in bytes). Tabs are kept
// in both lines so that the caret lines up in any terminal; a long line is cut to a
// window around the column; bytes that are not printable text show as '?'.
void appendQuote(std::string& out, std::string_view line, uint32_t column) {
    constexpr size_t kMaxShown = 200, kHalf = 90;
    size_t col = column > 0 ? column - 1 : 0;
    size_t from = 0, to = line.size();
    bool cutLeft = false, cutRight = false;
    if (line.size() > kMaxShown) {
        from = col > kHalf ? col - kHalf : 0;
        to = std::min(line.size(), from + 2 * kHalf);
        // Never cut a UTF-8 sequence in two.
        while (from > 0 && (static_cast<unsigned char>(line[from]) & 0xC0) == 0x80) --from;
        while (to < line.size() && (static_cast<unsigned char>(line[to]) & 0xC0) == 0x80) ++to;
        cutLeft = from > 0;
        cutRight = to < line.size();
    }
    std::string shown = "  ", caret = "  ";
    if (cutLeft) {
        shown += "...";
        caret += "   ";
    }
    for (size_t i = from; i < to;) {
        const unsigned char c = static_cast<unsigned char>(line[i]);
        const bool before = i < col;
        if (c == '\t') {
            shown += '\t';
            if (before) caret += '\t';
            ++i;
        } else if (c >= 0x20 && c < 0x7f) {
            shown += static_cast<char>(c);
            if (before) caret += ' ';
            ++i;
        } else if (const size_t n = c >= 0x80 ? utf8Length(line, i) : 0; n > 0) {
            shown.append(line.substr(i, n));
            if (before) caret += ' ';
            i += n;
        } else {
            shown += '?';
            if (before) caret += ' ';
            ++i;
        }
    }
    if (cutRight) shown += "...";
    // A column past the end of the shown text (the end of a line): pad with spaces.
    if (col > to) caret.append(std::min<size_t>(col - to, 8), ' ');
    caret += '^';
    out += shown;
    out += '\n';
    out += caret;
    out += '\n';
}

}  // namespace

std::vector<uint32_t> lineStartsOf(std::string_view text) {
    std::vector<uint32_t> starts{0};
    const char* base = text.data();
    const char* p = base;
    const char* end = base + text.size();
    while (p < end) {
        const void* nl = std::memchr(p, '\n', static_cast<size_t>(end - p));
        if (!nl) break;
        p = static_cast<const char*>(nl) + 1;
        starts.push_back(static_cast<uint32_t>(p - base));
    }
    return starts;
}

std::string Diagnostics::format() const {
    std::string out;
    // Line starts of each file, computed once and only for files with errors.
    std::vector<std::vector<uint32_t>> lineStarts(texts_.size());
    for (const Diagnostic& d : errors_) {
        const std::string name =
            d.loc.file < names_.size() ? names_[d.loc.file] : std::string("<input>");
        if (d.loc.line == 0 || d.loc.file >= texts_.size()) {
            out += fmt::format("{}: error: {}\n", name, d.message);
            continue;
        }
        out += fmt::format("{}:{}:{}: error: {}\n", name, d.loc.line, d.loc.column, d.message);
        const std::string_view text = texts_[d.loc.file];
        auto& starts = lineStarts[d.loc.file];
        if (starts.empty()) starts = lineStartsOf(text);
        if (d.loc.line > starts.size()) continue;
        const size_t begin = starts[d.loc.line - 1];
        size_t end = d.loc.line < starts.size() ? starts[d.loc.line] - 1 : text.size();
        if (end > begin && text[end - 1] == '\r') --end;
        appendQuote(out, text.substr(begin, end - begin), d.loc.column);
    }
    return out;
}

}  // namespace pcsg
