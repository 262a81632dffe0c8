// POV-Ray 3.7's light attenuation and area-light sampling (lights.h), against values
// computed by hand from its formulas; and a shaded floor under a spotlight, a fading light,
// a shadowless light and an area light.
#include "lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include "bounds.h"
#include "shading.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

Light spot(double radius, double falloff, double tightness) {
    Light l;
    l.position = {0, 0, 10};
    l.pointAt = {0, 0, 0};
    l.spotlight = true;
    l.radius = radius;
    l.falloff = falloff;
    l.tightness = tightness;
    return l;
}

// The unit direction from a floor point at angle `a` (degrees) off the spot axis back
// to the light at <0,0,10>.
Vec3 toLight(double a) {
    return Vec3{-std::sin(a * kDeg), 0, std::cos(a * kDeg)};
}

TEST(Lights, SpotlightConeRadiusFalloffAndTightness) {
    const Light l = spot(10, 30, 0);
    EXPECT_DOUBLE_EQ(spotAttenuation(l, toLight(0)), 1.0);
    EXPECT_DOUBLE_EQ(spotAttenuation(l, toLight(9.9)), 1.0);  // inside the radius
    EXPECT_DOUBLE_EQ(spotAttenuation(l, toLight(30.5)), 0.0);  // beyond the falloff
    EXPECT_DOUBLE_EQ(spotAttenuation(l, toLight(95)), 0.0);    // behind the light
    // Between: the cubic spline of the cosines.
    const double c = std::cos(20 * kDeg), lo = std::cos(30 * kDeg), hi = std::cos(10 * kDeg);
    const double t = (c - lo) / (hi - lo);
    EXPECT_NEAR(spotAttenuation(l, toLight(20)), 3 * t * t - 2 * t * t * t, 1e-12);
    // Tightness: cos^tightness everywhere, also inside the radius.
    const Light tight = spot(10, 30, 8);
    EXPECT_NEAR(spotAttenuation(tight, toLight(5)), std::pow(std::cos(5 * kDeg), 8), 1e-12);
    // A radius beyond the falloff: a sharp edge at the radius (POV-Ray renders it so).
    const Light sharp = spot(25, 20, 0);
    EXPECT_DOUBLE_EQ(spotAttenuation(sharp, toLight(24)), 1.0);
    EXPECT_DOUBLE_EQ(spotAttenuation(sharp, toLight(26)), 0.0);
    // Not a spotlight: no cone.
    Light point;
    EXPECT_DOUBLE_EQ(spotAttenuation(point, toLight(80)), 1.0);
}

TEST(Lights, FadingWithDistance) {
    Light l;
    EXPECT_DOUBLE_EQ(fadeAttenuation(l, 123), 1.0);  // fade_power 0: no fading
    l.fadeDistance = 4;
    l.fadePower = 2;
    EXPECT_DOUBLE_EQ(fadeAttenuation(l, 4), 1.0);  // 2 / (1 + 1)
    EXPECT_DOUBLE_EQ(fadeAttenuation(l, 8), 2.0 / 5.0);
    EXPECT_DOUBLE_EQ(fadeAttenuation(l, 2), 2.0 / 1.25);  // brighter than the colour nearby
    l.fadeDistance = 0;  // POV-Ray's d^-fade_power
    EXPECT_DOUBLE_EQ(fadeAttenuation(l, 4), 1.0 / 16.0);
}

TEST(Lights, AreaGridPointsSpanTheAxesAroundTheCentre) {
    Light l;
    l.size1 = 6;
    l.size2 = 3;
    const Vec3 a1{3, 0, 0}, a2{0, 2, 0};
    auto expectVec = [](const Vec3& got, const Vec3& want) {
        EXPECT_NEAR(got.x, want.x, 1e-12);
        EXPECT_NEAR(got.y, want.y, 1e-12);
        EXPECT_NEAR(got.z, want.z, 1e-12);
    };
    expectVec(areaOffset(l, 0, 0, a1, a2), {-1.5, -1, 0});
    expectVec(areaOffset(l, 5, 2, a1, a2), {1.5, 1, 0});
    expectVec(areaOffset(l, 2, 1, a1, a2), {-1.5 + 3 * 0.4, 0, 0});
    l.size2 = 1;  // one row: no offset along axis2
    expectVec(areaOffset(l, 5, 0, a1, a2), {1.5, 0, 0});
    // circular: the corners of a 3x3 grid move onto the circle of radius 1/2 (shells).
    Light c;
    c.size1 = c.size2 = 3;
    c.circular = true;
    const Vec3 corner = areaOffset(c, 0, 0, {1, 0, 0}, {0, 1, 0});
    EXPECT_NEAR(length(corner), 0.499, 1e-9);
    EXPECT_NEAR(corner.x, corner.y, 1e-12);
}

