// Transparency (transparency.h): Snell's law and total internal reflection, POV-Ray's
// interior stack, fade, and the ray tree's filter, transmit, weights and trace levels,
// computed here by hand from POV-Ray 3.7's formulas.
#include "transparency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bounds.h"
#include "shading.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

TEST(Transparency, RefractionFollowsSnellsLaw) {
    const Vec3 n{0, 0, 1};
    for (double ior : {1 / 1.5, 1.33, 1.5 / 1.2}) {
        for (double angle : {0.0, 0.3, 0.6}) {
            const Vec3 d{std::sin(angle), 0, -std::cos(angle)};
            const auto r = refractDirection(d, n, ior);
            ASSERT_TRUE(r) << ior << " " << angle;
            EXPECT_NEAR(length(*r), 1.0, 1e-12);
            // n1 sin(in) = n2 sin(out), with ior = n1 / n2; the ray goes on through.
            EXPECT_NEAR(r->x, ior * d.x, 1e-12);
            EXPECT_LT(r->z, 0);
        }
    }
}

// An interior stack copies only the interiors in use: a copy and an assignment (onto a
// deeper stack, whose old slots must not show through) hold the same interiors, innermost
// last, and change apart from the original.
TEST(Transparency, InteriorStacksCopyTheInteriorsInUse) {
    Interiors a;
    for (uint64_t id : {11, 22, 33}) a.push(Interior{id, static_cast<uint32_t>(id % 7)});
    Interiors b = a;
    EXPECT_EQ(b.size(), 3);
    EXPECT_EQ(b.innermost().id, 33u);
    EXPECT_EQ(b.innermost().material, 33u % 7);
    EXPECT_TRUE(b.contains(11) && b.contains(22) && !b.contains(44));
    b.push(Interior{44, 1});
    EXPECT_TRUE(b.contains(44));
    EXPECT_FALSE(a.contains(44));
    Interiors deeper;
    for (uint64_t id = 100; id < 140; ++id) deeper.push(Interior{id, 2});  // 8 ignored
    EXPECT_EQ(deeper.size(), Interiors::kCapacity);
    deeper = a;
    EXPECT_EQ(deeper.size(), 3);
    EXPECT_FALSE(deeper.contains(100));
    EXPECT_TRUE(deeper.remove(33));
    EXPECT_EQ(deeper.innermost().id, 22u);
    EXPECT_EQ(a.innermost().id, 33u);
    deeper.push(Interior{55, 4});
    EXPECT_EQ(deeper.innermost().material, 4u);
    EXPECT_FALSE(deeper.contains(131));  // a slot of the old stack, not copied over
    Interiors empty;
    deeper = empty;
    EXPECT_TRUE(deeper.empty());
    EXPECT_FALSE(deeper.contains(11));
}

TEST(Transparency, TotalInternalReflectionBeyondTheCriticalAngle) {
    const Vec3 n{0, 0, 1};
    const double ior = 1.5;  // leaving glass into air
    const double critical = std::asin(1 / ior);
    const Vec3 below{std::sin(critical - 0.01), 0, -std::cos(critical - 0.01)};
    const Vec3 beyond{std::sin(critical + 0.01), 0, -std::cos(critical + 0.01)};
    EXPECT_TRUE(refractDirection(below, n, ior));
    EXPECT_FALSE(refractDirection(beyond, n, ior));
    EXPECT_TRUE(refractDirection(beyond, n, 1 / ior));  // entering glass: never
}

Graph threeInteriors() {
    Graph g;
    g.materials.resize(3);
    g.materials[1].ior = 1.5;
    g.materials[2].ior = 1.2;
    return g;
}

TEST(Transparency, InteriorStackFollowsPovRaysRules) {
    const Graph g = threeInteriors();
    const Interior glass{11, 1}, other{12, 2};  // two objects, of materials 1 and 2
    Interiors in;
    EXPECT_DOUBLE_EQ(crossSurface(in, glass, g), 1 / 1.5);  // air into glass
    EXPECT_DOUBLE_EQ(relativeIor(in, other, g), 1.2 / 1.5);
    EXPECT_DOUBLE_EQ(crossSurface(in, other, g), 1.5 / 1.2);  // nested: glass into the other
    EXPECT_EQ(in.size(), 2);
    EXPECT_DOUBLE_EQ(relativeIor(in, other, g), 1.2 / 1.2);
    EXPECT_DOUBLE_EQ(crossSurface(in, other, g), 1.2 / 1.5);  // back out into the glass
    EXPECT_DOUBLE_EQ(relativeIor(in, glass, g), 1 / 1.5);
    EXPECT_DOUBLE_EQ(crossSurface(in, glass, g), 1.5);  // glass into air
    EXPECT_TRUE(in.empty());
    // Overlap (A (B A) B): leaving A while in B changes nothing, leaving B goes to air.
    crossSurface(in, glass, g);
    crossSurface(in, other, g);
    EXPECT_DOUBLE_EQ(crossSurface(in, glass, g), 1.0);
    EXPECT_DOUBLE_EQ(crossSurface(in, other, g), 1.2);
    EXPECT_TRUE(in.empty());
}

