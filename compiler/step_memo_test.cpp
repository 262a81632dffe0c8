// StepMemo gives exactly what the steps compute, whatever it remembers.
#include "step_memo.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <random>
#include <string>

#include "compile_test_util.h"

namespace pcsg {
namespace {

using testing::compile;

// C-nodes, T-nodes and S-nodes that read slots, rand(), choose() and the clock.
constexpr const char* kScene = R"(
{n = 3; a = 1; b = 2} S
S if(n > 0, if(b > 3, 3, 2), 1)
1: S -> sphere
2: S -> {n = n - 1; a = a + rand(); b = b * 2} rotx(a*30) uscale(1 + b/10) S ∪
        {n = n - 1} move(clock, a, 0) S
3: S -> {n = n - 1} T
T choose(1, 1 + a)
1: T -> scale(1, 1 + b, 2) S
2: T -> move(0, 0, rand()) cube
)";

// A frame of small values (below `spread`), so that the same keys come back.
std::vector<double> randomFrame(const Graph& g, std::mt19937_64& rng, uint64_t spread) {
    std::vector<double> f(g.slotCount());
    for (double& v : f) v = static_cast<double>(rng() % spread);
    return f;
}

bool sameBits(const double* a, const double* b, size_t n) {
    return std::memcmp(a, b, n * sizeof(double)) == 0;
}

bool sameAffine(const Affine& a, const Affine& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// Each step through the memo against the step computed directly, many times over.
void checkAgainstDirect(Graph& g, StepMemo& memo, int trials, uint64_t spread = 4) {
    std::mt19937_64 rng(7);
    const StepMemoPlan plan(g);
    std::vector<double> direct(g.slotCount()), remembered(g.slotCount());
    for (int k = 0; k < trials; ++k) {
        const std::vector<double> frame = randomFrame(g, rng, spread);
        const EvalState s{frame.data(), kRootPath + rng() % 3};
        g.time.clock = static_cast<double>(rng() % 2);
        for (NodeId n = 0; n < g.nodes.size(); ++n) {
            SCOPED_TRACE(::testing::Message() << "node " << n << " trial " << k);
            switch (g.nodes[n].kind) {
                case NodeKind::Calc:
                    applyCalc(g, n, s, direct.data());
                    memo.calc(n, s, remembered.data());
                    ASSERT_TRUE(sameBits(direct.data(), remembered.data(), direct.size()));
                    break;
                case NodeKind::Transform: {
                    if (g.transforms[g.nodes[n].payload].constant) break;
                    Affine f, i;
                    memo.transform(n, s, f, i);
                    const Affine d = transformMatrix(g, n, s);
                    ASSERT_TRUE(sameAffine(f, d));
                    ASSERT_TRUE(sameAffine(i, d.inverse()));
                    break;
                }
                case NodeKind::Select:
                    ASSERT_EQ(memo.select(n, s), selectRule(g, n, s));
                    break;
                default:
                    break;
            }
        }
    }
}

TEST(StepMemo, GivesWhatTheStepsComputeAndRemembers) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const StepMemoPlan plan(*c->graph);
    StepMemo memo(*c->graph, plan);
    checkAgainstDirect(*c->graph, memo, 400);
    // Few distinct keys: most steps are remembered.
    EXPECT_GT(memo.hits(), 4 * memo.misses());
}

TEST(StepMemo, ATinyTableEvictsButNeverMixesUpEntries) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const StepMemoPlan plan(*c->graph);
    StepMemo memo(*c->graph, plan, 1);  // two entries for all nodes
    checkAgainstDirect(*c->graph, memo, 200);
    EXPECT_GT(memo.misses(), 0u);
}

// C-nodes that read 1 to 16 slots (every length of key the lookup unrolls), in a chain, and
// one that reads the clock first.
std::string keysOfEveryLength() {
    std::string text = "{", sum;
    for (int i = 1; i <= 16; ++i)
        text += "s" + std::to_string(i) + " = " + std::to_string(i) + "; ";
    text += "r = 0} {r = clock + s1 + s2} ";
    for (int k = 1; k <= 16; ++k) {
        sum += (k > 1 ? " + s" : "s") + std::to_string(k);
        text += "{r = " + sum + "} ";
    }
    return text + "sphere\n";
}

// C-nodes that read the time (`frame`, or `clock` and `frame`) and then 0 to 14 slots: every
// length of the keys the lookup unrolls for them.
std::string timedKeysOfEveryLength() {
    std::string text = "{", sum;
    for (int i = 1; i <= 14; ++i)
        text += "s" + std::to_string(i) + " = " + std::to_string(i) + "; ";
    text += "r = 0} {r = frame} {r = clock + frame} ";
    for (int k = 1; k <= 14; ++k) {
        sum += " + s" + std::to_string(k);
        text += "{r = frame" + sum + "} {r = clock + frame" + sum + "} ";
    }
    return text + "sphere\n";
}