TEST(Lights, AreaRecursionSamplesCornersFirstAndSplitsAtTheMidpoints) {
    std::set<std::pair<int, int>> seen;
    int calls = 0;
    auto uniform = [&](int u, int v) {
        ++calls;
        seen.insert({u, v});
        return Vec3{1, 1, 1};
    };
    // adaptive 0 and equal corners: the four corners only.
    Vec3 avg = areaAverage(6, 6, 0, uniform);
    EXPECT_EQ(calls, 4);
    EXPECT_EQ(seen, (std::set<std::pair<int, int>>{{0, 0}, {5, 0}, {0, 5}, {5, 5}}));
    EXPECT_DOUBLE_EQ(avg.x, 1.0);
    // adaptive 1: one split, at floor/ceil of 2.5: corners of [0,2] and [3,5] in each axis.
    seen.clear();
    calls = 0;
    areaAverage(6, 6, 1, uniform);
    EXPECT_EQ(calls, 16);
    for (int u : {0, 2, 3, 5})
        for (int v : {0, 2, 3, 5}) EXPECT_TRUE(seen.count({u, v})) << u << "," << v;
    // The default (100): every point, each once.
    seen.clear();
    calls = 0;
    areaAverage(6, 6, 100, uniform);
    EXPECT_EQ(calls, 36);
    EXPECT_EQ(seen.size(), 36u);
    // The mean is hierarchical, not uniform: in a 3x3 grid the centre is a corner of all
    // four quarters, weight 4 x 1/16.
    const Vec3 centre = areaAverage(3, 3, 100, [](int u, int v) {
        return u == 1 && v == 1 ? Vec3{1, 1, 1} : Vec3{0, 0, 0};
    });
    EXPECT_DOUBLE_EQ(centre.x, 0.25);
    // Corners that differ by more than 0.1 split further even at adaptive 0.
    calls = 0;
    const Vec3 edge = areaAverage(5, 5, 0, [&](int u, int) {
        ++calls;
        return u < 2 ? Vec3{0, 0, 0} : Vec3{1, 1, 1};
    });
    EXPECT_GT(calls, 4);
    // Columns 2-4 lit, 0-1 dark: some light, not all.
    EXPECT_GT(edge.x, 0.5);
    EXPECT_LT(edge.x, 1.0);
}

TEST(Lights, OrientTurnsTheAxesToFaceThePoint) {
    Light l;
    l.axis1 = {2, 0, 0};
    l.axis2 = {0, 5, 0};
    Vec3 a1, a2;
    const Vec3 dir = normalize(Vec3{1, 1, 0});
    orientAxes(l, dir, a1, a2);
    EXPECT_NEAR(dot(a1, dir), 0, 1e-12);
    EXPECT_NEAR(dot(a2, dir), 0, 1e-12);
    EXPECT_NEAR(dot(a1, a2), 0, 1e-12);
    EXPECT_NEAR(length(a1), 2, 1e-12);  // both take axis1's length: a square
    EXPECT_NEAR(length(a2), 2, 1e-12);
}

// A floor lit from above by one light: the colour of the floor point p seen from above.
Vec3 floorColour(const char* light, const Vec3& p) {
    const std::string text = std::string(light) + R"(
background <0, 0, 0>
material m { color <1, 1, 1>  ambient 0  diffuse 1  phong 1  phong_size 1 }
paint(m) plane ∪ paint(m) move(0, 0, 2) uscale(0.5) sphere
)";
    auto c = testing::compile(text.c_str());
    EXPECT_TRUE(c->graph);
    if (!c->graph) return {};
    TraceScene scene(*c->graph, computeBounds(*c->graph));
    Shader shader(scene);
    const Vec3 eye = p + Vec3{0.3, 0, 1};
    return shader.shade(Ray{eye, normalize(p - eye)});
}

TEST(Lights, ShadedFloorUnderEachKindOfLight) {
    // A shadowless light: diffuse only (no phong), and no shadow under the ball.
    const Vec3 fill = floorColour("light { position <0, 0, 10>  shadowless }", {0, 0, 0});
    const Vec3 lit = floorColour("light { position <0, 0, 10> }", {3, 0, 0});
    const Vec3 shadowed = floorColour("light { position <0, 0, 10> }", {0, 0, 0});
    EXPECT_NEAR(fill.x, 1.0, 1e-9);  // N.L = 1, no highlight added
    EXPECT_NEAR(shadowed.x, 0.0, 1e-12);
    EXPECT_GT(lit.x, 0.9);
    // Fading: at distance 10 with fade_distance 5 and power 2, 2 / (1 + 4) of the light.
    const Vec3 faded = floorColour(
        "light { position <0, 0, 10>  shadowless  fade_distance 5  fade_power 2 }", {0, 0, 0});
    EXPECT_NEAR(faded.x, 0.4, 1e-9);
    // A spotlight pointing away from the point: dark.
    const Vec3 away = floorColour(
        "light { position <0, 0, 10>  spotlight  point_at <20, 0, 0>  radius 5  falloff 10 }",
        {0, 0, 0});
    EXPECT_NEAR(away.x, 0.0, 1e-12);
    // An area light wider than the ball: the point under it is in penumbra, not umbra.
    const Vec3 soft = floorColour(
        "light { position <0, 0, 10>  area_light <8, 0, 0>, <0, 8, 0>, 5, 5 }", {0, 0, 0});
    EXPECT_GT(soft.x, 0.1);
    EXPECT_LT(soft.x, lit.x);
}

}  // namespace
}  // namespace pcsg::tracer
