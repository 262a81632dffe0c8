// Tests of Diagnostics::format: one line "file:line:col: error: message", the source
// line and a caret under the column, like a C compiler's.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "diagnostics.h"

namespace pcsg {
namespace {

std::string formatOne(std::string_view text, uint32_t line, uint32_t column,
                      const std::string& msg) {
    Diagnostics d;
    const uint32_t f = d.addFile("a.pcsg", text);
    d.error({f, line, column}, msg);
    return d.format();
}

TEST(DiagnosticsFormat, HeaderSourceLineAndCaret) {
    EXPECT_EQ(formatOne("S 1\nS if(sine(c) > 0, 2, 1)\n", 2, 6, "unknown function 'sine'"),
              "a.pcsg:2:6: error: unknown function 'sine'\n"
              "  S if(sine(c) > 0, 2, 1)\n"
              "       ^\n");
}

TEST(DiagnosticsFormat, TabsAreKeptSoTheCaretLinesUp) {
    EXPECT_EQ(formatOne("\t\tx = $", 1, 7, "m"),
              "a.pcsg:1:7: error: m\n  \t\tx = $\n  \t\t    ^\n");
}

TEST(DiagnosticsFormat, MultiByteCharactersTakeOneColumnOfCaret) {
    // Columns count bytes; the caret counts characters, so it stays under its token.
    EXPECT_EQ(formatOne("A ∪ ∪ B", 1, 7, "m"), "a.pcsg:1:7: error: m\n  A ∪ ∪ B\n      ^\n");
}

TEST(DiagnosticsFormat, ControlBytesAndCarriageReturnsAreNotPrinted) {
    EXPECT_EQ(formatOne(std::string("a\x01\xff b\r\nnext", 9), 1, 5, "m"),
              "a.pcsg:1:5: error: m\n  a?? b\n      ^\n");
}

TEST(DiagnosticsFormat, ALocationPastTheEndOfTheLine) {
    EXPECT_EQ(formatOne("move(1,0,0)\n", 1, 12, "m"),
              "a.pcsg:1:12: error: m\n  move(1,0,0)\n             ^\n");
    EXPECT_EQ(formatOne("", 1, 1, "empty"), "a.pcsg:1:1: error: empty\n  \n  ^\n");
}

TEST(DiagnosticsFormat, NoPositionMeansNoSourceLine) {
    EXPECT_EQ(formatOne("x", 0, 0, "cannot open the file"),
              "a.pcsg: error: cannot open the file\n");
}

TEST(DiagnosticsFormat, SeveralFilesAndErrorsInOrder) {
    Diagnostics d;
    const uint32_t a = d.addFile("a.pcsg", "one\ntwo\n");
    const uint32_t b = d.addFile("b.pcsg", "three\n");
    d.error({a, 2, 1}, "first");
    d.error({b, 1, 3}, "second");
    EXPECT_EQ(d.format(),
              "a.pcsg:2:1: error: first\n  two\n  ^\nb.pcsg:1:3: error: second\n  three\n    ^\n");
    EXPECT_EQ(d.fileNames().size(), 2u);
}

TEST(DiagnosticsFormat, CollectionStopsAtTheLimitAndSaysSo) {
    Diagnostics d;
    d.addFile("a.pcsg", "x");
    for (int i = 0; i < 80; ++i) d.error({0, 1, 1}, std::string(1, 'e').append(std::to_string(i)));
    ASSERT_EQ(d.errors().size(), Diagnostics::kMaxErrors);
    EXPECT_EQ(d.errors()[48].message, "e48");
    EXPECT_NE(d.errors().back().message.find("too many errors"), std::string::npos);
}

TEST(DiagnosticsFormat, HugeMessagesAreCut) {
    Diagnostics d;
    d.addFile("a.pcsg", "x");
    d.error({0, 1, 1}, "unknown module '" + std::string(1 << 20, 'x') + "'");
    ASSERT_EQ(d.errors().size(), 1u);
    EXPECT_LE(d.errors()[0].message.size(), 410u);
    EXPECT_EQ(d.errors()[0].message.substr(d.errors()[0].message.size() - 3), "...");
}

// Line starts, which both the lexer's locations and the quoted lines come from: every byte
// after a '\n' starts a line, the first line starts at 0, and a '\r' stays in its line.
TEST(DiagnosticsFormat, LineStartsFollowEveryNewline) {
    EXPECT_EQ(lineStartsOf(""), (std::vector<uint32_t>{0}));
    EXPECT_EQ(lineStartsOf("a"), (std::vector<uint32_t>{0}));
    EXPECT_EQ(lineStartsOf("a\n"), (std::vector<uint32_t>{0, 2}));
    EXPECT_EQ(lineStartsOf("a\nb\r\n\nc"), (std::vector<uint32_t>{0, 2, 5, 6}));
}

}  // namespace
}  // namespace pcsg
