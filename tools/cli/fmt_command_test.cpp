// `pcsg fmt` run as a program: standard output, -i in place (atomically, nothing left
// behind), --check, compile errors and macros it cannot keep leave the file alone, bad
// command lines.
#include <gtest/gtest.h>

#include "cli_test_util.h"

namespace pcsg::tools {
namespace {

using testing::pcsg;
using testing::readFile;
using testing::TempDir;

const char* kMessy =
    "{c=2} S // axiom\nS if(c>0,2,1)\n1: S->sphere\n2: S->{c=c-1} (S|move(1,0,0)S)\n";
const char* kCanonical =
    "{c = 2} S // axiom\nS if(c > 0, 2, 1)\n1: S -> sphere\n"
    "2: S -> {c = c - 1} (S ∪ move(1, 0, 0) S)\n";

TEST(FmtCommand, PrintsTheCanonicalLayoutAndLeavesTheFileAlone) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kMessy);
    const ChildResult r = pcsg({"fmt", scene});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, kCanonical);
    EXPECT_EQ(readFile(scene), kMessy);
}

// --check writes nothing and says by its exit status whether the file is canonical: 0
// yes, 3 no (with the first line that would change), 1 when it does not compile.
TEST(FmtCommand, CheckSaysWhetherTheFileIsCanonicalAndWritesNothing) {
    TempDir dir;
    const std::string canonical = dir.write("c.pcsg", kCanonical);
    const ChildResult ok = pcsg({"fmt", canonical, "--check"});
    EXPECT_EQ(ok.exitCode, 0) << ok.err;
    EXPECT_EQ(ok.out + ok.err, "");
    const std::string messy = dir.write("m.pcsg", kMessy);
    const ChildResult bad = pcsg({"fmt", messy, "--check"});
    EXPECT_EQ(bad.exitCode, 3);
    EXPECT_EQ(bad.out, "");
    EXPECT_EQ(bad.err, messy + ":1: not in pcsg fmt's layout from this line on\n");
    EXPECT_EQ(readFile(messy), kMessy);
    // (the first two lines canonical, the third not)
    const std::string third = dir.write("t.pcsg",
                                        "{c = 2} S // axiom\nS if(c > 0, 2, 1)\n1: S->sphere\n"
                                        "2: S -> {c = c - 1} (S ∪ move(1, 0, 0) S)\n");
    EXPECT_EQ(pcsg({"fmt", third, "--check"}).err,
              third + ":3: not in pcsg fmt's layout from this line on\n");
    const std::string broken = dir.write("b.pcsg", "S ->\n");
    EXPECT_EQ(pcsg({"fmt", broken, "--check"}).exitCode, 1);
    EXPECT_EQ(pcsg({"fmt", messy, "--check", "-i"}).exitCode, 2);  // (a bad command line)
    EXPECT_EQ(readFile(messy), kMessy);
    EXPECT_EQ(testing::filesIn(dir.path()),
              (std::vector<std::string>{"b.pcsg", "c.pcsg", "m.pcsg", "t.pcsg"}));
}

TEST(FmtCommand, InPlaceRewritesTheFileAndLeavesNothingBehind) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kMessy);
    const ChildResult r = pcsg({"fmt", scene, "-i"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(readFile(scene), kCanonical);
    EXPECT_EQ(testing::filesIn(dir.path()), std::vector<std::string>{"s.pcsg"});
    EXPECT_EQ(pcsg({"fmt", scene, "-i"}).exitCode, 0);  // already canonical
    EXPECT_EQ(readFile(scene), kCanonical);
}

TEST(FmtCommand, ACompileErrorExitsOneAndWritesNothing) {
    TempDir dir;
    const std::string bad = "{c=2} S\nS if(c>0,2,1)\n1: S -> sphere ∪\n";
    const std::string scene = dir.write("bad.pcsg", bad);
    const ChildResult r = pcsg({"fmt", scene, "-i"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("error:"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(readFile(scene), bad);
    EXPECT_EQ(testing::filesIn(dir.path()), std::vector<std::string>{"bad.pcsg"});
}

// A file with #define is formatted with its macros kept; one whose macro cannot be kept is
// refused, and left as it was.
TEST(FmtCommand, AFileWithDefineKeepsItsMacrosOrIsLeftAlone) {
    TempDir dir;
    const std::string scene = dir.write("m.pcsg", "#define BALL sphere\nBALL  |  cube\n");
    const ChildResult r = pcsg({"fmt", scene, "-i"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(readFile(scene), "#define BALL sphere\nBALL ∪ cube\n");
    const std::string part = "#define PART move(1,0,0)\nPART sphere\n";
    const std::string partial = dir.write("p.pcsg", part);
    const ChildResult p = pcsg({"fmt", partial, "-i"});
    EXPECT_EQ(p.exitCode, 1);
    EXPECT_NE(p.err.find("cannot keep this use of macro 'PART'"), std::string::npos) << p.err;
    EXPECT_EQ(readFile(partial), part);
}

// The formatted scene renders the same image, byte for byte.
TEST(FmtCommand, TheFormattedSceneRendersTheSameImage) {
    TempDir dir;
    for (const char* text : {testing::kSierpinskiA, testing::kSierpinskiB}) {
        const std::string scene = dir.write("s.pcsg", text);
        const ChildResult f = pcsg({"fmt", scene});
        ASSERT_EQ(f.exitCode, 0) << f.err;
        const std::string formatted = dir.write("f.pcsg", f.out);
        ASSERT_EQ(
            pcsg({"render", scene, "-o", dir.file("a.png"), "--width", "48", "--height", "36"})
                .exitCode,
            0);
        ASSERT_EQ(
            pcsg({"render", formatted, "-o", dir.file("b.png"), "--width", "48", "--height", "36"})
                .exitCode,
            0);
        const std::string a = readFile(dir.file("a.png"));
        EXPECT_FALSE(a.empty());
        EXPECT_EQ(a, readFile(dir.file("b.png")));
    }
}

TEST(FmtCommand, BadCommandLinesExitTwo) {
    EXPECT_EQ(pcsg({"fmt"}).exitCode, 2);
    EXPECT_EQ(pcsg({"fmt", "-", "-i"}).exitCode, 2);
    EXPECT_EQ(pcsg({"fmt", "a.pcsg", "--nope"}).exitCode, 2);
    const ChildResult help = pcsg({"fmt", "--help"});
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.out.find("#define"), std::string::npos) << help.out;
}

}  // namespace
}  // namespace pcsg::tools