// A key's value changed: slot r of the frame, the clock or the frame number.
void change(Graph& g, std::vector<double>& frame, uint32_t r, double v) {
    if (r == StepMemoPlan::kClock)
        g.time.clock = v;
    else if (r == StepMemoPlan::kFrame)
        g.time.frame = static_cast<int>(v);
    else
        frame[r] = v;
}

// Node n's key, in a one-entry table: the same values again hit, each value changed alone
// misses and gives the computed values.
void expectEachValueMisses(Graph& g, const StepMemoPlan& plan, NodeId n) {
    const StepMemoPlan::NodePlan& p = plan.of(n);
    StepMemo memo(g, plan, 0);  // one entry: each lookup meets the key before it
    std::vector<double> frame(g.slotCount(), 1.0), direct(g.slotCount()), got(g.slotCount());
    g.time.clock = 1;
    g.time.frame = 1;
    const EvalState s{frame.data(), kRootPath};
    memo.calc(n, s, got.data());
    memo.calc(n, s, got.data());
    for (uint32_t j = 0; j < p.readCount; ++j) {  // each value alone differs: a miss
        change(g, frame, plan.reads(p)[j], 2);
        memo.calc(n, s, got.data());
        applyCalc(g, n, s, direct.data());
        ASSERT_TRUE(sameBits(direct.data(), got.data(), got.size())) << "value " << j;
        change(g, frame, plan.reads(p)[j], 1);
        memo.calc(n, s, got.data());
    }
    EXPECT_EQ(memo.hits(), 1u) << "node " << n << ", " << p.readCount << " values";
    EXPECT_EQ(memo.misses(), 1u + 2 * p.readCount) << "node " << n;
}

TEST(StepMemo, KeysOfEveryLengthHitOnlyWhenEveryValueIsTheSame) {
    auto c = testing::compileUnfolded(keysOfEveryLength());
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    const StepMemoPlan plan(g);
    uint32_t lengths = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        const StepMemoPlan::NodePlan& p = plan.of(n);
        if (g.nodes[n].kind != NodeKind::Calc || !p.memoised) continue;
        lengths |= 1u << p.readCount;
        expectEachValueMisses(g, plan, n);
    }
    EXPECT_EQ(lengths & 0x1fffeu, 0x1fffeu) << "keys of 1 to 16 values";
}

TEST(StepMemo, KeysThatReadTheTimeHitOnlyWhenEveryValueIsTheSame) {
    auto c = testing::compileUnfolded(timedKeysOfEveryLength());
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    const StepMemoPlan plan(g);
    uint32_t frameOnly = 0, both = 0;  // the key lengths seen, as bits
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        const StepMemoPlan::NodePlan& p = plan.of(n);
        if (g.nodes[n].kind != NodeKind::Calc || !p.memoised || p.readCount == 0) continue;
        const uint32_t* reads = plan.reads(p);
        if (reads[0] < StepMemoPlan::kFrame) continue;  // the first C-node: slots only
        const bool twice = p.readCount > 1 && reads[1] >= StepMemoPlan::kFrame;
        (twice ? both : frameOnly) |= 1u << p.readCount;
        expectEachValueMisses(g, plan, n);
    }
    EXPECT_EQ(frameOnly, 0xfffeu) << "frame and 0 to 14 slots";
    EXPECT_EQ(both, 0x1fffcu) << "clock, frame and 0 to 14 slots";
}

TEST(StepMemo, TheInstancePathIsPartOfTheKeyOnlyForRandomSteps) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const StepMemoPlan plan(g);
    int random = 0, plain = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Calc) continue;
        const StepMemoPlan::NodePlan& p = plan.of(n);
        EXPECT_TRUE(p.memoised);
        (p.usesPath ? random : plain) += 1;
    }
    EXPECT_EQ(random, 1);  // {n = n - 1; a = a + rand(); b = b * 2}
    EXPECT_GE(plain, 2);
}

TEST(StepMemo, ReadsOfTheClockAfterSlotsAreKeyedFirst) {
    // move(a, clock, b): the clock is read between two slots; the plan puts it first, and
    // the lookup's loop over slots never takes it for one
    auto c = compile(R"(
{n = 3; a = 1; b = 2} S
S if(n > 0, 2, 1)
1: S -> sphere
2: S -> {n = n - 1; a = a + 1; b = b * 2} move(a, frame + clock, b) S
)");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    const StepMemoPlan plan(g);
    bool seen = false;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        const StepMemoPlan::NodePlan& p = plan.of(n);
        if (g.nodes[n].kind != NodeKind::Transform || !p.memoised) continue;
        ASSERT_EQ(p.readCount, 4u);
        EXPECT_GE(plan.reads(p)[0], StepMemoPlan::kFrame);
        EXPECT_GE(plan.reads(p)[1], StepMemoPlan::kFrame);
        seen = true;
    }
    EXPECT_TRUE(seen);
    StepMemo memo(g, plan);
    checkAgainstDirect(g, memo, 200);
    EXPECT_GT(memo.hits(), memo.misses());
}

