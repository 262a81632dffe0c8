// Rendering at a time (docs/language.md section 11): the hyper-bounding boxes computed for
// a range of clocks hold at every clock of the range, so culling with them never changes
// an image; and the clock does move things.
#include <gtest/gtest.h>

#include <cstring>

#include "bounds.h"
#include "render.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

// A sphere moved by the clock, a tetrahedron fractal whose depth and scale follow the
// frame and the clock, and a torus whose tube grows with the clock.
const char* kMovingScene = R"(
camera { location <2, -9, 3>  look_at <2, 0, 0>  angle 60 }
light  { position <10, -20, 30> }
move(clock * 10, 0, 0) uscale(0.8) sphere ∪ {c = 1 + frame} move(0, 0, 2) S ∪
move(0, 0, -2) torus(1, 0.1 + clock * 0.3)
S if(c > 0, 2, 1)
1: S -> rotz(clock * 90) tetrahedron
2: S -> {c = c-1} ( move(0.5,0.5,0.5) uscale(0.5 + clock * 0.2) S ∪
                    move(-0.5,-0.5,0.5) uscale(0.5) S ∪ move(0.5,-0.5,-0.5) uscale(0.5) S )
)";

RenderOptions small() {
    RenderOptions o;
    o.width = 80;
    o.height = 60;
    o.threads = 2;
    return o;
}

bool sameBytes(const RenderResult& a, const RenderResult& b) {
    return a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

TEST(ClockRender, BoundsForAClockRangeGiveTheImageWithoutBounds) {
    auto c = compile(kMovingScene);
    ASSERT_TRUE(c->graph);
    Graph& g = *c->graph;
    for (const Time t : {Time{0, 1}, Time{0.5, 2}, Time{1, 3}}) {
        g.time = t;
        RenderOptions o = small();
        o.boundsTime = TimeRange{0, 1, 1, 3};
        const RenderResult ranged = render(g, o);
        o.boundsTime.reset();
        const RenderResult point = render(g, o);
        o.useBounds = false;
        const RenderResult plain = render(g, o);
        EXPECT_TRUE(sameBytes(ranged, plain)) << "clock " << t.clock;
        EXPECT_TRUE(sameBytes(point, plain)) << "clock " << t.clock;
    }
}

TEST(ClockRender, TheBoxesOfARangeHoldTheBoxesOfEachClock) {
    auto c = compile("move(clock * 10, 0, 0) sphere\n");
    ASSERT_TRUE(c->graph);
    Graph& g = *c->graph;
    BoundsOptions o;
    o.time = TimeRange{0, 1, 1, 1};
    const Box ranged = computeBounds(g, o).node[g.axiom];
    EXPECT_LE(ranged.lo.x, -1.0);
    EXPECT_GE(ranged.hi.x, 11.0);
    for (double clock : {0.0, 0.3, 1.0}) {
        g.time.clock = clock;
        const Box at = computeBounds(g).node[g.axiom];
        EXPECT_LE(at.lo.x, clock * 10 - 1 + 1e-6);
        EXPECT_GE(at.hi.x, clock * 10 + 1 - 1e-6);
        EXPECT_LT(at.hi.x - at.lo.x, 2.1);  // a point clock: a tight box
        EXPECT_LE(ranged.lo.x, at.lo.x);
        EXPECT_GE(ranged.hi.x, at.hi.x);
    }
}

TEST(ClockRender, TheClockMovesTheSphere) {
    auto c = compile(kMovingScene);
    ASSERT_TRUE(c->graph);
    Graph& g = *c->graph;
    g.time = Time{0, 1};
    const RenderResult a = render(g, small());
    g.time = Time{1, 1};
    const RenderResult b = render(g, small());
    EXPECT_FALSE(sameBytes(a, b));
}

}  // namespace
}  // namespace pcsg::tracer
