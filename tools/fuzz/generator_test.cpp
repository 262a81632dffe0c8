// The fuzz generator (generator.h) and the feature count (coverage.h): a seed gives the
// same text every time and different seeds different texts; every system of a range of
// seeds compiles, expands without a run-time error into a small tree, and survives the
// formatter (fmt(fmt(x)) == fmt(x), fmt(x) compiles to x's graph); a campaign of them
// covers every feature, section 10's appearance items included.
#include "generator.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "compiler.h"
#include "coverage.h"
#include "eval.h"
#include "expander.h"
#include "formatter.h"
#include "same_graph_test_util.h"

namespace pcsg::fuzz {
namespace {

using pcsg::testing::expectSameGraph;

TEST(FuzzRng, IsAFixedSequenceOfTheSeed) {
    // xoshiro256** from splitmix64: the first outputs are a property of the algorithm,
    // so a change of the generator's arithmetic shows here.
    Rng a(42), b(42), c(43);
    std::vector<uint64_t> first;
    for (int k = 0; k < 4; ++k) {
        const uint64_t x = a.next();
        EXPECT_EQ(x, b.next());
        first.push_back(x);
    }
    EXPECT_NE(first[0], c.next());
    EXPECT_EQ(mix64(0), 0xe220a8397b1dcdafull);  // splitmix64's first output for seed 0
    EXPECT_NE(systemSeed(1, 0), systemSeed(1, 1));
    EXPECT_NE(systemSeed(1, 0), systemSeed(2, 0));
}

TEST(FuzzRng, MilliPrintsThousandths) {
    EXPECT_EQ(milli(1250), "1.25");
    EXPECT_EQ(milli(-5), "-0.005");
    EXPECT_EQ(milli(3000), "3");
    EXPECT_EQ(milli(0), "0");
    EXPECT_EQ(milli(-120340), "-120.34");
}

TEST(FuzzGenerator, SameSeedSameTextOtherSeedOtherText) {
    for (uint64_t seed : {0ull, 1ull, 0xdeadbeefull}) {
        const std::string a = generateSystem(seed);
        EXPECT_EQ(a, generateSystem(seed));
        EXPECT_NE(a, generateSystem(seed + 1));
    }
}

TEST(FuzzGenerator, EverySystemCompilesExpandsAndFormats) {
    std::map<std::string, int> coverage;
    for (uint64_t i = 0; i < 120; ++i) {
        const std::string text = generateSystem(systemSeed(7, i));
        SCOPED_TRACE(text);
        Diagnostics diags;
        const std::optional<Graph> g = compileSource("g.pcsg", text, diags);
        ASSERT_TRUE(g) << diags.format();
        // Terminating, free of run-time errors, and small enough for POV-Ray.
        ExpansionCount count;
        ASSERT_NO_THROW(count = countExpansion(*g));
        EXPECT_TRUE(count.complete);
        EXPECT_GT(count.primitives, 0u);
        EXPECT_LT(count.primitives, 3000u);
        Diagnostics d1, d2, d3;
        const std::optional<std::string> once = formatScene("g.pcsg", text, d1);
        ASSERT_TRUE(once) << d1.format();
        const std::optional<std::string> twice = formatScene("g.pcsg", *once, d2);
        ASSERT_TRUE(twice) << d2.format();
        EXPECT_EQ(*once, *twice);
        const std::optional<Graph> formatted = compileSource("f.pcsg", *once, d3);
        ASSERT_TRUE(formatted) << d3.format();
        expectSameGraph(*g, *formatted);
        for (const std::string& f : featuresOf(text)) ++coverage[f];
    }
    for (const std::string& f : featureNames()) EXPECT_GT(coverage[f], 0) << f;
}

TEST(FuzzFeatures, ReadTheSyntaxTree) {
    const std::set<std::string> none = featuresOf("sphere");
    EXPECT_EQ(none, std::set<std::string>{"sphere"});
    const std::set<std::string> some = featuresOf(
        "w: S(1)\np: S(c) : c > 0 -> move(1,0,0) tri1 ∪ S(c - rand())\n"
        "q: S(c) -> cube ∩ {x = 1} paint(m) torus(1, 0.2)");
    const std::set<std::string> want = {"notation_b", "transform",    "triangle", "union", "rand",
                                        "cube",       "intersection", "calc",     "paint", "torus"};
    EXPECT_EQ(some, want);
    EXPECT_TRUE(featuresOf("sphere ∪").empty());  // does not parse
}

// Section 10's items are read from the tokens, by the block they stand in: `dents` in a
// pigment is a pigment pattern, in a normal a normal pattern; rgbft is filter and transmit.
TEST(FuzzFeatures, ReadTheAppearanceItems) {
    const std::set<std::string> found = featuresOf(
        "light { position <1, 2, 3>  color <1, 1, 1>  spotlight point_at <0, 0, 0> }\n"
        "fog { distance 3  color <1, 1, 1> }\n"
        "material m { pigment { spotted color_map { [0 color rgbft <1, 1, 1, 0.2, 0.3>] "
        "[1 color rgb <0, 0, 0>] } turbulence 0.2 scale 0.5 } normal { dents 0.4 } "
        "finish { specular 0.5 reflection { 0, 0.5 fresnel on } } interior { ior 1.5 } }\n"
        "paint(m) sphere");
    const std::set<std::string> want = {
        "paint",        "sphere",   "spotlight", "fog",        "pigment_bozo",
        "color_map",    "filter",   "transmit",  "turbulence", "pattern_transform",
        "normal_dents", "specular", "fresnel",   "ior"};
    EXPECT_EQ(found, want);
}

}  // namespace
}  // namespace pcsg::fuzz
