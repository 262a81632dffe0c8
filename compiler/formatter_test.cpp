// pcsg fmt (formatter.h): idempotent, the same graph as the input for every scene in the
// repository, comments kept, and a hand-written messy input against its canonical form.
#include "formatter.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "compile_test_util.h"
#include "same_graph_test_util.h"

namespace pcsg {
namespace {

using testing::expectSameGraph;

std::string format(const std::string& text) {
    Diagnostics diags;
    const std::optional<std::string> out = formatScene("t.pcsg", text, diags);
    EXPECT_TRUE(out) << diags.format();
    return out.value_or("");
}

// Compiles a text and its formatted text and expects the same graph; returns the
// formatted text's compilation.
auto expectSameGraphOf(const std::string& text, const std::string& formatted) {
    auto a = testing::compile(text);
    auto b = testing::compile(formatted);
    EXPECT_TRUE(a->graph) << a->errors();
    EXPECT_TRUE(b->graph) << b->errors() << formatted;
    if (a->graph && b->graph) expectSameGraph(*a->graph, *b->graph);
    return b;
}

// Formats `text` and expects `expected`, formatted again unchanged, and the same graph.
void expectFormatted(const std::string& text, const std::string& expected) {
    EXPECT_EQ(format(text), expected);
    EXPECT_EQ(format(expected), expected);
    expectSameGraphOf(text, expected);
}

const std::filesystem::path kRoot = std::filesystem::path(__FILE__).parent_path().parent_path();

std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(Formatter, EverySceneIsIdempotentAndKeepsItsGraph) {
    int formatted = 0, withMacros = 0;
    for (const char* dir : {"scenes", "tools/bench", "tests/scenes"}) {
        for (const auto& entry : std::filesystem::directory_iterator(kRoot / dir)) {
            if (entry.path().extension() != ".pcsg") continue;
            SCOPED_TRACE(entry.path().string());
            const std::string text = readFile(entry.path());
            Diagnostics diags;
            const std::optional<std::string> once = formatScene("x.pcsg", text, diags);
            ASSERT_TRUE(once) << diags.format();
            withMacros += text.find("#define") != std::string::npos;
            EXPECT_EQ(format(*once), *once);
            expectSameGraphOf(text, *once);
            ++formatted;
        }
    }
    EXPECT_GE(formatted, 10);
    EXPECT_GE(withMacros, 3);  // landsberg, terrain, terrain_sea
}

// The paper's figure 8: a C-node block defined once and used by name. The #define stays
// as written, comments and all, and each use is printed as the macro's name.
TEST(Formatter, AMacroOfACNodeBlockIsKeptAsWritten) {
    const std::string defines =
        "#define STEP\n"
        "{\n"
        "    n = n-1;   // one level down\n"
        "    r = r*0.5\n"
        "}\n"
        "#define NOTHING { }\n";
    const std::string text = defines +
                             "{n=3; r=1} S\n"
                             "S if(n>0,2,1)\n"
                             "1: S -> NOTHING uscale(r) sphere\n"
                             "2: S -> STEP move(r,0,0) S | STEP (move(-r,0,0) S)\n";
    const std::string expected = defines +
                                 "{n = 3; r = 1} S\n"
                                 "S if(n > 0, 2, 1)\n"
                                 "1: S -> NOTHING uscale(r) sphere\n"
                                 "2: S -> STEP move(r, 0, 0) S ∪ STEP move(-r, 0, 0) S\n";
    expectFormatted(text, expected);
}

// Macros of a number, an expression and a CSG term: each use is a whole construct,
// printed as the name, with the parentheses the printer puts back where the expansion
// needs them (`HALF * 2` would join HALF's `/` into one chain), and none around a macro
// whose body brings its own (SUM, PAIR).
TEST(Formatter, MacrosOfNumbersExpressionsAndTermsKeepTheirNames) {
    const std::string text =
        "#define N 3\n"
        "#define HALF 1/2\n"
        "#define SUM (1+2)\n"
        "#define LEAF move(1,0,0)   sphere\n"
        "#define PAIR (sphere | cube)\n"
        "{n=N; k=(HALF)*2; m = SUM*4} S\n"
        "S if(n>0,2,1)\n"
        "1: S -> LEAF | move(1,0,0) PAIR\n"
        "2: S -> {n=n-1} uscale(HALF) S\n";
    const std::string expected =
        "#define N 3\n"
        "#define HALF 1/2\n"
        "#define SUM (1+2)\n"
        "#define LEAF move(1,0,0)   sphere\n"
        "#define PAIR (sphere | cube)\n"
        "{n = N; k = (HALF) * 2; m = SUM * 4} S\n"
        "S if(n > 0, 2, 1)\n"
        "1: S -> LEAF ∪ move(1, 0, 0) PAIR\n"
        "2: S -> {n = n - 1} uscale(HALF) S\n";
    expectFormatted(text, expected);
}

// A use that is part of a construct (a prefix without its operand, an operand of a
// tighter operator) or that expands to nothing cannot be printed as its name, and a
// #define inside a statement cannot be printed as written: the file is refused with the
// place, and nothing is lost.
TEST(Formatter, AMacroThatIsNotAWholeConstructIsRefused) {
    struct Case {
        const char* text;
        const char* name;
        const char* where;
    };
    for (const Case& c : {Case{"#define PART move(1,0,0)\nPART sphere\n", "PART", "2:1"},
                          Case{"#define SUM 1+2\n{n = SUM*2} sphere\n", "SUM", "2:6"},
                          Case{"#define NONE\nsphere NONE\n", "NONE", "2:8"}}) {
        SCOPED_TRACE(c.text);
        Diagnostics diags;
        EXPECT_FALSE(formatScene("m.pcsg", c.text, diags));
        const std::string errors = diags.format();
        EXPECT_NE(errors.find(fmt::format("m.pcsg:{}: error: pcsg fmt cannot keep this use of "
                                          "macro '{}'",
                                          c.where, c.name)),
                  std::string::npos)
            << errors;
    }
    Diagnostics diags;
    EXPECT_FALSE(formatScene("d.pcsg", "{a = 1\n#define X 2\nb = X} sphere\n", diags));
    EXPECT_NE(diags.format().find("d.pcsg:2:1: error: pcsg fmt cannot format a #define inside a "
                                  "statement"),
              std::string::npos)
        << diags.format();
}

// The printer marks breaks and indents with the control characters 0x01 to 0x04, so a
// comment that holds one is refused rather than broken apart (found by the parser's
// libFuzzer target, which formats every scene that compiles).
TEST(Formatter, ACommentWithAMarkerCharacterIsRefused) {
    const std::string text = "{n = 1 // a \x01 b\n  k = 2} sphere\n";
    Diagnostics diags;
    EXPECT_FALSE(formatScene("c.pcsg", text, diags));
    EXPECT_NE(diags.format().find("c.pcsg:1:13: error: pcsg fmt cannot format a comment with the "
                                  "control character 0x01"),
              std::string::npos)
        << diags.format();
    EXPECT_EQ(format("{n = 1 // a \x05 b\n  k = 2} sphere\n"),
              "{\n    n = 1 // a \x05 b\n    k = 2\n} sphere\n");
}

TEST(Formatter, CommentsSurvive) {
    const std::string text =
        "// header\n"
        "/* block\n   comment */\n"
        "\n"
        "{c=3} S // axiom\n"
        "S if(c>0,2,1) /* selection */\n"
        "1: S -> sphere\n"
        "// before rule 2\n"
        "2: S -> {c=c-1} (move(1,0,0) S | // inside\n"
        "    move(-1,0,0) S)\n"
        "// the end\n";
    const std::string expected =
        "// header\n"
        "/* block\n   comment */\n"
        "\n"
        "{c = 3} S // axiom\n"
        "S if(c > 0, 2, 1) /* selection */\n"
        "1: S -> sphere\n"
        "// before rule 2\n"
        "// inside\n"
        "2: S -> {c = c - 1} (move(1, 0, 0) S ∪ move(-1, 0, 0) S)\n"
        "// the end\n";
    EXPECT_EQ(format(text), expected);
    EXPECT_EQ(format(expected), expected);
}

TEST(Formatter, CommentsInACNodeStayWithTheirAssignments) {
    const std::string text =
        "sphere ∪ {   n = 2;   // count\n"
        "    r = 0.5;  /* radius */\n"
        "    // the last one\n"
        "    k = n*r\n"
        "    // after all\n"
        "} S\n"
        "S if(n > 0, 2, 1)\n"
        "1: S -> uscale(r) sphere\n"
        "2: S -> {n = n - 1} move(k, 0, 0) S\n";
    const std::string expected =
        "sphere ∪ {\n"
        "    n = 2 // count\n"
        "    r = 0.5 /* radius */\n"
        "    // the last one\n"
        "    k = n * r\n"
        "    // after all\n"
        "} S\n"
        "S if(n > 0, 2, 1)\n"
        "1: S -> uscale(r) sphere\n"
        "2: S -> {n = n - 1} move(k, 0, 0) S\n";
    expectFormatted(text, expected);
}

TEST(Formatter, CommentsInADirectiveStayWithTheirItems) {
    const std::string text =
        "camera {\n  location <1,2,3> // where\n  // what to look at\n  look_at <0,0,0>\n"
        "  angle 30 /* wide */\n}\nsphere\n";
    const std::string expected =
        "camera {\n"
        "    location <1, 2, 3> // where\n"
        "    // what to look at\n"
        "    look_at <0, 0, 0>\n"
        "    angle 30 /* wide */\n"
        "}\n"
        "sphere\n";
    EXPECT_EQ(format(text), expected);
    EXPECT_EQ(format(expected), expected);
}

// Section 10's light items: flags alone, area_light's values after commas, and fog.
TEST(Formatter, LightFlagsAreaLightAndFog) {
    const std::string messy =
        "light{position<1,2,3>;spotlight point_at <0,0,0>,radius 10\n tightness 2}\n"
        "light { area_light <1,0,0> , <0,1,0>,4,2 adaptive 1 jitter\nshadowless }\n"
        "fog{fog_type 2 distance 3,color <1,1,1> fog_alt 0.5}\n"
        "sphere\n";
    const std::string expected =
        "light { position <1, 2, 3>  spotlight  point_at <0, 0, 0>  radius 10  tightness 2 }\n"
        "light { area_light <1, 0, 0>, <0, 1, 0>, 4, 2  adaptive 1  jitter  shadowless }\n"
        "fog { fog_type 2  distance 3  color <1, 1, 1>  fog_alt 0.5 }\n"
        "sphere\n";
    EXPECT_EQ(format(messy), expected);
    EXPECT_EQ(format(expected), expected);
}

// Written by hand: what each messy spelling becomes.
TEST(Formatter, MessyInputBecomesCanonical) {
    const std::string messy =
        "camera{location<4,-6,3>;look_at <0,0,0.5>}\n"
        "light   { position <1,2,3>\n color <1,1,1> }\n"
        "background<0.1,0.2,0.3>\n"
        "material   m {color <1,0,0>,phong 0.5}\n"
        "settings { seed 7 }\n"
        "{n=2;k = 1.50} paint( m ) T ; T if(n>0,2,1)\n"
        "1:T->torus(1,0.25)&cube\\cylinder|D\n"
        "2: T → (A|B) & ((A & B) & C) | flipyz {n=n-1} uscale(.5) T\n"
        "A = scale(1,2,3)sphere\n"
        "B=translate( 1 , 0 , -2e-1 ) cube\n"
        "C = rotz( -(1+2)*3 - -k ^ 2 ^ (1 - k) ) sphere\n"
        "D = move(2 * (3 - 1) / 4, (1 < 2) && !(2 >= 3) || 0, (k - 1) - 1) sphere\n";
    const std::string expected =
        "camera { location <4, -6, 3>  look_at <0, 0, 0.5> }\n"
        "light { position <1, 2, 3>  color <1, 1, 1> }\n"
        "background <0.1, 0.2, 0.3>\n"
        "material m { color <1, 0, 0>  phong 0.5 }\n"
        "settings { seed 7 }\n"
        "{n = 2; k = 1.50} paint(m) T\n"
        "T if(n > 0, 2, 1)\n"
        "1: T -> torus(1, 0.25) ∩ cube \\ cylinder ∪ D\n"
        "2: T -> (A ∪ B) ∩ ((A ∩ B) ∩ C) ∪ flipyz {n = n - 1} uscale(.5) T\n"
        "A = scale(1, 2, 3) sphere\n"
        "B = translate(1, 0, -2e-1) cube\n"
        "C = rotz(-(1 + 2) * 3 - -k^2^(1 - k)) sphere\n"
        "D = move(2 * (3 - 1) / 4, 1 < 2 && !(2 >= 3) || 0, (k - 1) - 1) sphere\n";
    expectFormatted(messy, expected);
}

// A material's blocks (section 10): each item on one line when it fits, else one per line;
// numbers in a row keep their comma, so that `{ 0.1, -0.05 }` stays two numbers.
TEST(Formatter, MaterialBlocks) {
    const std::string messy =
        "material w {pigment{color rgbf<0.3,0.5,0.6,0>}\n"
        " finish{reflection{0.1,-0.05+0.2 fresnel on}specular 0.4;metallic}interior{ior 1.33}}\n"
        "material s { finish { phong 0.5 } }\n"
        "paint(w) sphere ∪ paint(s) cube\n";
    const std::string expected =
        "material w {\n"
        "    pigment { color rgbf <0.3, 0.5, 0.6, 0> }\n"
        "    finish { reflection { 0.1, -0.05 + 0.2 fresnel on } specular 0.4 metallic }\n"
        "    interior { ior 1.33 }\n"
        "}\n"
        "material s { finish { phong 0.5 } }\n"
        "paint(w) sphere ∪ paint(s) cube\n";
    expectFormatted(messy, expected);
    const auto b = testing::compile(expected);
    ASSERT_TRUE(b->graph) << b->errors();
    EXPECT_EQ(b->graph->materials[1].minReflection(), 0.1);
}

// sky_sphere (section 10) is a directive whose body is a pigment block; patterns and
// colour maps keep their items and brackets.
TEST(Formatter, SkySphereAndPatterns) {
    const std::string messy =
        "sky_sphere{pigment{gradient z color_map{[0 rgb<1,1,1>][1 rgb<0.2,0.3,0.8>]}}}\n"
        "material m {pigment{checker rgb 1,rgb 0 scale 2}normal{bumps 0.4 scale 0.1}}\n"
        "paint(m) sphere\n";
    const std::string expected =
        "sky_sphere { pigment { gradient z color_map { [0 rgb <1, 1, 1>] [1 rgb <0.2, 0.3, "
        "0.8>] } } }\n"
        "material m {\n"
        "    pigment { checker rgb 1 rgb 0 scale 2 }\n"
        "    normal { bumps 0.4 scale 0.1 }\n"
        "}\n"
        "paint(m) sphere\n";
    const std::string out = format(messy);
    EXPECT_EQ(format(out), out);
    const auto b = expectSameGraphOf(messy, out);
    ASSERT_TRUE(b->graph);
    EXPECT_TRUE(b->graph->scene.skySphere);
    EXPECT_EQ(b->graph->scene.skyPigment.colourMap.size(), 2u);
    EXPECT_EQ(b->graph->materials[1].pigment.listColours.size(), 2u);
    (void)expected;
}

TEST(Formatter, LongRulesBreakAfterUnion) {
    std::string rule = "{c=2} S\nS if(c > 0, 2, 1)\n1: S -> sphere\n2: S -> {c=c-1} (";
    for (int k = 0; k < 8; ++k) rule += (k ? " ∪ " : "") + std::string("move(0.25,0.5,0.75) S");
    rule += ")\n";
    const std::string out = format(rule);
    const std::string expected =
        "{c = 2} S\nS if(c > 0, 2, 1)\n1: S -> sphere\n"
        "2: S -> {c = c - 1} (move(0.25, 0.5, 0.75) S ∪ move(0.25, 0.5, 0.75) S ∪ "
        "move(0.25, 0.5, 0.75) S ∪\n"
        "    move(0.25, 0.5, 0.75) S ∪ move(0.25, 0.5, 0.75) S ∪ move(0.25, 0.5, 0.75) S ∪\n"
        "    move(0.25, 0.5, 0.75) S ∪ move(0.25, 0.5, 0.75) S)\n";
    EXPECT_EQ(out, expected);
    EXPECT_EQ(format(out), out);
}

// Spellings the scenes do not use: notation B with `=` in a condition, grouped runs of
// one operator, unary operators, calls, empty C-nodes, the ASCII operators.
TEST(Formatter, TrickySpellingsKeepTheirGraph) {
    const std::string text =
        "w:  S(6)   /* axiom */ ; // after a semicolon\n"
        "p1: S(c) : c = 0 -> tetrahedron\n"
        "p2: S(c) : c > 0 -> move(0.5,0.5,0.5) uscale(0.5) S(c-1) | ( ( T(c) ) ) & sphere \\ "
        "cube \\ (cube \\ cube) | ((S(c-1) | S(c-1)) | S(c-1))\n"
        "p3: T(x) -> {} {a=+x , b=!x} rot(1,2,3,e*pi) zshear(1, 2) matrix(1,0,0, 0,1,0, "
        "0,0,1, 0,0,0) scale(-x^2, (-x)^2, 2^-x) sphere\n";
    const std::string once = format(text);
    EXPECT_EQ(format(once), once);
    EXPECT_NE(once.find("p1: S(c) : c = 0 -> tetrahedron\n"), std::string::npos) << once;
    EXPECT_NE(once.find("((S(c - 1) ∪ S(c - 1)) ∪ S(c - 1))"), std::string::npos) << once;
    EXPECT_NE(once.find("w: S(6) /* axiom */ // after a semicolon\n"), std::string::npos) << once;
    expectSameGraphOf(text, once);
}

// An operand goes to the next line whole; a C-node breaks at its `;` only when one
// operand is too long for a line, and a short head is not broken off.
TEST(Formatter, OperandsMoveWholeAndCNodesBreakLast) {
    const std::string text =
        "material meadow {}\nSTEM = sphere\n"
        "paint(meadow) plane | {np=21;p=np;rs=0.035;lean=3.5;ll=0.75} ({n=6;l=0.75} STEM | "
        "{n=5;l=0.68} move(-1.1,0.5,0) rotz(60) STEM | {n=4;l=0.62} move(1.0,0.7,0) rotz(200) "
        "STEM)\n";
    const std::string expected =
        "material meadow {}\nSTEM = sphere\n"
        "paint(meadow) plane ∪ {np = 21; p = np; rs = 0.035; lean = 3.5; ll = 0.75} "
        "({n = 6; l = 0.75} STEM ∪\n"
        "    {n = 5; l = 0.68} move(-1.1, 0.5, 0) rotz(60) STEM ∪\n"
        "    {n = 4; l = 0.62} move(1.0, 0.7, 0) rotz(200) STEM)\n";
    EXPECT_EQ(format(text), expected);
    EXPECT_EQ(format(expected), expected);
}

TEST(Formatter, ErrorsGiveNoOutput) {
    Diagnostics diags;
    EXPECT_FALSE(formatScene("bad.pcsg", "S ∪\n", diags));
    EXPECT_TRUE(diags.hasErrors());
}

}  // namespace
}  // namespace pcsg
