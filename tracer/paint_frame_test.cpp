// Pattern space (docs/language.md section 10): a hit on a material with a pattern comes
// with its point in the frame of the paint node that applied the material. Scenes whose
// paint frames can be stated: a paint at the axiom (the world), a paint inside a recursion
// right above the solids (each instance's own frame, so every point lies on a unit
// sphere), through CSG span lists, with instances expanded and with culling off.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "bounds.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

std::string recursion(const std::string& axiomPaint, const std::string& leaf) {
    return R"(
material m { color rgb <1, 0, 0> }
material plain { color rgb <0, 1, 0> }
{n = 4} )" +
           axiomPaint +
           R"( S
S if(n > 0, 2, 1)
1: S -> )" +
           leaf + R"(
2: S -> {n = n-1} ( move(1.5, 0, 0) rot(0, 0, 1, 30) uscale(0.5) S ∪
                    move(-1.5, 0, 0) scale(0.5, 0.7, 0.6) S ∪ move(0, 0, 1.2) uscale(0.4) S )
)";
}

struct Ray {
    Vec3 o, d;
};

std::vector<Ray> rays(int count) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> x(-3, 3), z(-1.2, 2.2), jitter(-0.2, 0.2);
    std::vector<Ray> out;
    for (int i = 0; i < count; ++i)
        out.push_back({Vec3{x(rng), -10, z(rng)}, Vec3{jitter(rng), 1, jitter(rng)}});
    return out;
}

// Traces the rays with material m patterned; `check(ray, hit)` judges each painted hit.
// Returns the number of painted hits. The hits must equal, in t, normal and material,
// those of the same scene without patterns.
template <class Check>
int traceAll(const std::string& text, bool useBounds, Check check, uint64_t* expansions = nullptr) {
    auto c = compile(text);
    if (!c->graph) return -1;
    const Graph& g = *c->graph;
    TraceScene plain(g, computeBounds(g));
    TraceScene patterned(g, computeBounds(g));
    plain.useBounds = patterned.useBounds = useBounds;
    patterned.paintFrames.assign(g.materials.size(), 0);
    patterned.paintFrames[1] = 1;  // m (materials[0] is the default)
    EXPECT_EQ(g.materials[1].name, "m");
    Tracer a(plain), b(patterned);
    int painted = 0;
    for (int pass = 0; pass < 2; ++pass) {  // the second pass meets expanded instances
        for (const Ray& r : rays(4000)) {
            SurfaceHit ha, hb;
            const bool fa = a.firstHit(r.o, r.d, 1e-6, 1e9, ha);
            EXPECT_EQ(fa, b.firstHit(r.o, r.d, 1e-6, 1e9, hb));
            if (!fa) continue;
            EXPECT_EQ(ha.t, hb.t);
            EXPECT_EQ(ha.material, hb.material);
            EXPECT_TRUE(ha.normal == hb.normal);
            EXPECT_FALSE(ha.painted);
            EXPECT_EQ(hb.painted, hb.material == 1);
            if (!hb.painted) continue;
            ++painted;
            check(r, hb);
        }
    }
    if (expansions) *expansions = b.expansions();
    return painted;
}

TEST(PaintFrame, AtTheAxiomIsTheWorld) {
    for (bool useBounds : {true, false}) {
        uint64_t expansions = 0;
        const int painted = traceAll(
            recursion("paint(m)", "sphere"), useBounds,
            [](const Ray& r, const SurfaceHit& h) {
                const Vec3 p = r.o + r.d * h.t;
                EXPECT_NEAR(length(h.paintPoint - p), 0, 1e-9);
            },
            &expansions);
        EXPECT_GT(painted, 150);
        // Instances below the paint are expanded and inherit its frame.
        EXPECT_TRUE(!useBounds || expansions > 0u);
    }
}

TEST(PaintFrame, InsideTheRecursionIsEachInstancesOwn) {
    for (bool useBounds : {true, false}) {
        uint64_t expansions = 1;
        const int painted = traceAll(
            recursion("", "paint(m) sphere"), useBounds,
            [](const Ray&, const SurfaceHit& h) { EXPECT_NEAR(length(h.paintPoint), 1, 1e-9); },
            &expansions);
        EXPECT_GT(painted, 150);
        // Instances with the paint inside are expanded too, each surface keeping the
        // matrices on the way to its paint node (the graph walk had recorded them alone).
        EXPECT_TRUE(!useBounds || expansions > 0u);
    }
}

