// The shrinker (shrinker.h) against synthetic failures: a predicate stands for "the
// renderers disagree", so the tests know the minimal case the shrinker must reach.
#include "shrinker.h"

#include <gtest/gtest.h>

#include "formatter.h"
#include "generator.h"

namespace pcsg::fuzz {
namespace {

std::string format(const std::string& text) {
    Diagnostics diags;
    return formatScene("t.pcsg", text, diags).value_or("(does not compile)");
}

TEST(FuzzShrinker, CandidatesCompileAndAreSmallerSteps) {
    const std::string text =
        "light { position <1, 2, 3> }\n{d = 2} (S ∪ cube)\n"
        "S if(d > 0, 2, 1)\n1: S -> sphere\n"
        "2: S -> move(0.5, 0.25, 0) {d = d - 1} S ∪ rotz(33.3) cone\n";
    const std::vector<std::string> c = shrinkCandidates(text);
    ASSERT_FALSE(c.empty());
    for (const std::string& x : c) EXPECT_EQ(format(x), x);  // compiles, already formatted
    const auto has = [&](const std::string& s) {
        return std::find(c.begin(), c.end(), format(s)) != c.end();
    };
    EXPECT_TRUE(
        has("{d = 2} (S ∪ cube)\nS if(d > 0, 2, 1)\n1: S -> sphere\n"
            "2: S -> move(0.5, 0.25, 0) {d = d - 1} S ∪ rotz(33.3) cone\n"));  // the light
    EXPECT_TRUE(
        has("light { position <1, 2, 3> }\n{d = 2} (S ∪ cube)\nS if(d > 0, 2, 1)\n"
            "1: S -> sphere\n2: S -> move(0.5, 0.25, 0) {d = d - 1} S ∪ rotz(33) cone\n"));
    EXPECT_TRUE(
        has("light { position <1, 2, 3> }\n{d = 1} (S ∪ cube)\nS if(d > 0, 2, 1)\n"
            "1: S -> sphere\n2: S -> move(0.5, 0.25, 0) {d = d - 1} S ∪ rotz(33.3) cone\n"));
    // Dropping the module alone leaves a reference to it: not a candidate.
    EXPECT_FALSE(has("light { position <1, 2, 3> }\n{d = 2} (S ∪ cube)\n"));
}

TEST(FuzzShrinker, FirstDropsWhatTheAxiomNoLongerReaches) {
    const std::string text =
        "material a { diffuse 0.5 }\nmaterial b { diffuse 0.2 }\n"
        "{d = 2} paint(a) (T ∪ cube)\nT = U\nU = sphere\n"
        "S if(d > 0, 2, 1)\n1: S -> paint(b) sphere\n2: S -> {d = d - 1} S\n";
    const std::vector<std::string> c = shrinkCandidates(text);
    ASSERT_FALSE(c.empty());
    EXPECT_EQ(c.front(), format("material a { diffuse 0.5 }\n{d = 2} paint(a) (T ∪ cube)\n"
                                "T = U\nU = sphere\n"));
    // Nothing is unreached now: the first candidate edits a CSG node and keeps every
    // statement.
    const std::vector<std::string> next = shrinkCandidates(c.front());
    ASSERT_FALSE(next.empty());
    EXPECT_NE(next.front().find("material a"), std::string::npos) << next.front();
    EXPECT_NE(next.front().find("T = U\nU = "), std::string::npos) << next.front();
}

TEST(FuzzShrinker, ReducesAGeneratedSystemToTheFailingPart) {
    // "Fails" while the scene has a torus: the minimal case is the axiom reduced to
    // one torus, with the camera (which is never dropped) and nothing else.
    std::string text;
    for (uint64_t seed = 0; text.empty(); ++seed) {
        const std::string t = generateSystem(seed);
        if (t.find("torus(") != std::string::npos) text = t;
    }
    int calls = 0;
    const StillFails hasTorus = [&](const std::string& t) {
        ++calls;
        return t.find("torus") != std::string::npos;
    };
    const ShrinkResult r = shrinkSystem(text, hasTorus, {.maxTries = 5000});
    EXPECT_EQ(r.tries, calls);
    EXPECT_GT(r.accepted, 0);
    EXPECT_LT(r.text.size(), text.size() / 3);
    EXPECT_NE(r.text.find("torus"), std::string::npos);
    // Minimal: no one-step reduction keeps the torus.
    for (const std::string& c : shrinkCandidates(r.text))
        EXPECT_EQ(c.find("torus"), std::string::npos) << c;
    EXPECT_EQ(r.text.find("light"), std::string::npos);
    EXPECT_EQ(r.text.find("material"), std::string::npos);
}

TEST(FuzzShrinker, StopsAtItsBudgetAndKeepsAFailingText) {
    const std::string text = generateSystem(3);
    int calls = 0;
    const ShrinkResult r =
        shrinkSystem(text, [&](const std::string&) { return ++calls % 2 == 0; }, {.maxTries = 10});
    EXPECT_EQ(r.tries, 10);
    EXPECT_EQ(calls, 10);
    EXPECT_EQ(format(r.text), r.text);
}

TEST(FuzzShrinker, NothingToDoWhenNothingFails) {
    const std::string text = generateSystem(5);
    const ShrinkResult r = shrinkSystem(text, [](const std::string&) { return false; });
    EXPECT_EQ(r.accepted, 0);
    EXPECT_EQ(r.text, format(text));
}

}  // namespace
}  // namespace pcsg::fuzz
