// `pcsg graph` run as a program: the DOT of the Sierpinski system in both notations has
// one S-node with its two rule edges and the four back edges of figure 3b; -o writes
// DOT or, through Graphviz, SVG; a missing `dot` gets an install hint.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <set>

#include "cli_test_util.h"

namespace pcsg::tools {
namespace {

using testing::pcsg;
using testing::TempDir;

struct ParsedDot {
    std::set<std::string> selectNodes;  // ids of the S-nodes (drawn with peripheries=2)
    std::map<std::string, std::string> labels;
    struct Edge {
        std::string from, to, attrs;
    };
    std::vector<Edge> edges;
};

ParsedDot parseDot(const std::string& dot) {
    ParsedDot p;
    const std::regex node(R"re(^\s*(n\d+) \[label="((?:[^"\\]|\\.)*)", (.*)\];$)re");
    const std::regex edge(R"(^\s*(\w+) -> (\w+)(?: \[(.*)\])?;$)");
    std::istringstream in(dot);
    std::string line;
    std::smatch m;
    while (std::getline(in, line)) {
        if (std::regex_match(line, m, node)) {
            p.labels[m[1]] = m[2];
            if (m[3].str().find("peripheries=2") != std::string::npos) p.selectNodes.insert(m[1]);
        } else if (std::regex_match(line, m, edge)) {
            p.edges.push_back({m[1], m[2], m[3]});
        }
    }
    return p;
}

void expectFigure3b(const std::string& dot) {
    const ParsedDot p = parseDot(dot);
    ASSERT_EQ(p.selectNodes.size(), 1u) << dot;
    const std::string s = *p.selectNodes.begin();
    size_t ruleEdges = 0, backEdges = 0, otherEdgesIntoS = 0;
    for (const auto& e : p.edges) {
        if (e.from == s) ++ruleEdges;
        if (e.to != s) {
            EXPECT_EQ(e.attrs.find("dashed"), std::string::npos) << "back edge not into S";
            continue;
        }
        const bool back = e.attrs.find("style=dashed") != std::string::npos &&
                          e.attrs.find("constraint=false") != std::string::npos;
        (back ? backEdges : otherEdgesIntoS)++;
    }
    EXPECT_EQ(ruleEdges, 2u) << dot;
    EXPECT_EQ(backEdges, 4u) << dot;
    EXPECT_EQ(otherEdgesIntoS, 1u) << dot;  // from the axiom's C-node: S hangs below it
    // Every node is declared once; every edge joins declared nodes (or the axiom marker).
    for (const auto& e : p.edges) {
        EXPECT_TRUE(e.from == "axiom" || p.labels.count(e.from)) << e.from;
        EXPECT_TRUE(p.labels.count(e.to)) << e.to;
    }
    const std::regex decl(R"(\n\s*(n\d+) \[label=)");
    std::set<std::string> seen;
    for (auto it = std::sregex_iterator(dot.begin(), dot.end(), decl); it != std::sregex_iterator();
         ++it)
        EXPECT_TRUE(seen.insert((*it)[1]).second) << "declared twice: " << (*it)[1];
}

TEST(GraphCommand, SierpinskiHasOneSNodeTwoRulesAndFourBackEdges) {
    TempDir dir;
    const ChildResult r = pcsg({"graph", dir.write("fig3a.pcsg", testing::kSierpinskiA)});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err, "");
    expectFigure3b(r.out);
    const ParsedDot p = parseDot(r.out);
    EXPECT_EQ(p.labels.at(*p.selectNodes.begin()), "S\\nif(c > 0, 2, 1)");
    std::multiset<std::string> labels;
    for (const auto& [id, label] : p.labels) labels.insert(label);
    EXPECT_EQ(labels.count("uscale(0.5)"), 4u) << r.out;
    EXPECT_EQ(labels.count("move(-0.5, -0.5, 0.5)"), 1u) << r.out;
    EXPECT_EQ(labels.count("{c = c-1}"), 1u) << r.out;
    EXPECT_EQ(labels.count("{c = 6}"), 1u) << r.out;
    EXPECT_EQ(labels.count("tetrahedron"), 1u) << r.out;
}

TEST(GraphCommand, NotationBGivesTheSameShape) {
    TempDir dir;
    const ChildResult r = pcsg({"graph", dir.write("fig2.pcsg", testing::kSierpinskiB)});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    expectFigure3b(r.out);
    const ParsedDot p = parseDot(r.out);
    EXPECT_EQ(p.labels.at(*p.selectNodes.begin()), "S(c)");
}

TEST(GraphCommand, TheDefaultSceneHasFigure3bsShape) {
    const ChildResult r = pcsg({"graph", std::string(PCSG_SCENES_DIR) + "/sierpinski.pcsg"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    expectFigure3b(r.out);
}

TEST(GraphCommand, OutputFileGetsTheSameDot) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", testing::kSierpinskiA);
    const ChildResult toStdout = pcsg({"graph", scene});
    const ChildResult toFile = pcsg({"graph", scene, "-o", dir.file("s.dot")});
    ASSERT_EQ(toFile.exitCode, 0) << toFile.err;
    EXPECT_EQ(toFile.out, "");
    EXPECT_EQ(testing::readFile(dir.file("s.dot")), toStdout.out);
}

TEST(GraphCommand, SvgThroughGraphviz) {
    if (!inPath("dot")) GTEST_SKIP() << "Graphviz's dot is not installed";
    TempDir dir;
    const ChildResult r =
        pcsg({"graph", dir.write("s.pcsg", testing::kSierpinskiA), "-o", dir.file("s.svg")});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string svg = testing::readFile(dir.file("s.svg"));
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("uscale(0.5)"), std::string::npos);
    EXPECT_NE(svg.find("stroke-dasharray"), std::string::npos);  // the back edges
}

TEST(GraphCommand, MissingGraphvizGetsAnInstallHint) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", testing::kSierpinskiA);
    // An empty PATH: pcsg is started by its full path, but cannot find `dot`.
    const ChildResult r = runChild(
        {"env", "PATH=" + dir.path(), PCSG_EXECUTABLE, "graph", scene, "-o", dir.file("s.svg")});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("apt-get install graphviz"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("s.svg")));
    // DOT output needs no Graphviz.
    const ChildResult dot = runChild(
        {"env", "PATH=" + dir.path(), PCSG_EXECUTABLE, "graph", scene, "-o", dir.file("s.dot")});
    EXPECT_EQ(dot.exitCode, 0) << dot.err;
}

TEST(GraphCommand, BadSceneAndBadOutputNames) {
    TempDir dir;
    const ChildResult bad = pcsg({"graph", dir.write("bad.pcsg", "sphere ∪ ∪ cube\n")});
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_EQ(bad.out, "");
    EXPECT_NE(bad.err.find("bad.pcsg:1:"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find(": error: "), std::string::npos) << bad.err;

    const std::string scene = dir.write("s.pcsg", testing::kSierpinskiA);
    const ChildResult ext = pcsg({"graph", scene, "-o", dir.file("s.txt")});
    EXPECT_EQ(ext.exitCode, 2);
    EXPECT_NE(ext.err.find(".dot, .gv, .svg, .png or .pdf"), std::string::npos) << ext.err;

    const ChildResult unwritable = pcsg({"graph", scene, "-o", dir.file("no/such/dir/s.dot")});
    EXPECT_EQ(unwritable.exitCode, 2);
    EXPECT_NE(unwritable.err.find("cannot write"), std::string::npos) << unwritable.err;

    EXPECT_EQ(pcsg({"graph", dir.file("missing.pcsg")}).exitCode, 1);
}

}  // namespace
}  // namespace pcsg::tools