TEST(StepMemo, AStepThatFailsIsNotRemembered) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const StepMemoPlan plan(g);
    StepMemo memo(g, plan);
    // b = -10 makes uscale(1 + b/10) singular: the step throws every time it is taken.
    std::vector<double> frame(g.slotCount(), 1.0);
    for (size_t k = 0; k < g.slotCount(); ++k)
        if (g.slotNames[k] == "b") frame[k] = -10;
    int failing = 0;
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Transform || g.transforms[g.nodes[n].payload].constant)
            continue;
        bool failsDirectly = false;
        try {
            transformMatrix(g, n, {frame.data(), kRootPath});
        } catch (const RuntimeError&) {
            failsDirectly = true;
        }
        failing += failsDirectly;
        Affine f, i;
        for (int k = 0; k < 3; ++k) {
            if (failsDirectly)
                EXPECT_THROW(memo.transform(n, {frame.data(), kRootPath}, f, i), RuntimeError);
            else
                EXPECT_NO_THROW(memo.transform(n, {frame.data(), kRootPath}, f, i));
        }
    }
    EXPECT_EQ(failing, 1);
}

// An entry holds what the graph's memoised nodes read and write at most, not room for
// kMaxReads and kMaxWrites: the Sierpinski tetrahedron's S-node and C-node read and write
// one value each.
TEST(StepMemo, EntriesAreSizedToTheGraph) {
    auto c = compile(R"(
{c=6} S
S if(c > 0, 2, 1)
1: S -> tetrahedron
2: S -> {c=c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪ move(-0.5,-0.5,0.5) uscale(0.5) S )
)");
    ASSERT_TRUE(c->graph) << c->errors();
    const StepMemoPlan plan(*c->graph);
    EXPECT_EQ(plan.maxReads(), 1u);
    EXPECT_EQ(plan.maxWrites(), 1u);
    const StepMemo memo(*c->graph, plan, 12);
    EXPECT_EQ(memo.bytes(), 4096u * 4 * sizeof(uint64_t));  // node, path, c, the result

    // kScene: a T-node's two matrices, and a key of n, b and the clock at most.
    auto k = compile(kScene);
    ASSERT_TRUE(k->graph) << k->errors();
    const StepMemoPlan full(*k->graph);
    EXPECT_EQ(full.maxWrites(), 24u);
    EXPECT_GE(full.maxReads(), 2u);
    EXPECT_LT(full.maxReads(), StepMemoPlan::kMaxReads);
    // Its entries are over 200 bytes: 512 of them (a table of at most 128 KB), not 4,096.
    const size_t entryBytes = (2 + full.maxReads() + full.maxWrites()) * sizeof(uint64_t);
    const StepMemo large(*k->graph, full, 12);
    EXPECT_EQ(large.bytes(), 512u * entryBytes);
    EXPECT_EQ(StepMemo(*k->graph, full, 8).bytes(), 256u * entryBytes);
}

// A table that misses for most of its lookups doubles at the end of each window, up to
// 2^entriesLog2 entries and the growth's byte limit, and still gives the steps' numbers.
TEST(StepMemo, ATableThatMissesOftenGrowsUpToItsLimit) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const StepMemoPlan plan(*c->graph);
    const size_t entryBytes = (2 + plan.maxReads() + plan.maxWrites()) * sizeof(uint64_t);
    StepMemoGrowth growth;
    growth.window = 1024;
    StepMemo memo(*c->graph, plan, 12, growth);
    EXPECT_EQ(memo.bytes(), 512u * entryBytes);          // the start: within 128 KB
    checkAgainstDirect(*c->graph, memo, 400, 1u << 20);  // nearly every key new
    EXPECT_EQ(memo.bytes(), 4096u * entryBytes);

    growth.maxBytes = 3000 * entryBytes;  // room for 2,048 entries, not 4,096
    StepMemo capped(*c->graph, plan, 12, growth);
    checkAgainstDirect(*c->graph, capped, 400, 1u << 20);
    EXPECT_EQ(capped.bytes(), 2048u * entryBytes);
}

// A table that hits for most of its lookups keeps its size through many windows.
TEST(StepMemo, ATableThatHitsKeepsItsSize) {
    auto c = compile(kScene);
    ASSERT_TRUE(c->graph) << c->errors();
    const StepMemoPlan plan(*c->graph);
    StepMemoGrowth growth;
    growth.window = 16384;
    StepMemo memo(*c->graph, plan, 12, growth);
    const size_t start = memo.bytes();
    checkAgainstDirect(*c->graph, memo, 8000, 2);               // few distinct keys
    EXPECT_GT(memo.hits() + memo.misses(), 4 * growth.window);  // windows were ended
    EXPECT_EQ(memo.bytes(), start);
}

}  // namespace
}  // namespace pcsg
