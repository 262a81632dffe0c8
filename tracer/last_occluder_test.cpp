// The last occluder of shadow rays (last_occluder.h): with it, a tracer with expanded
// instances says "occluded" for exactly the shadow rays the walk of the graph alone does.
#include "last_occluder.h"

#include <gtest/gtest.h>

#include <cmath>

#include "bounds.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

// A Sierpinski tetrahedron of order 6: the default options expand the copies a few
// levels down, below T-nodes (the occluder's chain of matrices is not empty).
const std::string kOrder6 = testing::sierpinski(6);

// Shadow rays toward two lights from the surface points of a grid of camera rays, in
// pixel order (neighbours share occluders), twice (the second time through expansions):
// the same answer with and without expanded instances. Returns the shortcuts taken.
uint64_t expectSameShadows(const std::string& text, const InstanceBoxOptions& options) {
    auto c = compile(text);
    EXPECT_TRUE(c->graph);
    if (!c->graph) return 0;
    const Graph& g = *c->graph;
    TraceScene plain(g, computeBounds(g), true, options);
    plain.expansionBytes = 0;
    TraceScene expanding(g, computeBounds(g), true, options);
    Tracer a(plain), b(expanding);
    const Vec3 eye{0.4, -4, 1.1};
    const Vec3 lights[2] = {{3, -2, 6}, {-5, -1, 1}};
    int occluded = 0, lit = 0;
    for (int round = 0; round < 2; ++round)
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                const Vec3 d = normalize(Vec3{(x - 24) / 40.0, 1, (y - 24) / 40.0} -
                                         Vec3{eye.x / 4, 0, eye.z / 4});
                SurfaceHit h;
                if (!a.firstHit(eye, d, 1e-4, 1e7, h)) continue;
                const Vec3 p = eye + d * h.t;
                for (const Vec3& light : lights) {
                    const double dist = length(light - p);
                    const Vec3 l = (light - p) * (1 / dist);
                    const bool sa = a.anyHit(p, l, 1e-6, dist - 1e-6);
                    EXPECT_EQ(b.anyHit(p, l, 1e-6, dist - 1e-6), sa) << x << " " << y;
                    ++(sa ? occluded : lit);
                }
            }
    EXPECT_GT(occluded, 100);
    EXPECT_GT(lit, 100);
    EXPECT_EQ(a.shadowShortcuts(), 0u);
    return b.shadowShortcuts();
}

TEST(LastOccluder, SierpinskiShadowsAreTheSameWithShortcuts) {
    EXPECT_GT(expectSameShadows(kOrder6, InstanceBoxOptions{}), 100u);
}

TEST(LastOccluder, PlantShadowsAreTheSame) {
    // paints, choose(), rand() and a shear above the expanded copies
    expectSameShadows(testing::branchingPlant(6), testing::eagerExpansion());
}

}  // namespace
}  // namespace pcsg::tracer
