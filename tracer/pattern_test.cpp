// Pattern values at known points, from POV-Ray 3.7's definitions of the patterns
// (source/core/material/pattern.cpp), the colour map's search and interpolation, and
// frequency and phase.
#include "pattern.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "colour_map.h"
#include "pigment.h"

namespace pcsg::tracer {
namespace {

PatternSpec spec(PatternKind k) {
    PatternSpec s;
    s.kind = k;
    return s;
}

TEST(Pattern, CheckerIsTheParityOfTheUnitCube) {
    const PatternSpec s = spec(PatternKind::Checker);
    EXPECT_EQ(patternValue(s, {0.5, 0.5, 0.5}), 0);
    EXPECT_EQ(patternValue(s, {1.5, 0.5, 0.5}), 1);
    EXPECT_EQ(patternValue(s, {-0.5, 0.5, 0.5}), 1);
    EXPECT_EQ(patternValue(s, {-0.5, -0.5, 0.5}), 0);
    EXPECT_EQ(patternValue(s, {0.5, 2.5, -2.5}), 1);
    EXPECT_EQ(patternValue(s, {0.5, 2.5, -3.5}), 0);
    // POV-Ray's EPSILON: a point a hair below a cube's face counts as above it.
    EXPECT_EQ(patternValue(s, {1 - 1e-12, 0.5, 0.5}), 1);
}

TEST(Pattern, GradientIsTheFractionAlongItsAxis) {
    PatternSpec s = spec(PatternKind::Gradient);
    s.gradient = {1, 0, 0};
    EXPECT_NEAR(patternValue(s, {0.25, 7, 7}), 0.25, 1e-12);
    EXPECT_NEAR(patternValue(s, {1.75, 0, 0}), 0.75, 1e-12);
    EXPECT_NEAR(patternValue(s, {-0.25, 0, 0}), 0.75, 1e-12);  // negative: wrapped up
    s.gradient = {0, 0, 2};
    EXPECT_NEAR(patternValue(s, {0, 0, 0.2}), 0.4, 1e-12);
}

TEST(Pattern, OnionIsTheFractionOfTheDistanceToTheOrigin) {
    const PatternSpec s = spec(PatternKind::Onion);
    EXPECT_NEAR(patternValue(s, {0, 2.3, 0}), 0.3, 1e-12);
    EXPECT_NEAR(patternValue(s, {0.3, 0.4, 0}), 0.5, 1e-12);
}

TEST(Pattern, LeopardIsTheSquaredMeanOfThreeSines) {
    const PatternSpec s = spec(PatternKind::Leopard);
    const double h = std::numbers::pi / 2;
    EXPECT_NEAR(patternValue(s, {h, h, h}), 1.0, 1e-9);
    EXPECT_NEAR(patternValue(s, {0, 0, 0}), 0.0, 1e-12);
    EXPECT_NEAR(patternValue(s, {h, 0, 0}), 1.0 / 9.0, 1e-12);
}

TEST(Pattern, RadialIsTheAngleAroundY) {
    const PatternSpec s = spec(PatternKind::Radial);
    EXPECT_NEAR(plainPatternValue(s, {0, 0, 1}), 0.75, 1e-12);       // +z
    EXPECT_NEAR(plainPatternValue(s, {1, 0, 0}), 1.0, 1e-12);        // +x
    EXPECT_NEAR(plainPatternValue(s, {0, 0, -1}), 1.25, 1e-12);      // raw: past 1
    EXPECT_NEAR(patternValue(s, {0, 0, -1}), 0.25, 1e-4);            // then mod 1.00001
    EXPECT_NEAR(plainPatternValue(s, {0.0001, 5, 0}), 0.25, 1e-12);  // on the axis
    EXPECT_NEAR(patternValue(s, {-1, 0, 0}), 0.5, 1e-12);
}

TEST(Pattern, BrickHasMortarBetweenOffsetCourses) {
    const PatternSpec s = spec(PatternKind::Brick);  // brick_size <8, 3, 4.5>, mortar 0.5
    EXPECT_EQ(patternValue(s, {1, 1.5, 1}), 1);
    EXPECT_EQ(patternValue(s, {-0.2, 1.5, 1}), 0);  // a vertical joint of the lower course
    EXPECT_EQ(patternValue(s, {1, 2.9, 1}), 0);     // a horizontal joint
    EXPECT_EQ(patternValue(s, {0, 4.5, 1}), 1);     // the next course is offset by half a brick
    EXPECT_EQ(patternValue(s, {3.5, 4.5, 1}), 0);   // where its joint is
}

TEST(Pattern, HexagonGivesThreeColoursInTheXZPlane) {
    const PatternSpec s = spec(PatternKind::Hexagon);
    EXPECT_EQ(patternValue(s, {0, 5, 0}), 0);  // the hexagon around the origin
    EXPECT_EQ(patternValue(s, {0, 0, 0.866 * 1.5}), 1);
    EXPECT_EQ(patternValue(s, {1.25, 0, 0.1}), 2);
    EXPECT_EQ(patternValue(s, {-1.25, 0, 0.1}), 2);  // mirrored in x
    EXPECT_EQ(patternValue(s, {1.5, 0, 2.598}), 0);  // the next hexagon of colour 0
}

TEST(Pattern, FrequencyAndPhaseRepeatTheValue) {
    PatternSpec s = spec(PatternKind::Gradient);
    s.frequency = 2;
    s.phase = 0.1;
    EXPECT_NEAR(patternValue(s, {0.3, 0, 0}), 0.7, 1e-12);
    EXPECT_NEAR(patternValue(s, {0.7, 0, 0}), 0.5, 1e-4);  // 1.5 mod 1.00001
    s.frequency = -1;
    s.phase = 0;
    EXPECT_NEAR(patternValue(s, {0.3, 0, 0}), 0.7, 1e-12);  // negative frequency wraps up
}

TEST(Pattern, TransformationsMoveThePattern) {
    PatternSpec s = spec(PatternKind::Gradient);
    s.fromPattern = Affine::translate({0.25, 0, 0}) * Affine::scale({2, 2, 2});
    s.toPattern = s.fromPattern.inverse();
    s.transformed = true;
    EXPECT_NEAR(patternValue(s, {0.75, 0, 0}), 0.25, 1e-12);  // (0.75 - 0.25) / 2
}

TEST(ColourMap, InterpolatesBetweenTheEntriesAroundTheValue) {
    const std::vector<ColourMapEntry> map = {
        {0.2, FilterColour{{1, 0, 0}, 0, 0}},
        {0.6, FilterColour{{0, 0, 1}, 0.4, 0.8}},
    };
    const FilterColour mid = colourMapLookup(map, 0.3);
    EXPECT_NEAR(mid.rgb.x, 0.75, 1e-12);
    EXPECT_NEAR(mid.rgb.z, 0.25, 1e-12);
    EXPECT_NEAR(mid.filter, 0.1, 1e-12);
    EXPECT_NEAR(mid.transmit, 0.2, 1e-12);
    EXPECT_EQ(colourMapLookup(map, 0.1).rgb.x, 1);  // below the first: the first
    EXPECT_EQ(colourMapLookup(map, 0.9).rgb.z, 1);  // above the last: the last
}

TEST(ColourMap, EqualValuesMakeASharpEdge) {
    const std::vector<ColourMapEntry> map = {
        {0.0, FilterColour{{1, 1, 1}}},
        {0.5, FilterColour{{1, 0, 0}}},
        {0.5, FilterColour{{0, 0, 1}}},
        {1.0, FilterColour{{0, 0, 0}}},
    };
    EXPECT_EQ(colourMapLookup(map, 0.5).rgb.x, 1);  // on the value: the first of the two
    EXPECT_NEAR(colourMapLookup(map, 0.5 + 1e-9).rgb.z, 1, 1e-6);
    EXPECT_NEAR(colourMapLookup(map, 0.25).rgb.y, 0.5, 1e-12);
}

TEST(Pigment, ListPatternsTakeTheirColoursByIndex) {
    Pigment p;
    p.pattern.kind = PatternKind::Checker;
    EXPECT_EQ(pigmentAt(p, {0.5, 0.5, 0.5}).rgb, (Vec3{0, 0, 1}));  // POV-Ray's default blue
    EXPECT_EQ(pigmentAt(p, {1.5, 0.5, 0.5}).rgb, (Vec3{0, 1, 0}));  // and green
    p.listColours = {FilterColour{{1, 1, 1}}, FilterColour{{0.2, 0.2, 0.2}}};
    EXPECT_EQ(pigmentAt(p, {1.5, 0.5, 0.5}).rgb, (Vec3{0.2, 0.2, 0.2}));
}

TEST(Pigment, ContinuousPatternsWithoutAMapUsePovRaysDefault) {
    Pigment p;
    p.pattern.kind = PatternKind::Gradient;
    EXPECT_NEAR(pigmentAt(p, {0.25, 0, 0}).rgb.y, 0.25, 1e-12);  // black to white
}

}  // namespace
}  // namespace pcsg::tracer
