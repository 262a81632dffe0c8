// Reading section 10's pigment and normal patterns: what each item sets, in POV-Ray's
// order (the errors are in tests/diagnostics/pattern_items.pcsg).
#include <gtest/gtest.h>

#include <cmath>

#include "compile_test_util.h"

namespace pcsg {
namespace {

using testing::compile;

// The material `m` of a scene made of it alone.
Material materialOf(const std::string& body) {
    auto c = compile("material m { " + body + " }\npaint(m) sphere\n");
    EXPECT_TRUE(c->graph) << c->errors();
    if (!c->graph) return Material{};
    return c->graph->materials.back();
}

void expectNear(const Vec3& a, const Vec3& b) {
    EXPECT_NEAR(a.x, b.x, 1e-12);
    EXPECT_NEAR(a.y, b.y, 1e-12);
    EXPECT_NEAR(a.z, b.z, 1e-12);
}

TEST(PatternReading, ListPatternsTakeTheirColours) {
    Material m = materialOf("pigment { checker color rgb <1, 0, 0> colour rgb <0, 0, 1> }");
    EXPECT_EQ(m.pigment.pattern.kind, PatternKind::Checker);
    ASSERT_EQ(m.pigment.listColours.size(), 2u);
    EXPECT_EQ(m.pigment.listColours[1].rgb, (Vec3{0, 0, 1}));
    m = materialOf("pigment { hexagon rgb 1 rgb 0.5 rgb <0, 1, 0> scale 2 }");
    ASSERT_EQ(m.pigment.listColours.size(), 3u);
    EXPECT_EQ(m.pigment.listColours[1].rgb, (Vec3{0.5, 0.5, 0.5}));
    m = materialOf("pigment { brick brick_size <1, 2, 3> mortar 0.1 }");
    EXPECT_TRUE(m.pigment.listColours.empty());  // POV-Ray's default colours
    EXPECT_EQ(m.pigment.pattern.brickSize, (Vec3{1, 2, 3}));
    EXPECT_EQ(m.pigment.pattern.mortar, 0.1);
}

TEST(PatternReading, ColourMapsInBothForms) {
    const Material m = materialOf(
        "pigment { wood colour_map { [0 color rgb 1] [0.25, 0.5 rgb 0 color rgbf <1, 0, 0, 0>] "
        "[1 rgb <0, 1, 0>] } }");
    const auto& map = m.pigment.colourMap;
    ASSERT_EQ(map.size(), 4u);
    EXPECT_EQ(map[1].value, 0.25);
    EXPECT_EQ(map[2].value, 0.5);
    EXPECT_EQ(map[2].colour.rgb, (Vec3{1, 0, 0}));
    EXPECT_EQ(map[3].colour.rgb, (Vec3{0, 1, 0}));
}

TEST(PatternReading, ModifiersAndTurbulence) {
    Material m = materialOf(
        "pigment { gradient z frequency 3 phase 0.25 turbulence <0.1, 0.2, 0.3> octaves 4 "
        "omega 0.6 lambda 2.5 }");
    const PatternSpec& s = m.pigment.pattern;
    EXPECT_EQ(s.gradient, (Vec3{0, 0, 1}));
    EXPECT_EQ(s.frequency, 3);
    EXPECT_EQ(s.phase, 0.25);
    EXPECT_EQ(s.turbulence.amount, (Vec3{0.1, 0.2, 0.3}));
    EXPECT_EQ(s.turbulence.octaves, 4);
    EXPECT_EQ(s.turbulence.omega, 0.6);
    EXPECT_EQ(s.turbulence.lambda, 2.5);
    EXPECT_FALSE(s.transformed);
    m = materialOf("pigment { marble turbulence 0.5 }");
    EXPECT_EQ(m.pigment.pattern.turbulence.amount, (Vec3{0.5, 0.5, 0.5}));
    m = materialOf("pigment { gradient <3, 4, 0> }");  // POV-Ray normalises the axis
    expectNear(m.pigment.pattern.gradient, Vec3{0.6, 0.8, 0});
}

TEST(PatternReading, TransformationsComposeInTheOrderWritten) {
    const Material m =
        materialOf("pigment { onion scale 2 rotate <0, 0, 90> translate <1, 0, 0> }");
    const PatternSpec& s = m.pigment.pattern;
    ASSERT_TRUE(s.transformed);
    ASSERT_EQ(s.transforms.size(), 3u);
    // The pattern's point (1, 0, 0): scaled to (2, 0, 0), turned to (0, 2, 0), moved to (1, 2, 0).
    expectNear(s.fromPattern.point({1, 0, 0}), Vec3{1, 2, 0});
    expectNear(s.toPattern.point({1, 2, 0}), Vec3{1, 0, 0});
    // POV-Ray's rotate <a, b, c> turns about x first, then y, then z.
    const Material r = materialOf("pigment { onion rotate <90, 90, 0> }");
    expectNear(r.pigment.pattern.fromPattern.point({0, 1, 0}), Vec3{1, 0, 0});
}

TEST(PatternReading, NormalsTakeAnAmountAndModifiers) {
    Material m = materialOf("normal { ripples 0.8 frequency 5 phase 0.1 scale 0.5 }");
    EXPECT_EQ(m.normal.kind, NormalKind::Ripples);
    EXPECT_EQ(m.normal.amount, 0.8);
    EXPECT_EQ(m.normal.pattern.frequency, 5);
    EXPECT_TRUE(m.normal.pattern.transformed);
    m = materialOf("normal { bumps }");
    EXPECT_EQ(m.normal.kind, NormalKind::Bumps);
    EXPECT_EQ(m.normal.amount, 0.5);  // POV-Ray's default
    m = materialOf("normal { dents 1.5 turbulence 0.2 }");
    EXPECT_EQ(m.normal.kind, NormalKind::Dents);
    EXPECT_EQ(m.normal.pattern.turbulence.amount.x, 0.2);
}

TEST(PatternReading, SpottedIsBozoWithItsOwnDefaultMap) {
    const Material m = materialOf("pigment { spotted }");
    EXPECT_EQ(m.pigment.pattern.kind, PatternKind::Bozo);
    EXPECT_TRUE(m.pigment.pattern.spotted);
}

}  // namespace
}  // namespace pcsg
