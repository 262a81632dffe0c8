// The instance boxes a sequence's frames share (instance_boxes.h's SequenceInstanceBoxes):
// the boxes of instances whose sub-graph reads no time are computed in the first frame
// and found in the later ones; the instances of modules that read the time are computed
// in every frame; and a frame's pixels do not depend on what the earlier frames left.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "bounds.h"
#include "instance_boxes.h"
#include "render.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

using testing::compile;
using testing::expectSameBoxes;

// F reads no time (only the transform above it moves with the clock; 243 spheres, so that
// its instances are large enough for the render to store: InstanceBoxOptions::minWeight);
// G's spheres grow with the clock while the parameters G reads stay the same in every
// frame, so a box of G kept from an earlier frame would be too small.
const char* kScene = R"(
camera { location <0, -9, 2>  look_at <0, 0, 0>  angle 60 }
light  { position <10, -20, 30> }
move(clock * 2 - 1, 0, 1) {n = 5} F ∪ move(0, 0, -1.5) {k = 3} G
F if(n > 0, 2, 1)
1: F -> sphere
2: F -> {n = n-1} (move(0.5,0.5,0.5) uscale(0.5) F ∪ move(-0.5,-0.5,0.5) uscale(0.5) F ∪
                   move(0.5,-0.5,-0.5) uscale(0.5) F)
G if(k > 0, 2, 1)
1: G -> uscale(0.2 + clock) sphere
2: G -> {k = k-1} (move(1.2,0,0) uscale(0.6) G ∪ move(-1.2,0,0) uscale(0.6) G)
)";

// Exact boxes at every depth, all stored.
InstanceBoxOptions always(std::shared_ptr<SequenceInstanceBoxes> sequence = nullptr) {
    InstanceBoxOptions o;
    o.trial = UINT32_MAX;
    o.minWeight = 1;
    o.sequence = std::move(sequence);
    return o;
}

TEST(SequenceBoxes, ALaterFrameFindsTheTimeFreeBoxesAndComputesTheOthers) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph);
    Graph& g = *c->graph;
    auto sequence = std::make_shared<SequenceInstanceBoxes>(g, 64u << 20);
    g.time = Time{0, 1};
    const Bounds bounds1 = computeBounds(g);
    const InstanceBoxes first(g, bounds1, always(sequence)), alone1(g, bounds1, always());
    EXPECT_GT(expectSameBoxes(g, first, alone1), 10u);
    const uint64_t stored = sequence->entries();
    EXPECT_GT(stored, 0u);                     // F's instances
    EXPECT_LT(stored, first.stats().entries);  // G's stayed in the frame's own table

    g.time = Time{0.5, 2};
    const Bounds bounds2 = computeBounds(g);
    const InstanceBoxes second(g, bounds2, always(sequence)), alone2(g, bounds2, always());
    expectSameBoxes(g, second, alone2);      // G's boxes are the larger ones of this frame
    EXPECT_EQ(sequence->entries(), stored);  // F's were all there
    EXPECT_GT(second.stats().computed, 0u);  // G's were computed again
    EXPECT_LT(second.stats().computed, alone2.stats().computed);
}

TEST(SequenceBoxes, TheSequenceBelongsToOneGraph) {
    auto a = compile(kScene), b = compile(kScene);
    ASSERT_TRUE(a->graph && b->graph);
    auto sequence = std::make_shared<SequenceInstanceBoxes>(*a->graph, 1u << 20);
    const Bounds bounds = computeBounds(*b->graph);
    EXPECT_THROW(InstanceBoxes(*b->graph, bounds, always(sequence)), std::logic_error);
}

bool sameBytes(const RenderResult& a, const RenderResult& b) {
    return a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

// Each frame of a sequence that shares its boxes (two threads) is the frame rendered on its
// own (one thread), going forwards and back over the clock.
TEST(SequenceBoxes, AFrameIsTheSameWithTheBoxesOfEarlierFrames) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph);
    Graph& g = *c->graph;
    RenderOptions shared;
    shared.width = 80;
    shared.height = 60;
    shared.threads = 2;
    shared.sequenceBoxes = std::make_shared<SequenceInstanceBoxes>(g, 64u << 20);
    RenderOptions alone = shared;
    alone.threads = 1;
    alone.sequenceBoxes = nullptr;
    int frame = 1;
    for (const double clock : {0.0, 0.4, 1.0, 0.2}) {
        g.time = Time{clock, frame++};
        const RenderResult a = render(g, shared), b = render(g, alone);
        EXPECT_TRUE(sameBytes(a, b)) << "clock " << clock;
    }
    EXPECT_GT(shared.sequenceBoxes->entries(), 0u);
}

}  // namespace
}  // namespace pcsg::tracer
