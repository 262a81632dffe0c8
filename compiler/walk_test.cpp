// The shared walk (walk.h): the world matrices it hands a sink are the products of the
// T-steps from the identity, bit for bit, also where it takes a step's own matrix instead of
// multiplying it by the identity (the first T-step below the start and, with local frames,
// below every S-node).
#include "walk.h"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include "compile_test_util.h"
#include "eval.h"

namespace pcsg {
namespace {

// Records the world matrix of every primitive, in the frame of its S-node (local frames).
struct WorldSink {
    using Result = int;
    static constexpr bool kLocalSelectFrames = true;
    std::vector<Affine>& worlds;
    int nothing() const { return 0; }
    void visit() {}
    bool lookup(NodeId, uint32_t, const double*, uint64_t, int&) { return false; }
    void store(NodeId, uint32_t, const double*, uint64_t, int) {}
    int toParent(const Affine&, int r) const { return r; }
    int primitive(PrimitiveKind, const Affine& w, uint32_t, const double*, uint32_t) {
        worlds.push_back(w);
        return 0;
    }
    void beginOperator(WalkEntry&) {}
    int endOperator(CsgOp, const int*, uint32_t, const WalkEntry&) { return 0; }
};

std::vector<Affine> worldsOf(const Graph& g) {
    std::vector<Affine> worlds;
    WorldSink sink{worlds};
    const Semantics sem(g);
    Walker<WorldSink> walker(sem, sink);
    walker.run();
    return worlds;
}

// The same bits (the sign of a zero included).
void expectSameBits(const Affine& a, const Affine& b, int which) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            EXPECT_EQ(std::bit_cast<uint64_t>(a.l[i][j]), std::bit_cast<uint64_t>(b.l[i][j]))
                << "primitive " << which << " l[" << i << "][" << j << "]";
    const double at[3] = {a.t.x, a.t.y, a.t.z}, bt[3] = {b.t.x, b.t.y, b.t.z};
    for (int i = 0; i < 3; ++i)
        EXPECT_EQ(std::bit_cast<uint64_t>(at[i]), std::bit_cast<uint64_t>(bt[i]))
            << "primitive " << which << " t[" << i << "]";
}

TEST(Walk, WorldsBelowAnSNodeAreTheProductsFromTheIdentityBitForBit) {
    // Below S (local frames: the world restarts at the identity): a parameter T-node whose
    // matrix holds -0 (identity * M turns it into +0), a plain one, and a fused chain of
    // constant T-nodes followed by a parameter T-node. (Infinities never reach a matrix: a
    // T-node's arguments must be finite.)
    auto c = testing::compile(R"(
{a = -1} S
S 1
1: S -> {z = a * 0} (move(z, 1, 2) sphere ∪ move(a, 3, 4) sphere ∪
        move(1, 2, 3) scale(2, 2, 2) move(0, 0, a) sphere)
)");
    ASSERT_TRUE(c->graph) << c->errors();
    const std::vector<Affine> worlds = worldsOf(*c->graph);
    ASSERT_EQ(worlds.size(), 3u);
    const Affine I = Affine::identity();
    const double minusZero = -1.0 * 0.0;
    ASSERT_TRUE(std::signbit(minusZero));
    expectSameBits(worlds[0], I * Affine::translate({minusZero, 1, 2}), 0);
    EXPECT_FALSE(std::signbit(worlds[0].t.x));  // (+0: the product, not the matrix's -0)
    expectSameBits(worlds[1], I * Affine::translate({-1, 3, 4}), 1);
    const Affine chain = I * Affine::translate({1, 2, 3}) * Affine::scale({2, 2, 2});
    expectSameBits(worlds[2], chain * Affine::translate({0, 0, -1}), 2);
}

// Records the world matrix of every primitive in the start node's frame (no local frames).
struct GlobalWorldSink : WorldSink {
    static constexpr bool kLocalSelectFrames = false;
};

// Without local frames the world goes on through S-, C- and paint nodes unchanged and
// through every T-step as the product with the world above it.
TEST(Walk, WorldsGoOnThroughEveryUnaryNodeAsTheProductsBitForBit) {
    auto c = testing::compile(R"(
{a = -1} S
S 1
1: S -> move(a, 2, 3) {b = a * 2} T
T 1
1: T -> paint(default) rotz(b * 10) (move(0, b, 1) sphere ∪ sphere)
)");
    ASSERT_TRUE(c->graph) << c->errors();
    std::vector<Affine> worlds;
    GlobalWorldSink sink{{worlds}};
    const Semantics sem(*c->graph);
    Walker<GlobalWorldSink> walker(sem, sink);
    walker.run();
    ASSERT_EQ(worlds.size(), 2u);
    const Affine outer = Affine::identity() * Affine::translate({-1, 2, 3});
    const Affine rotated = outer * makeTransform(TransformOp::RotZ, std::array{-20.0}.data());
    expectSameBits(worlds[0], rotated * Affine::translate({0, -2, 1}), 0);
    expectSameBits(worlds[1], rotated, 1);
}

}  // namespace
}  // namespace pcsg
