// Whatever the input, the compiler returns a graph or clean errors: it never crashes,
// hangs or exhausts the stack (docs/language.md section 8). Seeded, so failures reproduce.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "compiler.h"

namespace pcsg {
namespace {

// The graph's indices all point inside its arrays.
void expectWellFormed(const Graph& g) {
    ASSERT_LT(g.axiom, g.nodes.size());
    for (const Node& n : g.nodes) {
        ASSERT_LE(n.firstChild + n.childCount, g.edges.size());
        switch (n.kind) {
            case NodeKind::Select:
                ASSERT_LT(n.payload, g.modules.size());
                break;
            case NodeKind::Transform:
                ASSERT_LT(n.payload, g.transforms.size());
                break;
            case NodeKind::Calc:
                ASSERT_LT(n.payload, g.calcs.size());
                break;
            case NodeKind::Paint:
                ASSERT_LT(n.payload, g.materials.size());
                break;
            case NodeKind::Primitive:
                ASSERT_LT(n.payload, g.primitives.size());
                break;
            default:
                break;
        }
    }
    for (NodeId e : g.edges) ASSERT_LT(e, g.nodes.size());
    for (const Expr& e : g.exprs) {
        ASSERT_LE(e.begin, e.end);
        ASSERT_LE(e.end, g.code.size());
        ASSERT_GE(e.maxStack, 1u);
    }
    for (const Assignment& a : g.assignments) {
        ASSERT_LT(a.slot, g.slotCount());
        ASSERT_LT(a.value, g.exprs.size());
    }
    for (ExprId a : g.args) ASSERT_LT(a, g.exprs.size());
    for (const Module& m : g.modules) {
        ASSERT_LT(m.node, g.nodes.size());
        if (!m.notationB) {
            ASSERT_LT(m.select, g.exprs.size());
        }
    }
    ASSERT_GE(g.materials.size(), 1u);
    ASSERT_GE(g.scene.lights.size(), 1u);
}

void expectCleanResult(const std::string& text) {
    Diagnostics diags;
    const auto g = compileSource("fuzz.pcsg", text, diags);
    if (g) {
        EXPECT_FALSE(diags.hasErrors());
        expectWellFormed(*g);
    } else {
        ASSERT_TRUE(diags.hasErrors());
        EXPECT_LE(diags.errors().size(), Diagnostics::kMaxErrors);
        const std::string out = diags.format();
        EXPECT_NE(out.find(": error: "), std::string::npos);
    }
}

TEST(Robustness, RandomBytes) {
    std::mt19937 rng(1234);
    for (int i = 0; i < 300; ++i) {
        std::string text(rng() % 4096, '\0');
        for (char& c : text) c = static_cast<char>(rng());
        expectCleanResult(text);
    }
}

TEST(Robustness, RandomTokenSoup) {
    // Sequences of the language's own words: they reach deep into the parser and builder.
    const char* words[] = {
        "S",       "T",        "c",     "d",        "x",         "1",      "2",          "0.5",
        ":",       "->",       "→",     "∪",        "|",         "∩",      "&",          "\\",
        "(",       ")",        "{",     "}",        "=",         "==",     "<",          ">",
        "+",       "-",        "*",     "/",        "^",         "!",      "&&",         "||",
        ",",       ";",        "\n",    "\n",       "if",        "rand",   "choose",     "sin",
        "min",     "move",     "rotz",  "uscale",   "flipxz",    "matrix", "sphere",     "tri1",
        "torus",   "triangle", "paint", "material", "camera",    "light",  "background", "settings",
        "<1,2,3>", "location", "angle", "seed",     "#define M", "M",      "p1",         "w",
        "pi",      "e"};
    const size_t n = sizeof(words) / sizeof(words[0]);
    std::mt19937 rng(99);
    for (int i = 0; i < 3000; ++i) {
        std::string text;
        const int len = 1 + static_cast<int>(rng() % 60);
        for (int k = 0; k < len; ++k) {
            text += words[rng() % n];
            text += ' ';
        }
        SCOPED_TRACE(text);
        expectCleanResult(text);
        if (testing::Test::HasFatalFailure()) return;
    }
}

TEST(Robustness, MutatedValidScenes) {
    const std::string base =
        "camera { location <4,-6,3> look_at <0,0,0.5> angle 40 }\n"
        "material red { color <1,0,0> phong 0.3 }\n"
        "#define HALF uscale(0.5)\n"
        "{c = 3} S ∪ w2\n"
        "S if(c > 0, 2, 1)\n"
        "1: S -> paint(red) tetrahedron\n"
        "2: S -> {c = c - 1} (move(0.5,0.5,0.5) HALF S ∪ move(-0.5,-0.5,0.5) HALF S)\n"
        "w2 = move(3,0,0) T(2)\n"
        "p1: T(n) : n > 0 -> rotz(30) T(n - 1) ∪ sphere\n"
        "p2: T(n) -> torus(1, 0.25)\n";
    {
        Diagnostics d;
        ASSERT_TRUE(compileSource("base.pcsg", base, d)) << d.format();
    }
    std::mt19937 rng(7);
    for (int i = 0; i < 1500; ++i) {
        std::string text = base;
        const int edits = 1 + static_cast<int>(rng() % 4);
        for (int k = 0; k < edits; ++k) {
            const size_t at = rng() % text.size();
            switch (rng() % 3) {
                case 0:
                    text.erase(at, 1 + rng() % 3);
                    break;
                case 1:
                    text.insert(at, 1, "(){}<>,;:=|&\\-+*/^!#\n0aS"[rng() % 25]);
                    break;
                default:
                    text[at] = static_cast<char>(rng());
                    break;
            }
        }
        SCOPED_TRACE(text);
        expectCleanResult(text);
        if (testing::Test::HasFatalFailure()) return;
    }
}

TEST(Robustness, EmptyInputsGetOneError) {
    for (const std::string& text :
         {std::string(), std::string(" \n\t\r\n"), std::string("// nothing\n/* at all */"),
          std::string("\xEF\xBB\xBF")}) {
        Diagnostics d;
        EXPECT_FALSE(compileSource("e.pcsg", text, d));
        ASSERT_EQ(d.errors().size(), 1u);
        EXPECT_EQ(d.errors()[0].message.rfind("the file is empty", 0), 0u) << d.errors()[0].message;
    }
}

TEST(Robustness, TooManyErrorsStopAtTheLimit) {
    std::string text;
    for (int i = 0; i < 500; ++i) text += "sphere )\n";
    Diagnostics d;
    EXPECT_FALSE(compileSource("many.pcsg", text, d));
    ASSERT_EQ(d.errors().size(), Diagnostics::kMaxErrors);
    EXPECT_NE(d.errors().back().message.find("too many errors"), std::string::npos);
}

// Once the list of errors is full, an error adds nothing to it, yet the steps that ask
// "did this report an error" must still see it: a directive value that reads a parameter
// was evaluated without a frame here and crashed (found by the parser fuzzer).
TEST(Robustness, ErrorsPastTheLimitStillCount) {
    std::string text = "{n = 1} S\nS 1\n1: S -> sphere\n";
    for (int i = 0; i < 60; ++i) text += "light { position <10, n - 20, 30>  color <1, 1, 1> }\n";
    Diagnostics d;
    EXPECT_FALSE(compileSource("full.pcsg", text, d));
    ASSERT_EQ(d.errors().size(), Diagnostics::kMaxErrors);
    EXPECT_EQ(d.count(), 60u);
    EXPECT_NE(d.errors().back().message.find("too many errors"), std::string::npos);
    EXPECT_NE(d.errors().front().message.find("constants, not parameters"), std::string::npos)
        << d.errors().front().message;
}

TEST(Robustness, ALargeGeneratedFileCompiles) {
    // About 2.5 MB: 16,000 modules of two rules each, chained, and as many definitions.
    std::string text = "{n = 1} M0\n";
    const int modules = 16000;
    for (int i = 0; i < modules; ++i) {
        text += fmt::format("M{} if(n > 0, 2, 1)\n", i);
        text += fmt::format("1: M{} -> d{}\n", i, i);
        if (i + 1 < modules)
            text +=
                fmt::format("2: M{} -> d{} ∪ {{n = n - 0.00001}} move(0, 0, 1.5) uscale(0.9) M{}\n",
                            i, i, i + 1);
        else
            text += fmt::format("2: M{} -> cube\n", i);
        text += fmt::format("d{} = move({}, 0, 0) (sphere ∩ cube) \\ cylinder\n", i, i % 7);
    }
    ASSERT_GT(text.size(), 2u << 20);
    Diagnostics d;
    const auto g = compileSource("large.pcsg", text, d);
    ASSERT_TRUE(g) << d.format().substr(0, 1000);
    EXPECT_EQ(g->modules.size(), static_cast<size_t>(modules));
    expectWellFormed(*g);
}

TEST(Robustness, FilesOverTheSizeLimitAreRejectedWithoutReading) {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / fmt::format("pcsg_huge_{}.pcsg", ::getpid());
    { std::ofstream out(path); }
    std::filesystem::resize_file(path, (size_t(300) << 20));  // sparse: no disk space used
    std::string storage;
    Diagnostics d;
    EXPECT_FALSE(compileFile(path.string(), storage, d));
    std::filesystem::remove(path);
    ASSERT_EQ(d.errors().size(), 1u);
    EXPECT_NE(d.errors()[0].message.find("the file is too large"), std::string::npos);
    EXPECT_TRUE(storage.empty());
    // No source line is quoted: one line of output.
    const std::string out = d.format();
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

TEST(Robustness, UnreadableFilesAreDiagnostics) {
    std::string storage;
    Diagnostics d;
    EXPECT_FALSE(compileFile("/nonexistent/dir/scene.pcsg", storage, d));
    ASSERT_EQ(d.errors().size(), 1u);
    EXPECT_EQ(
        d.format(),
        "/nonexistent/dir/scene.pcsg: error: cannot open the file: No such file or directory\n");
    Diagnostics d2;
    EXPECT_FALSE(compileFile(std::filesystem::temp_directory_path().string(), storage, d2));
    ASSERT_EQ(d2.errors().size(), 1u);
    EXPECT_NE(d2.errors()[0].message.find("cannot read the file"), std::string::npos);
}

TEST(Robustness, ALongLineIsShownAroundTheColumn) {
    std::string text = "S 1 + ";
    text.append(500000, ' ');
    text += "$ + 2\n1: S -> sphere\nS\n";
    Diagnostics d;
    EXPECT_FALSE(compileSource("long.pcsg", text, d));
    ASSERT_EQ(d.errors().size(), 1u);
    const std::string out = d.format();
    EXPECT_LT(out.size(), 600u) << out.substr(0, 600);
    EXPECT_EQ(out.rfind("long.pcsg:1:500007: error: unexpected character '$'", 0), 0u)
        << out.substr(0, 300);
    // The caret is under the '$' in the shown window.
    std::vector<std::string> lines;
    for (size_t p = 0, q; p < out.size(); p = q + 1) {
        q = out.find('\n', p);
        lines.push_back(out.substr(p, q - p));
    }
    ASSERT_GE(lines.size(), 3u);
    const size_t caret = lines[2].find('^');
    ASSERT_NE(caret, std::string::npos);
    EXPECT_EQ(lines[1][caret], '$');
    EXPECT_NE(lines[1].find("..."), std::string::npos);
}

}  // namespace
}  // namespace pcsg
