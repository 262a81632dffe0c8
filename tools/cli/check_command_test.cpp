// `pcsg check` run as a program: exit status, diagnostics on standard error, the
// --stats and --json figures, and clean errors for files that are not scenes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace pcsg::tools {
namespace {

using testing::pcsg;
using testing::TempDir;

size_t countOf(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(CheckCommand, AGoodSceneExitsZeroAndSaysOk) {
    TempDir dir;
    const std::string scene = dir.write("fig3a.pcsg", testing::kSierpinskiA);
    const ChildResult r = pcsg({"check", scene});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_NE(r.out.find(scene + ": ok (1 module"), std::string::npos) << r.out;
}

TEST(CheckCommand, ABadSceneExitsOneWithEveryDiagnostic) {
    TempDir dir;
    // Two independent errors in two statements: both must be reported.
    const std::string scene = dir.write("bad.pcsg",
                                        "{c=6} S\n"
                                        "S if(c > 0, 2, 1)\n"
                                        "1: S -> tetrahedron\n"
                                        "2: S -> {c=c-1} uscale(0.5) (S ∪ )\n"
                                        "material m { color <1,1,1> shininess 3 }\n");
    const ChildResult r = pcsg({"check", scene});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind(scene + ":4:", 0), 0u) << r.err;  // the first line names line 4
    EXPECT_NE(r.err.find(scene + ":5:"), std::string::npos) << r.err;
    EXPECT_EQ(countOf(r.err, ": error: "), 2u) << r.err;
    // The source line and a caret under the column follow each message.
    EXPECT_NE(r.err.find("\n  2: S -> {c=c-1} uscale(0.5) (S ∪ )\n"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("^"), std::string::npos);
}

TEST(CheckCommand, StatsCountTheNodesByKind) {
    TempDir dir;
    const ChildResult r = pcsg({"check", "--stats", dir.write("s.pcsg", testing::kSierpinskiA)});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* line : {"S-nodes (select)        1\n", "primitives              1\n",
                             "∪ nodes (union)         1\n", "∩ nodes (intersection)  0\n",
                             "modules                 1\n", "parameters              1\n"})
        EXPECT_NE(r.out.find(line), std::string::npos) << "missing: " << line << "\n" << r.out;
    EXPECT_NE(r.out.find("graph bytes             "), std::string::npos) << r.out;
}

TEST(CheckCommand, JsonHasTheSameFigures) {
    TempDir dir;
    const ChildResult r = pcsg({"check", "--json", dir.write("s.pcsg", testing::kSierpinskiA)});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["ok"].get<bool>());
    const auto& n = j["nodes"];
    EXPECT_EQ(n["select"], 1);
    EXPECT_EQ(n["union"], 1);
    EXPECT_EQ(n["primitive"], 1);
    EXPECT_EQ(n["intersection"], 0);
    EXPECT_EQ(n["difference"], 0);
    EXPECT_EQ(n["paint"], 0);
    EXPECT_GE(n["calc"], 2);       // {c=6} and {c=c-1}
    EXPECT_GE(n["transform"], 4);  // four moves and four uscales, unless folded
    int sum = 0;
    for (const char* k : {"select", "transform", "calc", "paint", "union", "intersection",
                          "difference", "primitive"})
        sum += n[k].get<int>();
    EXPECT_EQ(n["total"], sum);
    EXPECT_EQ(j["modules"], 1);
    EXPECT_EQ(j["parameters"], 1);
    EXPECT_GT(j["expressions"].get<int>(), 0);
    EXPECT_GT(j["graph_bytes"].get<int>(), 0);
    // --stats --json prints the same JSON.
    const ChildResult both = pcsg({"check", "--stats", "--json", dir.file("s.pcsg")});
    EXPECT_EQ(nlohmann::json::parse(both.out)["nodes"], n);
}

TEST(CheckCommand, JsonOfABadSceneSaysNotOk) {
    TempDir dir;
    const ChildResult r = pcsg({"check", "--json", dir.write("bad.pcsg", "sphere ∪\n")});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_FALSE(nlohmann::json::parse(r.out)["ok"].get<bool>());
    EXPECT_NE(r.err.find("error:"), std::string::npos);
}

TEST(CheckCommand, FilesThatAreNotScenesGetACleanError) {
    TempDir dir;
    const ChildResult missing = pcsg({"check", dir.file("nothere.pcsg")});
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_EQ(missing.err, dir.file("nothere.pcsg") +
                               ": error: cannot open the file: No such file or directory\n");

    const ChildResult directory = pcsg({"check", dir.path()});
    EXPECT_EQ(directory.exitCode, 1);
    EXPECT_EQ(directory.err, dir.path() + ": error: this is a directory, not a scene file\n");

    const ChildResult empty = pcsg({"check", dir.write("empty.pcsg", "")});
    EXPECT_EQ(empty.exitCode, 1);
    EXPECT_NE(empty.err.find("empty.pcsg:1:1: error: "), std::string::npos) << empty.err;

    const ChildResult garbage =
        pcsg({"check", dir.write("garbage.pcsg", std::string("\x00\xff\xfe{{((\x01", 9))});
    EXPECT_EQ(garbage.exitCode, 1);
    EXPECT_NE(garbage.err.find("garbage.pcsg:1:"), std::string::npos) << garbage.err;
}

TEST(CheckCommand, ReadsStandardInputForDash) {
    // runChild gives the program /dev/null as standard input: an empty scene.
    const ChildResult r = pcsg({"check", "-"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(r.err.rfind("<stdin>:1:1: error: the file is empty", 0), 0u) << r.err;
}

TEST(CheckCommand, UsageErrorsExitTwo) {
    EXPECT_EQ(pcsg({"check"}).exitCode, 2);
    EXPECT_EQ(pcsg({"check", "a.pcsg", "--no-such-flag"}).exitCode, 2);
    EXPECT_EQ(pcsg({"no-such-command"}).exitCode, 2);
    const ChildResult help = pcsg({"check", "--help"});
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.out.find("--stats"), std::string::npos);
}

TEST(CheckCommand, PcsgPrintsItsVersion) {
    // `pcsg --version` needs no subcommand, and names the project's version from CMake.
    const ChildResult r = pcsg({"--version"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, std::string("pcsg ") + PCSG_VERSION + "\n");
}

TEST(CheckCommand, TheDefaultSceneCompiles) {
    const std::string scene = std::string(PCSG_SCENES_DIR) + "/sierpinski.pcsg";
    const ChildResult r = pcsg({"check", "--json", scene});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["nodes"]["select"], 1);
}

}  // namespace
}  // namespace pcsg::tools