// Interiors are objects, not materials: a second object of the same glass met from inside
// the first is entered (ior 1.5 to 1.5: straight on), not taken for the way out of it.
TEST(Transparency, TwoObjectsOfOneMaterialAreTwoInteriors) {
    const Graph g = threeInteriors();
    const Interior a{21, 1}, b{22, 1};
    Interiors in;
    EXPECT_DOUBLE_EQ(crossSurface(in, a, g), 1 / 1.5);
    EXPECT_DOUBLE_EQ(relativeIor(in, b, g), 1.0);
    EXPECT_DOUBLE_EQ(crossSurface(in, b, g), 1.0);  // into b, still in glass
    EXPECT_EQ(in.size(), 2);
    EXPECT_DOUBLE_EQ(crossSurface(in, a, g), 1.0);  // out of a, still in b
    EXPECT_DOUBLE_EQ(crossSurface(in, b, g), 1.5);  // out of b into air
    EXPECT_TRUE(in.empty());
    // The same object twice is one interior: its far wall leads out.
    crossSurface(in, a, g);
    EXPECT_DOUBLE_EQ(crossSurface(in, a, g), 1.5);
    EXPECT_TRUE(in.empty());
}

TEST(Transparency, FadeIsPovRaysAttenuation) {
    Material m;
    EXPECT_EQ(fade(m, 3), (Vec3{1, 1, 1}));  // no fade_distance: none
    m.fadeDistance = 2;
    m.fadePower = 2;
    m.fadeColour = Vec3{0.5, 0, 0};
    const double k = 1 + std::pow(3.0 / 2, 2);
    const Vec3 f = fade(m, 3);
    EXPECT_NEAR(f.x, 0.5 + 0.5 / k, 1e-12);
    EXPECT_NEAR(f.y, 1 / k, 1e-12);
    m.fadePower = 1000;
    EXPECT_NEAR(fade(m, 3).y, std::exp(-1.5), 1e-12);
    m.fadePower = 0;  // 1 + x^0 = 2 for lit rays; shadow rays need fade_power > 0
    EXPECT_NEAR(fade(m, 3).y, 0.5, 1e-12);
    EXPECT_EQ(fade(m, 3, true), (Vec3{1, 1, 1}));
}

TEST(Transparency, ConserveEnergyTakesTheReflectedShare) {
    const Vec3 got = conserveEnergy(Vec3{0.8, 0.8, 0.8}, Vec3{0.25, 0.5, -0.5});
    EXPECT_NEAR(got.x, 0.6, 1e-12);
    EXPECT_NEAR(got.y, 0.4, 1e-12);
    EXPECT_NEAR(got.z, 0.8, 1e-12);  // min(1 - r, 1)
}

// One camera ray through a thin transparent box onto a wall lit by ambient only.
double throughVeil(const std::string& veil, const std::string& settings) {
    const std::string text =
        settings + "\nmaterial wall { color <0.2, 0.4, 0.8> ambient 1 diffuse 0 }\n" +
        "material veil { " + veil + " ambient 0.5 diffuse 0 }\n" +
        "paint(wall) move(0, 0, -5) plane ∪ paint(veil) scale(3, 3, 0.1) cube\n";
    auto c = compile(text);
    if (!c->graph) return -1;
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g));
    Shader shader(scene);
    return shader.shade(Ray{{0, 0, 2}, Vec3{0, 0, -1}}).y;
}

TEST(Transparency, TransmitAndFilterLetTheWallThroughBothWalls) {
    const double wall = 0.4;
    // transmit 0.6: each wall adds its ambient times its opacity 0.4 and lets 0.6 through.
    const double own = 0.5 * 0.2 * 0.4;
    EXPECT_NEAR(throughVeil("color rgbt <0.5, 0.2, 0.1, 0.6>", ""), own + 0.6 * (own + 0.6 * wall),
                1e-12);
    // filter 0.6: what passes is 0.6 times the colour (0.2 in green).
    EXPECT_NEAR(throughVeil("color rgbf <0.5, 0.2, 0.1, 0.6>", ""),
                own + 0.12 * (own + 0.12 * wall), 1e-12);
}

