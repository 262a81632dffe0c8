// Fixed slots (fixed_slots.h) and the memo keys that leave them out (step_memo.h).
#include "fixed_slots.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>

#include "compile_test_util.h"
#include "step_memo.h"

namespace pcsg {
namespace {

using testing::compile;

Slot slotNamed(const Graph& g, const std::string& name) {
    for (Slot s = 0; s < g.slotCount(); ++s)
        if (g.slotNames[s] == name) return s;
    ADD_FAILURE() << "no parameter " << name;
    return 0;
}

NodeId moduleNode(const Graph& g, const std::string& name) {
    for (const Module& m : g.modules)
        if (m.name == name) return m.node;
    ADD_FAILURE() << "no module " << name;
    return kNone;
}

// k is decremented in B's recursion only: fixed on entry to A, not to B.
constexpr const char* kTwoModules = R"(
{ k = 3; n = 2; r = rand(); c = clock } A
A if(n > 0, 1, 2)
1: A -> { n = n - 1 } move(k + r + c, 0, 0) A ∪ B
2: A -> sphere
B if(k > 0, 1, 2)
1: B -> { k = k - 1 } move(0, k, 0) B
2: B -> cube
)";

TEST(FixedSlots, ASlotIsFixedWhereNoWalkHasChangedIt) {
    auto c = compile(kTwoModules);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const FixedSlots fixed(g);
    EXPECT_TRUE(fixed.fixed(moduleNode(g, "A"), slotNamed(g, "k")));
    EXPECT_FALSE(fixed.fixed(moduleNode(g, "B"), slotNamed(g, "k")));
    EXPECT_FALSE(fixed.fixed(moduleNode(g, "A"), slotNamed(g, "n")));
}

TEST(FixedSlots, ValuesFromThePathOrTheTimeAreNotFixed) {
    auto c = compile(kTwoModules);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const FixedSlots fixed(g);
    EXPECT_FALSE(fixed.fixed(moduleNode(g, "A"), slotNamed(g, "r")));
    EXPECT_FALSE(fixed.fixed(moduleNode(g, "A"), slotNamed(g, "c")));
}

TEST(FixedSlots, DifferentValuesOnTwoPathsAreNotFixed) {
    auto c = compile(
        "{ k = 1; n = 1 } A ∪ { k = 2; n = 1 } A\nA if(n > 0, 1, 2)\n"
        "1: A -> { n = n - 1 } move(k, 0, 0) A\n2: A -> sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const FixedSlots fixed(g);
    EXPECT_FALSE(fixed.fixed(moduleNode(g, "A"), slotNamed(g, "k")));
}

// The reads of the memo plan's only C-node with more than one assignment.
std::vector<std::string> calcReads(const Graph& g, const StepMemoPlan& plan) {
    for (NodeId n = 0; n < g.nodes.size(); ++n) {
        if (g.nodes[n].kind != NodeKind::Calc || g.calcs[g.nodes[n].payload].count < 2) continue;
        const StepMemoPlan::NodePlan& p = plan.of(n);
        EXPECT_TRUE(p.memoised);
        std::vector<std::string> out;
        for (uint32_t i = 0; i < p.readCount; ++i) out.push_back(g.slotNames[plan.reads(p)[i]]);
        return out;
    }
    ADD_FAILURE() << "no C-node";
    return {};
}

constexpr const char* kScratch = R"(
{ k = 3; n = 2 } A
A if(n > 0, 1, 2)
1: A -> { n = n - 1; t = n * k; n = n + t - t } move(t, 0, 0) A ∪ B
2: A -> sphere
B if(k > 0, 1, 2)
1: B -> { k = k - 1 } move(0, k, 0) B
2: B -> cube
)";

TEST(StepMemoPlanKeys, ACNodeKeyLeavesOutWhatItAssignedBeforeReading) {
    auto c = compile(kScratch);
    ASSERT_TRUE(c->graph) << c->errors();
    const StepMemoPlan plan(*c->graph);
    EXPECT_EQ(calcReads(*c->graph, plan), (std::vector<std::string>{"n", "k"}));
}

TEST(StepMemoPlanKeys, LeavesOutFixedSlots) {
    auto c = compile(kScratch);
    ASSERT_TRUE(c->graph) << c->errors();
    const FixedSlots fixed(*c->graph);
    const StepMemoPlan plan(*c->graph, &fixed);
    EXPECT_EQ(calcReads(*c->graph, plan), (std::vector<std::string>{"n"}));
}

// The narrower key still gives what the C-node computes, for frames of any values.
TEST(StepMemoPlanKeys, TheMemoGivesTheComputedFrame) {
    auto c = compile(kScratch);
    ASSERT_TRUE(c->graph) << c->errors();
    const Graph& g = *c->graph;
    const StepMemoPlan plan(g);
    StepMemo memo(g, plan, 4);
    std::mt19937_64 rng(3);
    std::vector<double> frame(g.slotCount()), direct(g.slotCount()), remembered(g.slotCount());
    for (int k = 0; k < 400; ++k) {
        for (double& v : frame) v = static_cast<double>(rng() % 3);
        for (NodeId n = 0; n < g.nodes.size(); ++n) {
            if (g.nodes[n].kind != NodeKind::Calc) continue;
            applyCalc(g, n, EvalState{frame.data(), kRootPath}, direct.data());
            memo.calc(n, EvalState{frame.data(), kRootPath}, remembered.data());
            ASSERT_EQ(std::memcmp(direct.data(), remembered.data(), direct.size() * 8), 0);
        }
    }
    EXPECT_GT(memo.hits(), 0u);
}

}  // namespace
}  // namespace pcsg
