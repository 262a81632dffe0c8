// Tests of the lexer: tokens, #define and the newline rule (docs/language.md sections 1, 2).
#include "lexer.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pcsg {
namespace {

struct Lexed {
    std::string text;
    Diagnostics diags;
    std::unique_ptr<Source> src;
    TokenStream ts;
};

std::unique_ptr<Lexed> lexText(std::string text) {
    auto l = std::make_unique<Lexed>();
    l->text = std::move(text);
    const uint32_t f = l->diags.addFile("t.pcsg", l->text);
    l->src = std::make_unique<Source>(l->text, f);
    l->ts = lex(*l->src, l->diags);
    return l;
}

// The token stream as one string: spellings, "NL" for a statement-ending line break,
// "nl" for a separating one inside braces, "EOF" at the end.
std::string render(const std::string& text) {
    auto l = lexText(text);
    std::string out;
    for (const Token& t : l->ts.tokens) {
        if (!out.empty()) out += ' ';
        if (t.kind == Tok::Newline)
            out += (t.flags & kTopLevel) ? "NL" : "nl";
        else if (t.kind == Tok::End)
            out += "EOF";
        else
            out += std::string(spelling(*l->src, t));
    }
    return out;
}

std::vector<Tok> kinds(const std::string& text) {
    auto l = lexText(text);
    std::vector<Tok> k;
    for (const Token& t : l->ts.tokens) k.push_back(t.kind);
    return k;
}

std::string errors(const std::string& text) {
    auto l = lexText(text);
    std::string out;
    for (const auto& d : l->diags.errors())
        out += std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + ": " + d.message +
               "\n";
    return out;
}

// Where macros went (for pcsg fmt): the #define lines and blocks, each use outside them,
// and for each token the use it came from; a use inside a macro's body belongs to the
// outer use, and a line break the newline rule puts inside a block belongs to its use.
TEST(Lexer, MacroOriginsSayWhichUseEachTokenCameFrom) {
    const std::string text = "#define B {\n  a = 1\n  b = 2\n}\n#define C B sphere\nC | B cube\n";
    Diagnostics diags;
    const Source src(text, diags.addFile("t.pcsg", text));
    MacroOrigins o;
    const TokenStream ts = lex(src, diags, &o);
    ASSERT_FALSE(diags.hasErrors()) << diags.format();
    ASSERT_EQ(o.defines.size(), 2u);
    EXPECT_EQ(text.substr(o.defines[0].begin, o.defines[0].end - o.defines[0].begin),
              "#define B {\n  a = 1\n  b = 2\n}");
    EXPECT_EQ(text.substr(o.defines[1].begin, o.defines[1].end - o.defines[1].begin),
              "#define C B sphere");
    ASSERT_EQ(o.uses.size(), 2u);
    EXPECT_EQ(text.substr(o.uses[0].begin, 1), "C");
    EXPECT_EQ(text.substr(o.uses[1].begin, 1), "B");
    ASSERT_EQ(o.useOf.size(), ts.tokens.size());
    std::string uses;  // each token's use: 0, 1 or '-' for none
    for (size_t k = 0; k < ts.tokens.size(); ++k)
        uses += o.useOf[k] == MacroOrigins::kNone ? '-' : static_cast<char>('0' + o.useOf[k]);
    // C: { a = 1 nl b = 2 nl } sphere; then |; B: { a = 1 nl b = 2 nl }; then cube, EOF
    EXPECT_EQ(uses, "00000000000-1111111111--");
}

TEST(Lexer, UnicodeAndAsciiOperatorsAreTheSameTokens) {
    EXPECT_EQ(kinds("A ∪ B ∩ C \\ D → E"), kinds("A | B & C \\ D -> E"));
    EXPECT_EQ(kinds("A | B"), (std::vector<Tok>{Tok::Ident, Tok::Union, Tok::Ident, Tok::End}));
    EXPECT_EQ(kinds("a || b && c"), (std::vector<Tok>{Tok::Ident, Tok::OrOr, Tok::Ident,
                                                      Tok::AndAnd, Tok::Ident, Tok::End}));
    EXPECT_EQ(kinds("a == b != c = d"),
              (std::vector<Tok>{Tok::Ident, Tok::Eq, Tok::Ident, Tok::Ne, Tok::Ident, Tok::Assign,
                                Tok::Ident, Tok::End}));
    EXPECT_EQ(kinds("a <= b >= c < d > e"),
              (std::vector<Tok>{Tok::Ident, Tok::Le, Tok::Ident, Tok::Ge, Tok::Ident, Tok::Lt,
                                Tok::Ident, Tok::Gt, Tok::Keyword, Tok::End}));
    EXPECT_EQ(kinds("c-1 -> x"), (std::vector<Tok>{Tok::Ident, Tok::Minus, Tok::Number, Tok::Arrow,
                                                   Tok::Ident, Tok::End}));
    EXPECT_EQ(errors("A ∪ B ∩ C \\ D → E ∖ F"), "");
}

TEST(Lexer, NumbersInEveryForm) {
    auto l = lexText("12 0.5 .5 1e-3 2.5E+2 7. 3e4");
    const auto& t = l->ts.tokens;
    ASSERT_EQ(t.size(), 8u);
    for (int i = 0; i < 7; ++i) EXPECT_EQ(t[i].kind, Tok::Number) << i;
    EXPECT_TRUE(t[0].flags & kInteger);
    for (int i = 1; i < 7; ++i) EXPECT_FALSE(t[i].flags & kInteger) << i;
    EXPECT_EQ(spelling(*l->src, t[3]), "1e-3");
    EXPECT_EQ(spelling(*l->src, t[4]), "2.5E+2");
    EXPECT_EQ(l->diags.errors().size(), 0u);
}

TEST(Lexer, MalformedNumbersAreErrors) {
    EXPECT_NE(errors("x = 1e+").find("1:5: malformed number '1e+'"), std::string::npos)
        << errors("x = 1e+");
    EXPECT_NE(errors("2x").find("malformed number '2x'"), std::string::npos);
    EXPECT_NE(errors("1.2.3").find("malformed number '1.2.3'"), std::string::npos);
}

TEST(Lexer, KeywordsAreCaseSensitiveAndIdentifiersAreNot) {
    auto l = lexText("sphere Sphere move_ rotz tri1 e pi E _x9");
    const auto& t = l->ts.tokens;
    EXPECT_TRUE(t[0].isKw(Kw::Sphere));
    EXPECT_EQ(t[1].kind, Tok::Ident);
    EXPECT_EQ(t[2].kind, Tok::Ident);
    EXPECT_TRUE(t[3].isKw(Kw::RotZ));
    EXPECT_TRUE(t[4].isKw(Kw::Tri1));
    EXPECT_TRUE(t[5].isKw(Kw::E));
    EXPECT_TRUE(t[6].isKw(Kw::Pi));
    EXPECT_EQ(t[7].kind, Tok::Ident);
    EXPECT_EQ(t[8].kind, Tok::Ident);
}

TEST(Lexer, CommentsDoNotNestAndMayBeUnterminated) {
    EXPECT_EQ(render("a // b c\nd"), "a NL d EOF");
    EXPECT_EQ(render("a /* b /* c */ d"), "a d EOF");
    EXPECT_EQ(render("a /* x\n y */ b"), "a NL b EOF");  // a comment's line break still counts
    EXPECT_EQ(errors("a /* b"), "1:3: unterminated /* comment\n");
}

TEST(Lexer, LocationsAreLineAndByteColumn) {
    auto l = lexText("ab\n  ∪ cd\n\tx");
    const auto& t = l->ts.tokens;
    // ab NL ∪ cd NL x EOF: the ∪ continues nothing, so a statement ends after ab.
    ASSERT_GE(t.size(), 6u);
    FileLoc c = l->src->loc(t[3].offset);  // cd, after a three-byte ∪
    EXPECT_EQ(c.line, 2u);
    EXPECT_EQ(c.column, 7u);
    FileLoc x = l->src->loc(t[5].offset);
    EXPECT_EQ(x.line, 3u);
    EXPECT_EQ(x.column, 2u);
}

TEST(Lexer, BadBytesGetOneCleanErrorEach) {
    EXPECT_EQ(errors("a $ b"), "1:3: unexpected character '$'\n");
    EXPECT_EQ(errors("a @@@ b"), "1:3: unexpected character '@'\n");
    EXPECT_EQ(errors("a \xFF b"), "1:3: invalid UTF-8 byte 0xFF\n");
    EXPECT_EQ(errors("a \xE2\x88 b"), "1:3: invalid UTF-8 byte 0xE2\n");
    EXPECT_EQ(errors("a ü b"), "1:3: unexpected character 'ü' (U+00FC)\n");
    // A NUL byte stops the lexer: binary files get one error, not fifty.
    EXPECT_EQ(errors(std::string("a \0 $ $ $", 9)),
              "1:3: unexpected NUL byte: this does not look like a text file\n");
    EXPECT_EQ(errors("\xEF\xBB\xBF"
                     "a"),
              "");  // a byte-order mark is skipped
}

// --- the newline rule (section 2) ---

TEST(NewlineRule, ALineBreakEndsAStatement) {
    EXPECT_EQ(render("S if(c>0,2,1)\n1: S -> cube\n"),
              "S if ( c > 0 , 2 , 1 ) NL 1 : S -> cube EOF");
    EXPECT_EQ(render("a; b"), "a ; b EOF");
}

TEST(NewlineRule, ATokenThatCannotEndAnExpressionContinuesTheLine) {
    EXPECT_EQ(render("1: S -> A ∪\n  B"), "1 : S -> A ∪ B EOF");
    EXPECT_EQ(render("1: S -> A \\\n  B"), "1 : S -> A \\ B EOF");
    EXPECT_EQ(render("1: S ->\n  B"), "1 : S -> B EOF");
    EXPECT_EQ(render("p: S(c) :\n c > 0 -> B"), "p : S ( c ) : c > 0 -> B EOF");
    EXPECT_EQ(render("d =\n B"), "d = B EOF");
    EXPECT_EQ(render("S c +\n 1"), "S c + 1 EOF");
    EXPECT_EQ(render("S c *\n 1 ||\n 0"), "S c * 1 || 0 EOF");
    // But an operand at the end of a line ends the statement.
    EXPECT_EQ(render("A\n∪ B"), "A NL ∪ B EOF");
}

TEST(NewlineRule, LineBreaksInsideParenthesesAreIgnored) {
    EXPECT_EQ(render("1: S -> move(1,\n 2,\n 3) (A\n ∪ B\n)"),
              "1 : S -> move ( 1 , 2 , 3 ) ( A ∪ B ) EOF");
}

TEST(NewlineRule, InsideBracesALineBreakSeparatesItems) {
    EXPECT_EQ(render("{ a = 1\n b = 2\n} S\n"), "{ a = 1 nl b = 2 nl } S EOF");
    EXPECT_EQ(render("{\n a = 1;\n b = 2,\n} S"), "{ a = 1 ; b = 2 , } S EOF");
    // A C-node's '}' needs its operand: the statement goes on.
    EXPECT_EQ(render("{c=6}\nS"), "{ c = 6 } S EOF");
}

TEST(NewlineRule, DirectivesEndAfterTheirBraceOrVector) {
    EXPECT_EQ(
        render("background <1,2,3>\ncamera { angle 40\n location <1,\n2,3>\n}\nS"),
        "background < 1 , 2 , 3 > NL camera { angle 40 nl location < 1 , 2 , 3 > nl } NL S EOF");
}

TEST(NewlineRule, AnUnclosedBracketEndsAtTheNextRule) {
    // One missing ')' must not swallow the rest of the file.
    EXPECT_EQ(render("1: S -> (A ∪\n2: S -> B"), "1 : S -> ( A ∪ NL 2 : S -> B EOF");
    auto l = lexText("1: S -> (A ∪\n2: S -> B");
    EXPECT_TRUE(l->ts.tokens[7].flags & kForced);
}

// --- #define (section 1) ---

TEST(Define, ALineMacroExpandsAsTokens) {
    EXPECT_EQ(render("#define HALF uscale(0.5)\n1: S -> HALF S"), "1 : S -> uscale ( 0.5 ) S EOF");
    EXPECT_EQ(render("#define EMPTY\nA EMPTY"), "A EOF");
}

TEST(Define, ABlockMacroMaySpanLinesAsInFigure8) {
    EXPECT_EQ(render("#define calc\n{\n  a = 1;\n  b = a\n}\n1: S -> calc T"),
              "1 : S -> { a = 1 ; b = a nl } T EOF");
    EXPECT_EQ(render("#define calc {\n  a = 1\n}\n1: S -> calc T"), "1 : S -> { a = 1 nl } T EOF");
    // A block closed on its own line is a line body: the rest of the line is part of it.
    EXPECT_EQ(render("#define START {c=6} S\nSTART"), "{ c = 6 } S EOF");
}

TEST(Define, MacrosMayUseEarlierMacrosAndExpandWhereUsed) {
    EXPECT_EQ(render("#define A 1 + B\n#define B 2\nS A"), "S 1 + 2 EOF");
    EXPECT_EQ(render("#define U ∪\n1: S -> A U\n B"), "1 : S -> A ∪ B EOF");
}

TEST(Define, UseBeforeDefineIsAnError) {
    EXPECT_EQ(errors("S X\n#define X 1\n"),
              "1:3: macro 'X' is used before its #define at line 2\n");
}

TEST(Define, RedefinitionIsAnError) {
    EXPECT_EQ(errors("#define X 1\n#define X 2\n"),
              "2:9: macro 'X' is already defined at line 1\n");
}

TEST(Define, SelfExpansionIsAnError) {
    EXPECT_EQ(errors("#define X X + 1\n"), "1:11: macro 'X' expands into itself\n");
    // Through another macro: reported at the use, once, and the expansion terminates.
    EXPECT_EQ(errors("#define A B\n#define B A\nS A A"), "2:11: macro 'A' expands into itself\n");
}

TEST(Define, BadDirectivesAreErrors) {
    EXPECT_EQ(errors("#include x\n"),
              "1:2: unknown directive '#include': only #define is supported\n");
    EXPECT_EQ(errors("#define sphere 1\n"),
              "1:9: 'sphere' is a keyword and cannot be a macro name\n");
    EXPECT_EQ(errors("#define\n"), "1:2: expected a macro name after #define\n");
    EXPECT_EQ(errors("a # define X\n"), "1:3: '#' must be the first thing on its line\n");
    EXPECT_EQ(errors("#define X\n{ a = 1\n"), "2:1: the '{' of #define X is never closed\n");
    EXPECT_EQ(errors("#define X {\n a = 1\n} b\n"),
              "3:3: unexpected 'b' after the block of #define X\n");
}

TEST(Define, ExponentialExpansionStopsWithAnError) {
    std::string text;
    for (int i = 0; i < 40; ++i)
        text += "#define M" + std::to_string(i) + " M" + std::to_string(i + 1) + " M" +
                std::to_string(i + 1) + "\n";
    text += "#define M40 x\nS M0\n";
    const std::string e = errors(text);
    EXPECT_NE(e.find("macro expansion makes more than"), std::string::npos) << e;
}

TEST(Define, AChainOfManyMacrosDoesNotRecurse) {
    std::string text;
    const int n = 100000;
    for (int i = 0; i < n; ++i)
        text += "#define M" + std::to_string(i) + " M" + std::to_string(i + 1) + "\n";
    text += "#define M" + std::to_string(n) + " 42\nS M0\n";
    EXPECT_EQ(render(text), "S 42 EOF");
}

}  // namespace
}  // namespace pcsg