TEST(PaintFrame, BetweenTransformsAndThroughSpanLists) {
    // The paint's frame is neither the world nor the solids': the sphere of radius 0.5 at
    // (0, 0, 0.5), minus a sphere of radius 0.3 at (0.3, 0, 0.5) (span lists), in it.
    const Vec3 big{0, 0, 0.5}, small{0.3, 0, 0.5};
    const int painted =
        traceAll(recursion("",
                           "rot(1, 0, 0, 40) paint(m) move(0, 0, 0.5) uscale(0.5) "
                           "(sphere \\ move(0.6, 0, 0) uscale(0.6) sphere)"),
                 true, [&](const Ray&, const SurfaceHit& h) {
                     const double onBig = std::abs(length(h.paintPoint - big) - 0.5);
                     const double onSmall = std::abs(length(h.paintPoint - small) - 0.3);
                     EXPECT_LT(std::min(onBig, onSmall), 1e-9)
                         << h.paintPoint.x << " " << h.paintPoint.y << " " << h.paintPoint.z;
                 });
    EXPECT_GT(painted, 40);
}

TEST(PaintFrame, AnInnerPaintWithoutAPatternHasNone) {
    int plainHits = 0;
    const int painted =
        traceAll(recursion("paint(m)", "sphere ∪ paint(plain) move(0, 0, 0.9) uscale(0.4) sphere"),
                 true, [&](const Ray&, const SurfaceHit&) {});
    EXPECT_GT(painted, 150);
    auto c = compile(recursion("paint(m)", "paint(plain) sphere"));
    ASSERT_TRUE(c->graph);
    TraceScene scene(*c->graph, computeBounds(*c->graph));
    scene.paintFrames = {0, 1, 0};
    Tracer t(scene);
    for (const Ray& r : rays(500)) {
        SurfaceHit h;
        if (!t.firstHit(r.o, r.d, 1e-6, 1e9, h)) continue;
        ++plainHits;
        EXPECT_FALSE(h.painted);
    }
    EXPECT_GT(plainHits, 10);
}

// Interiors (transparency.h): in a scene with transparency, a hit knows the paint node
// instance that applied its material. Two instances of one paint node (a rule used
// twice) are two interiors, the primitives under one paint node instance share one, and
// a surface under no paint node has the default interior 0. Without transparency no
// paint node records anything.
TEST(PaintFrame, HitsKnowTheirPaintNodeInstance) {
    const std::string scene = R"(
material glass { pigment { color rgbf <1, 1, 1, 0.9> } interior { ior 1.5 } }
move(-3, 0, 0) B ∪ B ∪ paint(glass) (move(3, 0, 0) sphere ∪ move(3, 0, 3) sphere) ∪
  move(6, 0, 0) sphere
B 1
1: B -> paint(glass) sphere
)";
    const auto interiorAt = [](Tracer& t, double x, double z) {
        SurfaceHit h;
        EXPECT_TRUE(t.firstHit(Vec3{x, -10, z}, Vec3{0, 1, 0}, 1e-6, 1e9, h));
        return h.interior;
    };
    for (const bool transparent : {true, false}) {
        std::string text = scene;
        if (!transparent) text.replace(text.find("rgbf <1, 1, 1, 0.9>"), 19, "rgb <1, 1, 1>");
        auto c = compile(text);
        ASSERT_TRUE(c->graph);
        TraceScene ts(*c->graph, computeBounds(*c->graph));
        Tracer t(ts);
        const uint64_t left = interiorAt(t, -3, 0), middle = interiorAt(t, 0, 0);
        const uint64_t low = interiorAt(t, 3, 0), high = interiorAt(t, 3, 3);
        EXPECT_EQ(interiorAt(t, 6, 0), 0u);
        if (!transparent) {
            EXPECT_EQ(left | middle | low | high, 0u);
            continue;
        }
        EXPECT_NE(left, 0u);
        EXPECT_NE(middle, 0u);
        EXPECT_NE(low, 0u);
        EXPECT_NE(left, middle);
        EXPECT_NE(left, low);
        EXPECT_NE(middle, low);
        EXPECT_EQ(low, high);
        EXPECT_EQ(interiorAt(t, -3, 0.5), left);  // the same instance, another ray
    }
}

}  // namespace
}  // namespace pcsg::tracer