TEST(Transparency, StraightThroughKeepsTheTraceLevelRefractionDoesNot) {
    const double own = 0.5 * 0.2 * 0.4, wall = 0.4;
    const char* plain = "color rgbt <0.5, 0.2, 0.1, 0.6>";
    const char* glass = "color rgbt <0.5, 0.2, 0.1, 0.6> interior { ior 1.5 }";
    // Every ray is checked against max_trace_level, but the rays straight through (ior 1)
    // keep the camera ray's level 1: at level 2 they reach the wall through both walls.
    EXPECT_NEAR(throughVeil(plain, "settings { max_trace_level 1 }"), own, 1e-12);
    EXPECT_NEAR(throughVeil(plain, "settings { max_trace_level 2 }"),
                own + 0.6 * (own + 0.6 * wall), 1e-12);
    // ior 1.5: the refracted ray inside is level 2, the one leaving level 3.
    EXPECT_NEAR(throughVeil(glass, "settings { max_trace_level 2 }"), own + 0.6 * own, 1e-12);
    EXPECT_NEAR(throughVeil(glass, "settings { max_trace_level 3 }"),
                own + 0.6 * (own + 0.6 * wall), 1e-12);
}

TEST(Transparency, WeightBelowAdcBailoutIsNotTraced) {
    const double t = 0.003;  // below 1/255: the transmitted ray is not traced
    const double own = 0.5 * 0.2 * (1 - t);
    EXPECT_NEAR(throughVeil("color rgbt <0.5, 0.2, 0.1, 0.003>", ""), own, 1e-12);
    // adc_bailout 0.001: traced; but behind the box's back wall the weight is 0.003^2.
    EXPECT_NEAR(throughVeil("color rgbt <0.5, 0.2, 0.1, 0.003>", "settings { adc_bailout 0.001 }"),
                own + t * own, 1e-12);
}

// A white floor lit straight from above through a filter box: the light is filtered by both
// walls of the box, (filter * colour)^2 per channel.
TEST(Transparency, ShadowsAreTintedByEverySurfaceCrossed) {
    auto c = compile(R"(
light { position <0, 0.5, 10>  color <1, 1, 1> }
material ground { color <1, 1, 1> ambient 0 diffuse 1 }
material tint { color rgbf <1, 0.5, 0.25, 0.8> ambient 0 diffuse 0 }
paint(ground) plane ∪ paint(tint) move(0, 0, 3) cube
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g));
    Shader shader(scene);
    // The camera ray looks at the floor beside the box, the light straight above it through
    // the box: diffuse 1 * N.L (1) * light through the box.
    const Vec3 p{0, 0.5, 0};
    const Vec3 from{0, -3, 1.5};
    const Vec3 col = shader.shade(Ray{from, normalize(p - from)});
    EXPECT_NEAR(col.x, 0.8 * 0.8, 1e-9);
    EXPECT_NEAR(col.y, 0.4 * 0.4, 1e-9);
    EXPECT_NEAR(col.z, 0.2 * 0.2, 1e-9);
}

// The same through a fading box: the shadow ray enters the box at its top wall and fades
// over the 2 units to its bottom wall, 1 / (1 + (2 / 1)^2) with fade_power 2.
TEST(Transparency, ShadowRaysFadeInsideTheSolidsTheyCross) {
    auto c = compile(R"(
light { position <0, 0.5, 10>  color <1, 1, 1> }
material ground { color <1, 1, 1> ambient 0 diffuse 1 }
material tint { color rgbt <1, 1, 1, 1> ambient 0 diffuse 0
                interior { fade_distance 1 fade_power 2 fade_color <0.5, 0, 0> } }
paint(ground) plane ∪ paint(tint) move(0, 0, 3) cube
)");
    ASSERT_TRUE(c->graph);
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g));
    Shader shader(scene);
    const Vec3 p{0, 0.5, 0}, from{0, -3, 1.5};
    const Vec3 col = shader.shade(Ray{from, normalize(p - from)});
    const double k = 1 + 2.0 * 2.0;
    EXPECT_NEAR(col.x, 0.5 + 0.5 / k, 1e-9);
    EXPECT_NEAR(col.y, 1 / k, 1e-9);
}

}  // namespace
}  // namespace pcsg::tracer
